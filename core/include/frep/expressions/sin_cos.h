// sin and cos as every evaluator computes them (point, batch, gradient; the interval evaluator
// widens by the error bound below): the one definition, so that all give the same bits, and
// written as straight-line arithmetic so that the batch evaluator's lane loops vectorise
// (libm's sin/cos are calls per lane).
//
// Method: Cody-Waite reduction x = k pi/2 + r with pi/2 = P1 + P2, P1 of 31 bits (k P1 exact for
// |k| < 2^22, and x - k P1 exact by Sterbenz's lemma), then polynomials in z = r^2 on
// |r| <= pi/4 (+ rounding) of degree 13 (sin) and 14 (cos) fitted below (< 0.1 ulp), and the
// quadrant k mod 4 picks +-sin(r) or +-cos(r). Only + - * in IEEE double: with -ffp-contract=off
// the bits are the same for every ISA clone and every machine. |x| > kOwnTrigLimit, infinities
// and NaN go to libm (the batch evaluator takes a scalar path for a batch holding such a lane).
//
// Error (tests/core/own_sin_cos_test.cpp measures it against long double, max ~1.5 ulp): within
// kOwnTrigUlps ulps of the true value (0.5 ulp of r from the rounded subtraction, 0.5 ulp final
// rounding, 0.5 ulp from 1 - z/2 in cos, < 0.1 ulp from the polynomials) plus an absolute
// kOwnTrigAbsErr, which covers the reduction near zeros of sin/cos: the rounding of k P2
// (<= 2^-54 * 2^19 * 6.1e-11 = 3.4e-21) and the tail of pi/2 - (P1 + P2) (3.5e-27 * |k| <= 2^19).
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

