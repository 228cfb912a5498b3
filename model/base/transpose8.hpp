#pragma once
// transpose8(r): an 8 x 8 transpose of eight 8-lane vectors (GCC/clang vector extensions, any
// element type): r[l] holds lane l's 8 consecutive values before, r[i] holds value i of every
// lane after. Three stages of two-source shuffles (1-, 2-, then 4-element blocks), 24 in all;
// no ISA of its own, so a function built for the baseline and its AVX-512 clone both use it.
// Used by the batch receiver's lane (de)interleaving and the Pearson search's chunked sums.

namespace ranging {

template <class T>
inline void transpose8(T (&r)[8]) {  // __builtin_shufflevector: GCC >= 12 and clang
  T a[8], b[8];
  for (int k = 0; k < 8; k += 2) {
    a[k] = __builtin_shufflevector(r[k], r[k + 1], 0, 8, 2, 10, 4, 12, 6, 14);
    a[k + 1] = __builtin_shufflevector(r[k], r[k + 1], 1, 9, 3, 11, 5, 13, 7, 15);
  }
  for (int k = 0; k < 8; k += 4) {
    for (int m = 0; m < 2; ++m) {
      b[k + m] = __builtin_shufflevector(a[k + m], a[k + m + 2], 0, 1, 8, 9, 4, 5, 12, 13);
      b[k + m + 2] = __builtin_shufflevector(a[k + m], a[k + m + 2], 2, 3, 10, 11, 6, 7, 14, 15);
    }
  }
  for (int m = 0; m < 4; ++m) {
    r[m] = __builtin_shufflevector(b[m], b[m + 4], 0, 1, 2, 3, 8, 9, 10, 11);
    r[m + 4] = __builtin_shufflevector(b[m], b[m + 4], 4, 5, 6, 7, 12, 13, 14, 15);
  }
}

}  // namespace ranging
