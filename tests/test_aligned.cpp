// AlignedVector / BufferVector (model/base/aligned.hpp): the alignment of small blocks, and the
// huge-page path of large ones (2 MiB aligned, advised MADV_HUGEPAGE), across reallocations.
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <limits>
#include <new>
#include <numeric>
#include <sstream>
#include <string>

#include "model/base/aligned.hpp"

namespace ranging {
namespace {

std::uintptr_t address(const void* p) { return reinterpret_cast<std::uintptr_t>(p); }

// The VmFlags of the mapping of /proc/self/smaps that holds p ("" if none does).
std::string vm_flags_at(const void* p) {
  std::ifstream in("/proc/self/smaps");
  std::string line;
  bool inside = false;
  while (std::getline(in, line)) {
    std::uintptr_t lo = 0, hi = 0;
    char dash = 0;
    std::istringstream head(line);
    if (head >> std::hex >> lo >> dash >> hi && dash == '-') {
      inside = address(p) >= lo && address(p) < hi;
    } else if (inside && line.rfind("VmFlags:", 0) == 0) {
      return line;
    }
  }
  return "";
}

TEST(Aligned, SmallBlocksStartOnA64ByteBoundary) {
  for (std::size_t n : {1u, 3u, 1000u, 100000u}) {
    AlignedVector<double> v(n);
    EXPECT_EQ(address(v.data()) % 64, 0u) << n;
    BufferVector<float> b(n);
    EXPECT_EQ(address(b.data()) % 64, 0u) << n;
  }
}

TEST(Aligned, LargeBlocksStartOnAHugePageAndAreAdvisedHuge) {
  const std::size_t n = kHugeBufferMin / sizeof(double);  // the smallest block of the huge path
  AlignedVector<double> v(n, 1.5);
  EXPECT_EQ(address(v.data()) % kHugePage, 0u);
  EXPECT_EQ(std::accumulate(v.begin(), v.end(), 0.0), 1.5 * static_cast<double>(n));
  // MADV_HUGEPAGE shows as "hg" in the mapping's flags (Linux 3.8 on), in a kernel with THP
  if (!std::ifstream("/sys/kernel/mm/transparent_hugepage/enabled")) return;  // madvise: EINVAL
  const std::string flags = vm_flags_at(v.data());
  ASSERT_FALSE(flags.empty()) << "no mapping of /proc/self/smaps holds the block";
  EXPECT_NE(flags.find(" hg"), std::string::npos) << flags;
  // one byte short of the threshold: the ordinary path
  AlignedVector<char> c(kHugeBufferMin - 1);
  EXPECT_EQ(address(c.data()) % 64, 0u);
}

TEST(Aligned, ASizeBeyondHalfTheAddressSpaceIsRefused) {
  // (the rounding up to whole huge pages would otherwise wrap around)
  AlignedAllocator<double> a;
  EXPECT_THROW((void)a.allocate(std::numeric_limits<std::size_t>::max() / sizeof(double)), std::bad_array_new_length);
  EXPECT_THROW((void)a.allocate((std::numeric_limits<std::size_t>::max() >> 1) / sizeof(double)), std::bad_array_new_length);
}

TEST(Aligned, GrowingAcrossTheThresholdKeepsTheValues) {
  // a stream window's life: small, then large (huge path), then shrunk back (each block freed by
  // the path that allocated it: ASan reports a mismatch)
  BufferVector<double> w;
  std::size_t filled = 0;
  for (std::size_t n = 1000; n <= 3 * kHugeBufferMin / sizeof(double); n *= 2) {
    w.resize(n);
    for (; filled < n; ++filled) w[filled] = static_cast<double>(filled);
    if (n * sizeof(double) >= kHugeBufferMin) {
      EXPECT_EQ(address(w.data()) % kHugePage, 0u) << n;
    }
  }
  for (std::size_t i = 0; i < filled; ++i) ASSERT_EQ(w[i], static_cast<double>(i)) << i;
  w.resize(500);
  w.shrink_to_fit();
  EXPECT_EQ(address(w.data()) % 64, 0u);
  for (std::size_t i = 0; i < w.size(); ++i) ASSERT_EQ(w[i], static_cast<double>(i)) << i;
}

}  // namespace
}  // namespace ranging
