#pragma once
// AlignedAllocator<T, A>: a std::allocator whose blocks start on an A-byte boundary (A a power of
// two >= alignof(T)), so a vector's data can be read by whole 64-byte SIMD loads that never
// straddle two cache lines (malloc gives 16: a large block starts 16 bytes into a page, and every
// AVX-512 load of it then touches two lines). AlignedVector<T> = std::vector of 64-byte aligned data.
#include <cstddef>
#include <new>
#include <vector>

namespace ranging {

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
  T* allocate(std::size_t n) { return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t{A})); }
  void deallocate(T* p, std::size_t) { ::operator delete(p, std::align_val_t{A}); }
  template <class U>
  bool operator==(const AlignedAllocator<U, A>&) const {
    return true;
  }
};

template <class T>
using AlignedVector = std::vector<T, AlignedAllocator<T, 64>>;

}  // namespace ranging
