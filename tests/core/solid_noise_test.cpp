// Solid noise (frep/primitives/solid_noise.h): the proved range and slope bounds against dense
// samples, the gradient against central differences, and bound() against sampled values.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "frep/primitives/solid_noise.h"

namespace frep {
namespace {

TEST(SolidNoise, ValuesStayWithinTheProvedRange) {
  auto n = SolidNoise::make(1.0, 7, 1);
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> U(-20, 20);
  double worst = 0.0;
  for (int i = 0; i < 200000; ++i) {
    const double p[3] = {U(rng), U(rng), U(rng)};
    worst = std::max(worst, std::fabs(n->perlin(p, nullptr)));
  }
  EXPECT_LE(worst, SolidNoise::kPerlinBound);
  EXPECT_GT(worst, 0.5);  // a noise, not a constant
  auto f = SolidNoise::make(2.5, 3, 5);
  for (int i = 0; i < 50000; ++i) {
    const double p[3] = {U(rng), U(rng), U(rng)};
    ASSERT_LE(std::fabs(f->value(p)), 1.0);
  }
}

TEST(SolidNoise, ZeroAtLatticePointsAndContinuousAcrossCells) {
  auto n = SolidNoise::make(1.0, 11, 1);
  for (int i = -3; i <= 3; ++i) {
    const double p[3] = {double(i), double(2 * i), -5.0};
    EXPECT_EQ(n->perlin(p, nullptr), 0.0);
  }
  // Across the face x = 4 the two cells agree (value and slope).
  const double a[3] = {4 - 1e-9, 0.3, 0.7}, b[3] = {4 + 1e-9, 0.3, 0.7};
  double ga[3], gb[3];
  EXPECT_NEAR(n->perlin(a, ga), n->perlin(b, gb), 1e-7);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(ga[k], gb[k], 1e-6);
}

TEST(SolidNoise, GradientMatchesCentralDifferencesAndTheSlopeBound) {
  auto n = SolidNoise::make(1.7, 5, 3);
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> U(-5, 5);
  double steepest = 0.0;
  for (int i = 0; i < 2000; ++i) {
    double p[3] = {U(rng), U(rng), U(rng)}, g[3];
    n->gradient(p, g);
    for (int k = 0; k < 3; ++k) {
      const double h = 1e-6;
      double q[3] = {p[0], p[1], p[2]};
      q[k] += h;
      const double up = n->value(q);
      q[k] -= 2 * h;
      const double down = n->value(q);
      EXPECT_NEAR(g[k], (up - down) / (2 * h), 1e-5 * std::max(1.0, std::fabs(g[k])));
      steepest = std::max(steepest, std::fabs(g[k]));
    }
  }
  EXPECT_LE(steepest, n->lipschitz());
}

TEST(SolidNoise, BoundsContainSampledValues) {
  auto n = SolidNoise::make(3.0, 9, 4);
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> U(-2, 2), T(0, 1);
  for (double w : {1e-4, 1e-2, 0.1, 1.0}) {
    for (int b = 0; b < 300; ++b) {
      Interval box[3];
      for (auto& iv : box) {
        const double lo = U(rng);
        iv = Interval(lo, lo + w * T(rng));
      }
      const Interval r = n->bound(box);
      ASSERT_LE(r.lo, r.hi);
      for (int s = 0; s < 30; ++s) {
        const double p[3] = {box[0].lo + box[0].width() * T(rng), box[1].lo + box[1].width() * T(rng),
                             box[2].lo + box[2].width() * T(rng)};
        const double v = n->value(p);
        ASSERT_GE(v, r.lo);
        ASSERT_LE(v, r.hi);
      }
      // Never wider than the slope over the half-widths, both ways (tight for small boxes).
      ASSERT_LE(r.width(), n->lipschitz() * (box[0].width() + box[1].width() + box[2].width()) * (1 + 1e-9) + 1e-11);
    }
  }
}

TEST(SolidNoise, BadParametersAreRejected) {
  EXPECT_THROW(SolidNoise::make(0.0, 1, 1), std::invalid_argument);
  EXPECT_THROW(SolidNoise::make(1.0, 1, 0), std::invalid_argument);
  EXPECT_THROW(SolidNoise::make(1.0, 1, 17), std::invalid_argument);
  // Different seeds give different noise; the same parameters the same.
  auto a = SolidNoise::make(1.0, 1, 2), b = SolidNoise::make(1.0, 2, 2), c = SolidNoise::make(1.0, 1, 2);
  const double p[3] = {0.37, 1.21, -0.4};
  EXPECT_NE(a->value(p), b->value(p));
  EXPECT_EQ(a->value(p), c->value(p));
  EXPECT_TRUE(a->sameContent(*c));
  EXPECT_FALSE(a->sameContent(*b));
}

}  // namespace
}  // namespace frep
