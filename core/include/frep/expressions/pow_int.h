// Integer powers by repeated squaring: the one definition every evaluator uses, so that
// PowI gives the same bits in the point, batch and interval (endpoint) evaluations.
#pragma once

namespace frep {

template <typename T>
inline T powInt(T a, int n) {
  bool neg = n < 0;
  unsigned m = neg ? -static_cast<unsigned>(n) : static_cast<unsigned>(n);
  T r = 1, b = a;
  while (m) {
    if (m & 1u) r *= b;
    b *= b;
    m >>= 1;
  }
  return neg ? T(1) / r : r;
}

}  // namespace frep
