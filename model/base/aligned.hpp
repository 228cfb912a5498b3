#pragma once
// AlignedAllocator<T, A>: a std::allocator whose blocks start on an A-byte boundary (A a power of
// two >= alignof(T)), so a vector's data can be read by whole 64-byte SIMD loads that never
// straddle two cache lines (malloc gives 16: a large block starts 16 bytes into a page, and every
// AVX-512 load of it then touches two lines). AlignedVector<T> = std::vector of 64-byte aligned data.
#include <cstddef>
#include <new>
#include <type_traits>
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
