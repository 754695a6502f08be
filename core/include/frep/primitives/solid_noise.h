// Solid noise (Pasko-Survey, 3D texture: a continuous pseudo-random function of three
// variables is itself an F-rep primitive): Perlin's gradient noise on the integer lattice with
// the quintic fade 6t^5 - 15t^4 + 10t^3 (C^2), summed over octaves of doubling frequency and
// halving weight, and scaled so that |value| <= 1 everywhere (proved, not sampled: see
// kPerlinBound). bound() is the value at the box centre plus the Lipschitz constant per axis
// times the box's half-widths, clipped to [-1, 1]: sound for any box, tight for small ones.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>

#include "frep/expressions/field_function.h"

namespace frep {

class SolidNoise final : public FieldFunction {
 public:
  // One octave's |value| <= sqrt(3/2): each corner term is g.d with |g| = sqrt(2), and the fade
  // weights W_c (summing to 1) give sum W_c |d_c| <= sqrt(sum W_c |d_c|^2) <= sqrt(3/4), since
  // per axis (1 - s(t)) t^2 + s(t) (1 - t)^2 <= 1/4 (s is convex on [0, 1/2] below the chord t).
  static constexpr double kPerlinBound = 1.2247448713915890491;
  // One octave's |d value / d x_i| <= 1 + 4 max s' = 8.5 (the fade's slope s' <= 15/8; the
  // difference of two corner terms g.d along an axis is at most 4, each |g.d| <= 2).
  static constexpr double kPerlinSlope = 8.5;

  // frequency > 0 (lattice cells per unit length of the first octave), 1 <= octaves <= 16.
  // Throws std::invalid_argument naming the bad value.
  static std::shared_ptr<const SolidNoise> make(double frequency, uint32_t seed, int octaves);

  double frequency() const { return frequency_; }
  int octaves() const { return octaves_; }
  // Bound on |d value / d x_i| for each axis: the same on all three.
  double lipschitz() const { return lipschitz_; }

  std::string describe() const override;
  uint64_t contentHash() const override { return hash_; }
  bool sameContent(const FieldFunction& other) const override;
  double value(const double p[3]) const override;
  double gradient(const double p[3], double g[3]) const override;
  Interval bound(const Interval box[3]) const override;

  // One octave of the lattice noise (unscaled, |value| <= kPerlinBound), for the tests.
  double perlin(const double p[3], double* grad) const;

 private:
  SolidNoise() = default;
  double eval(const double p[3], double* grad) const;

  double frequency_ = 1.0;
  uint32_t seed_ = 0;
  int octaves_ = 1;
  double scale_ = 1.0;      // 1 / (kPerlinBound * sum of octave weights)
  double lipschitz_ = 0.0;  // per axis, after scaling
  std::array<uint8_t, 512> perm_{};
  std::array<std::array<double, 3>, 16> shift_{};  // per-octave offsets of the lattice
  uint64_t hash_ = 0;
};

}  // namespace frep
