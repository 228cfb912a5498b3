#pragma once
// The stimulus format of the run-time drivers (tb/verify_driver.cpp, tb/verify_driver_sc.cpp,
// tb/hls_driver.cpp; written by tool/rtl_runner.cpp), read once here:
//   run NAME VALID_PROB READY_PROB SEED RESET_AT QUIET N CADENCE
//   x_0 ... x_{N-1}
// (fields: see tb/verify_driver.cpp).
#include <cinttypes>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace ranging::tb {

struct DriverRun {
  std::string name;
  double valid_prob = 1, ready_prob = 1;
  unsigned long long seed = 0, quiet = 0, cadence = 0;
  long long reset_at = -1;
  std::vector<std::uint64_t> x;  // port values, masked to IN_W bits
};

// 1: a run was read into r; 0: end of the stimulus; -1: a short sample list (r.name says which).
inline int read_run(std::FILE* in, DriverRun& r) {
  char name[256];
  unsigned long long n = 0;
  if (std::fscanf(in, " run %255s %lf %lf %llu %lld %llu %llu %llu", name, &r.valid_prob, &r.ready_prob, &r.seed,
                  &r.reset_at, &r.quiet, &n, &r.cadence) != 8) {
    return 0;
  }
  r.name = name;
  r.x.assign(n, 0);
  for (auto& v : r.x) {
    if (std::fscanf(in, "%" SCNu64, &v) != 1) return -1;
  }
  return 1;
}

}  // namespace ranging::tb
