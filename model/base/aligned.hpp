#pragma once
// AlignedAllocator<T, A>: a std::allocator whose blocks start on an A-byte boundary (A a power of
// two >= alignof(T)), so a vector's data can be read by whole 64-byte SIMD loads that never
// straddle two cache lines (malloc gives 16: a large block starts 16 bytes into a page, and every
// AVX-512 load of it then touches two lines). AlignedVector<T> = std::vector of 64-byte aligned data.
// A block of kHugeBufferMin (1 MiB) or more is rounded up to whole kHugePage (2 MiB) pages, starts
// on a 2 MiB boundary and is advised MADV_HUGEPAGE, so the kernel can back it with transparent huge
// pages (where /sys/kernel/mm/transparent_hugepage/enabled is "always" or "madvise"): one page
// fault per 2 MiB instead of 512, each of which costs 10-14 us in a virtual machine (a streaming
// decode's buffers, model/sim/scene_simulator.cpp). Rounding wastes less than half of such a
// block; where the kernel gives no huge page the advice is ignored and the block is plain memory.
#include <sys/mman.h>

#include <cstddef>
#include <limits>
#include <new>
#include <type_traits>
#include <vector>

namespace ranging {

inline constexpr std::size_t kHugePage = std::size_t{2} << 20;       // x86-64's transparent huge page
inline constexpr std::size_t kHugeBufferMin = std::size_t{1} << 20;  // blocks from here on: huge pages

template <class T, std::size_t A = 64>
struct AlignedAllocator {
  static_assert(A >= alignof(T) && (A & (A - 1)) == 0, "AlignedAllocator: A must be a power of two >= alignof(T)");
  using value_type = T;
  template <class U>
  struct rebind {
    using other = AlignedAllocator<U, A>;
  };
  AlignedAllocator() = default;
  template <class U>
  AlignedAllocator(const AlignedAllocator<U, A>&) {}
  T* allocate(std::size_t n) {
    // (std::vector never asks for more than max_size(); this bound also keeps the rounding finite)
    if (n > ((std::numeric_limits<std::size_t>::max() >> 1) - kHugePage) / sizeof(T)) throw std::bad_array_new_length();
    const std::size_t bytes = n * sizeof(T);
    if (huge(n)) {
      const std::size_t r = (bytes + kHugePage - 1) / kHugePage * kHugePage;
      void* p = ::operator new(r, std::align_val_t{kHugePage});
      (void)::madvise(p, r, MADV_HUGEPAGE);  // a hint: EINVAL (no THP in this kernel) changes nothing
      return static_cast<T*>(p);
    }
    return static_cast<T*>(::operator new(bytes, std::align_val_t{A}));
  }
  void deallocate(T* p, std::size_t n) {
    if (huge(n)) return ::operator delete(p, std::align_val_t{kHugePage});
    ::operator delete(p, std::align_val_t{A});
  }
  // a block of n elements takes the huge-page path (allocate and deallocate decide alike)
  static bool huge(std::size_t n) { return n * sizeof(T) >= kHugeBufferMin; }
  template <class U>
  bool operator==(const AlignedAllocator<U, A>&) const {
    return true;
  }
};

template <class T>
using AlignedVector = std::vector<T, AlignedAllocator<T, 64>>;

// BufferVector<T>: an AlignedVector whose resize() leaves the new elements default-initialized
// (for double: no zero fill, no write at all), for a buffer that is always written before it is
// read. A growing stream window then costs no pass over fresh memory (zeroing it is a page fault
// per 4 KiB on top of the write that follows).
template <class T>
struct BufferAllocator : AlignedAllocator<T, 64> {
  template <class U>
  struct rebind {
    using other = BufferAllocator<U>;
  };
  BufferAllocator() = default;
  template <class U>
  BufferAllocator(const BufferAllocator<U>&) {}
  // (only the no-argument form: std::allocator_traits constructs with arguments by itself)
  template <class U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
};

template <class T>
using BufferVector = std::vector<T, BufferAllocator<T>>;

}  // namespace ranging