namespace frep {

constexpr double kOwnTrigLimit = 0x1p19;   // |x| above this: libm
constexpr int kOwnTrigUlps = 2;            // relative part of the error bound
constexpr double kOwnTrigAbsErr = 0x1p-64; // absolute part (5.4e-20 > 2^19 * 3.5e-27 + 3.4e-21)

namespace trig_detail {

// pi/2 = P1 + P2 + 3.5e-27: P1 with 31 significant bits (k P1 exact for |k| < 2^22), P2 the
// rest rounded to double.
constexpr double kP1 = 0x1.921fb544p+0;
constexpr double kP2 = 0x1.0b4611a626331p-34;
constexpr double kTwoOverPi = 6.36619772367581382433e-01;
constexpr double kRound = 0x1.8p52;  // (t + kRound) - kRound rounds t to an integer, |t| < 2^51

constexpr double fact(int n) { return n <= 1 ? 1.0 : n * fact(n - 1); }  // exact up to 22!

// sin and cos of r for |r| <= pi/4 (a hair more after rounding of k): sin r = r + r^3 S(z),
// cos r = 1 - z/2 + z^2 C(z), z = r^2, with S and C of degree 5: Chebyshev fits (mpmath chebyfit,
// 50 digits) of (sin r - r) / r^3 and (cos r - 1 + z/2) / z^2 over z in [0, 1.0001 (pi/4)^2];
// with the coefficients rounded to double, relative error 2.0e-17 (sin) and 1.3e-18 (cos).
inline void kernel(double r, double& s, double& c) {
  const double z = r * r;
  double ps = 0x1.5e0b05bff20f2p-33;
  ps = ps * z - 0x1.ae600aca92c64p-26;
  ps = ps * z + 0x1.71de379654304p-19;
  ps = ps * z - 0x1.a01a019e83816p-13;
  ps = ps * z + 0x1.1111111110bb2p-7;
  ps = ps * z - 0x1.5555555555555p-3;
  s = std::copysign(r + r * z * ps, r);  // sin(r) has the sign of r: sin(-0) = -0, as libm's
  double pc = -0x1.907d8f29fe831p-37;
  pc = pc * z + 0x1.1eeb68cd22f56p-29;
  pc = pc * z - 0x1.27e4fa17bf139p-22;
  pc = pc * z + 0x1.a01a019f4e9b4p-16;
  pc = pc * z - 0x1.6c16c16c16967p-10;
  pc = pc * z + 0x1.5555555555555p-5;
  c = (1.0 - 0.5 * z) + z * z * pc;
}

// Float lanes (the float batch path only), in float arithmetic so that a vector holds twice the
// lanes: pi/2 = F1 + F2 + F3 with 11-bit F1, F2 (k * F exact for |k| < 2^13) and a 24-bit F3
// (tail 1.7e-15); Taylor sin to r^9, cos to r^10 (truncation < 3e-9 relative).
constexpr float kF1 = 0x1.92p+0f, kF2 = 0x1.fb4p-12f, kF3 = 0x1.4442d2p-24f;
constexpr float kTwoOverPiF = 0x1.45f306p-1f;
constexpr float kRoundF = 0x1.8p23f;  // (t + kRoundF) - kRoundF rounds t, |t| < 2^22

inline void kernelFloat(float r, float& s, float& c) {
  const float z = r * r;
  float ps = float(1 / fact(9));
  ps = ps * z - float(1 / fact(7));
  ps = ps * z + float(1 / fact(5));
  ps = ps * z - float(1 / fact(3));
  s = std::copysign(r + r * z * ps, r);  // sin(-0) = -0
  float pc = float(-1 / fact(10));
  pc = pc * z + float(1 / fact(8));
  pc = pc * z - float(1 / fact(6));
  pc = pc * z + float(1 / fact(4));
  const float h = 0.5f * z, w = 1.0f - h;
  c = w + (((1.0f - w) - h) + z * z * pc);
}

}  // namespace trig_detail

// Both for |x| <= kOwnTrigLimit (no check: the caller tests ownTrigInRange).
inline void ownSinCosInRange(double x, double& sinX, double& cosX) {
  using namespace trig_detail;
  const double kb = x * kTwoOverPi + kRound;
  const double k = kb - kRound;
  uint64_t bits;
  std::memcpy(&bits, &kb, sizeof bits);  // low mantissa bits of kb: k mod 4 (kRound = 3 * 2^51)
  const double r = (x - k * kP1) - k * kP2;  // x - k P1 exact; k P2 and the subtraction rounded
  double s, c;
  trig_detail::kernel(r, s, c);
  const bool swap = bits & 1;
  const double sv = swap ? c : s, cv = swap ? s : c;
  uint64_t sb, cb;  // signs: sin negative for k mod 4 in {2, 3}, cos for {1, 2}
  std::memcpy(&sb, &sv, sizeof sb);
  std::memcpy(&cb, &cv, sizeof cb);
  sb ^= (bits & 2) << 62;
  cb ^= ((bits + 1) & 2) << 62;
  std::memcpy(&sinX, &sb, sizeof sb);
  std::memcpy(&cosX, &cb, sizeof cb);
}

inline bool ownTrigInRange(double x) { return std::fabs(x) <= kOwnTrigLimit; }  // false for NaN

inline double ownSin(double x) {
  if (!ownTrigInRange(x)) return std::sin(x);
  double s, c;
  ownSinCosInRange(x, s, c);
  return s;
}
inline double ownCos(double x) {
  if (!ownTrigInRange(x)) return std::cos(x);
  double s, c;
  ownSinCosInRange(x, s, c);
  return c;
}
inline void ownSinCos(double x, double& s, double& c) {
  if (ownTrigInRange(x)) {
    ownSinCosInRange(x, s, c);
  } else {
    s = std::sin(x);
    c = std::cos(x);
  }
}

// Float lanes: within 2 float ulps of the true value plus 1e-9 absolute (the float reduction) for
// |x| <= kOwnTrigLimitFloat; beyond, the double functions rounded to float. Only the float batch
// path uses these (tests/core/own_sin_cos_test.cpp measures them).
constexpr float kOwnTrigLimitFloat = 0x1p13f;
inline bool ownTrigInRangeFloat(float x) { return std::fabs(x) <= kOwnTrigLimitFloat; }

inline void ownSinCosInRangeFloat(float x, float& sinX, float& cosX) {
  using namespace trig_detail;
  const float kb = x * kTwoOverPiF + kRoundF;
  const float k = kb - kRoundF;
  uint32_t bits;
  std::memcpy(&bits, &kb, sizeof bits);  // low mantissa bits of kb: k mod 4 (kRoundF = 3 * 2^22)
  const float r = ((x - k * kF1) - k * kF2) - k * kF3;
  float s, c;
  kernelFloat(r, s, c);
  const bool swap = bits & 1, negSin = bits & 2, negCos = (bits + 1) & 2;
  const float sv = swap ? c : s, cv = swap ? s : c;
  sinX = negSin ? -sv : sv;
  cosX = negCos ? -cv : cv;
}
inline void ownSinCosFloat(float x, float& s, float& c) {
  if (ownTrigInRangeFloat(x)) {
    ownSinCosInRangeFloat(x, s, c);
  } else {
    double sd, cd;
    ownSinCos(double(x), sd, cd);
    s = float(sd);
    c = float(cd);
  }
}

}  // namespace frep
