// Recorded Pearson references (`ranging decode --references DIR`, scene receiver.reference:
// files): references written by the simulator itself decode every code at another distance,
// swapped reference files swap the Pearson decoder's codes (the files are really used), and
// bad reference files (missing, too short, wrong sample rate, all zero) exit 2 naming the file.
#include <gtest/gtest.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <functional>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "model/sim/capture.hpp"
#include "tests/process.hpp"

using namespace ranging;
namespace fs = std::filesystem;
using testing_support::ProcessResult;
using testing_support::run_tool;

namespace {

constexpr int kEta = 7;               // M1 has 7 codes
constexpr double kRefDistance = 0.3;  // references: noise-free bursts at 0.3 m
constexpr double kDistance = 1.1;     // measurements: noisy bursts at 1.1 m

void write(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

std::string dir_root() { return ::testing::TempDir() + "/refs_" + std::to_string(::getpid()); }

// The best-rho detection of a decode --json run (the receiver may also report noise events).
nlohmann::json best_detection(const ProcessResult& r) {
  const auto j = nlohmann::json::parse(r.out);
  nlohmann::json best;
  for (const auto& d : j["detections"]) {
    if (best.is_null() || d["rho"].get<double>() > best["rho"].get<double>()) best = d;
  }
  return best;
}

class References : public ::testing::Test {
 protected:
  // Simulate the references and the measurements once for the whole suite.
  static void SetUpTestSuite() {
    const std::string d = dir_root();
    fs::remove_all(d);
    fs::create_directories(d + "/refs");
    write(d + "/ref.yaml", "name: ref\ntransducers: {}\ngeometry:\n  distances_m: [0.3]\nexcitation:\n  family: M1\n");
    write(d + "/meas.yaml",
          "name: meas\ntransducers: {}\ngeometry:\n  distances_m: [1.1]\nexcitation:\n  family: M1\n"
          "noise:\n  noise_v: 0.002\n  seed: 7\n");
    for (const char* s : {"ref", "meas"}) {
      const ProcessResult r = run_tool("simulate " + d + "/" + s + ".yaml --out " + d + "/" + s +
                                       "_out --write-captures --quiet --json");
      ASSERT_EQ(r.status, 0) << r.err;
    }
    // The decoder's naming scheme DIR/<family>-<j>.csv|.wav; both formats are used.
    for (int j = 1; j <= kEta; ++j) {
      const char* ext = j % 2 ? ".csv" : ".wav";
      fs::copy_file(ref_capture(j, ext), d + "/refs/M1-" + std::to_string(j) + ext);
    }
  }
  static void TearDownTestSuite() { fs::remove_all(dir_root()); }

  static std::string ref_capture(int j, const std::string& ext) {
    return dir_root() + "/ref_out/captures/M1_" + std::to_string(std::lround(kRefDistance * 1e3)) + "mm_r1_j" +
           std::to_string(j) + ext;
  }
  static std::string meas_capture(int j) {
    return dir_root() + "/meas_out/captures/M1_" + std::to_string(std::lround(kDistance * 1e3)) + "mm_r1_j" +
           std::to_string(j) + ".wav";
  }
  // A copy of the good references with some files replaced or removed.
  static std::string refs_variant(const std::string& name) {
    const std::string v = dir_root() + "/" + name;
    fs::remove_all(v);
    fs::copy(dir_root() + "/refs", v);
    return v;
  }
};

TEST_F(References, SimulatedReferencesDecodeEveryCodeAtAnotherDistance) {
  // Pearson rho is compared with the simulated-template mode on the same capture. Templates and
  // segments are placed to the nearest sample, so the two modes may differ by about one sample
  // of misalignment at 25 samples per carrier cycle: 1 - cos(2 pi / 25) = 0.031.
  const double rho_tol = 1.0 - std::cos(2.0 * std::numbers::pi / 25.0);
  for (int j = 1; j <= kEta; ++j) {
    SCOPED_TRACE("code " + std::to_string(j));
    const ProcessResult sim = run_tool("decode " + meas_capture(j) + " --family M1 --json");
    const ProcessResult rec = run_tool("decode " + meas_capture(j) + " --family M1 --json --references " +
                                       dir_root() + "/refs");
    ASSERT_EQ(sim.status, 0) << sim.err;
    ASSERT_EQ(rec.status, 0) << rec.err;
    const auto a = best_detection(sim), b = best_detection(rec);
    ASSERT_FALSE(b.is_null()) << "nothing reported at the default --min-rho 0.7: " << rec.out;
    EXPECT_EQ(b["code"], j);          // the receiver bank
    EXPECT_EQ(b["pearson_code"], j);  // the Pearson decoder with the recorded references
    // 1 mm: the noisy ToF is within a few hundredths of a sample (68 um each) of the truth.
    EXPECT_NEAR(b["distance_m"].get<double>(), kDistance, 1e-3);
    EXPECT_EQ(b["tof_s"], a["tof_s"]) << "the references only change the Pearson decoder";
    EXPECT_GT(b["rho"].get<double>(), 0.95);
    EXPECT_NEAR(b["rho"].get<double>(), a["rho"].get<double>(), rho_tol);
    // The recorded references decode with a positive margin, as the simulated ones do.
    EXPECT_GT(b["pearson_margin"].get<double>(), 0.0);
    EXPECT_NEAR(b["pearson_margin"].get<double>(), a["pearson_margin"].get<double>(), 2 * rho_tol);
  }
}

// The scene form, receiver.reference: files with a references_dir relative to the scene file.
TEST_F(References, SceneWithReferenceFilesDecodesEveryCode) {
  const std::string d = dir_root();
  write(d + "/meas_files.yaml",
        "name: meas_files\ntransducers: {}\ngeometry:\n  distances_m: [1.1]\nexcitation:\n  family: M1\n"
        "noise:\n  noise_v: 0.002\n  seed: 7\nreceiver:\n  reference: files\n  references_dir: refs\n");
  const ProcessResult r = run_tool("simulate " + d + "/meas_files.yaml --out " + d + "/files_out --quiet --json");
  ASSERT_EQ(r.status, 0) << r.err;
  std::ifstream csv(d + "/files_out/measurements.csv");
  std::string line;
  std::getline(csv, line);
  ASSERT_NE(line.find("code_sent"), std::string::npos) << line;
  int rows = 0;
  while (std::getline(csv, line)) {
    std::vector<std::string> cell;
    std::stringstream ss(line);
    for (std::string x; std::getline(ss, x, ',');) cell.push_back(x);
    ASSERT_GE(cell.size(), 15u) << line;
    // family,repeat,burst,true_distance_m,code_sent,code_decoded,tof_s,distance_m,error_m,rho_max,
    // rho_submax,u,energy_v2,td_s,pearson_code,...
    EXPECT_EQ(cell[14], cell[4]) << line;
    EXPECT_NEAR(std::stod(cell[7]), kDistance, 1e-3) << line;
    EXPECT_GT(std::stod(cell[9]), 0.95) << line;
    ++rows;
  }
  EXPECT_EQ(rows, kEta);
}

// Negative control: exchange the files of codes 2 and 5. The receiver bank (simulated
// templates) still finds codes 2 and 5, the Pearson decoder reports the swapped names.
TEST_F(References, SwappedReferenceFilesSwapThePearsonCodes) {
  const std::string sw = refs_variant("swapped");
  fs::rename(sw + "/M1-2.wav", sw + "/tmp.wav");
  fs::rename(sw + "/M1-5.csv", sw + "/M1-2.csv");
  fs::rename(sw + "/tmp.wav", sw + "/M1-5.wav");
  for (auto [sent, named] : {std::pair{2, 5}, std::pair{5, 2}, std::pair{3, 3}}) {
    SCOPED_TRACE("code " + std::to_string(sent));
    const ProcessResult r = run_tool("decode " + meas_capture(sent) + " --family M1 --json --references " + sw);
    ASSERT_EQ(r.status, 0) << r.err;
    const auto b = best_detection(r);
    ASSERT_FALSE(b.is_null()) << r.out;
    EXPECT_EQ(b["code"], sent);
    EXPECT_EQ(b["pearson_code"], named);
    EXPECT_GT(b["rho"].get<double>(), 0.95);  // the right waveform, under the wrong name
  }
}

TEST_F(References, BadReferenceFilesExitTwoNamingTheFile) {
  const Capture good = read_capture(ref_capture(4, ".wav"));
  struct Case {
    std::string name;
    std::function<std::string(const std::string&)> make;  // edits the variant dir, returns the file named
    std::string expect;
  };
  const std::vector<Case> cases = {
      {"missing",
       [](const std::string& v) {
         fs::remove(v + "/M1-4.wav");
         return v + "/M1-4.csv";
       },
       "no reference for code 4"},
      {"short",
       [&](const std::string& v) {
         fs::remove(v + "/M1-4.wav");
         Capture c = good;
         c.samples.resize(300);  // 60 us: less than one M1 burst (7 chips x 4 cycles = 140 us)
         write(v + "/M1-4.csv", capture_csv(c));
         return v + "/M1-4.csv";
       },
       "too short"},
      {"rate",
       [&](const std::string& v) {
         Capture c = good;  // every other sample: 2.5 MS/s against the capture's 5 MS/s
         c.sample_rate /= 2;
         for (std::size_t n = 0; 2 * n < good.samples.size(); ++n) c.samples[n] = good.samples[2 * n];
         c.samples.resize((good.samples.size() + 1) / 2);
         write(v + "/M1-4.wav", capture_wav(c, WavFormat::Float32));
         return v + "/M1-4.wav";
       },
       "sampled at 2500000 Hz"},
      {"zero",
       [&](const std::string& v) {
         Capture c = good;
         c.samples.assign(c.samples.size(), 0.0);
         write(v + "/M1-4.wav", capture_wav(c, WavFormat::Float32));
         return v + "/M1-4.wav";
       },
       "all zero"},
  };
  for (const auto& k : cases) {
    const std::string v = refs_variant("bad_" + k.name);
    const std::string file = k.make(v);
    for (const char* fmt : {"", " --json"}) {
      const ProcessResult r = run_tool("decode " + meas_capture(4) + " --family M1 --references " + v + fmt);
      SCOPED_TRACE(k.name + std::string(fmt) + ": " + r.err);
      EXPECT_EQ(r.status, 2);
      EXPECT_TRUE(r.out.empty()) << r.out;
      EXPECT_NE(r.err.find(file), std::string::npos) << "names " << file;
      EXPECT_NE(r.err.find(k.expect), std::string::npos);
    }
  }
}

}  // namespace
