// The branch-and-bound's term form (core/src/extremum/extremum_terms.h): the min-of-terms rewrite, the
// soundness of constraint propagation against a cut (random boxes: no sampled point that
// reaches the cut is ever cut off, and the interval bounds hold every sampled value), the local
// ascent, end-to-end certification of B&B results against dense sampling, and identical sampled
// values for any brick split.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>

#include "../../core/src/extremum/extremum_terms.h"
#include "frep/evaluators/eval.h"
#include "frep/extremum/extremum.h"
#include "frep/primitives/ops.h"
#include "frep/sampling/sample.h"

using namespace frep;

namespace {

Expr x(uint32_t i) { return Expr::x(i); }
Expr len3(const Expr& a, const Expr& b, const Expr& c) { return sqrt(square(a) + square(b) + square(c)); }
Expr box3(const Expr& a, const Expr& b, const Expr& c, double h) { return min(min(h - abs(a), h - abs(b)), h - abs(c)); }

// Bodies over (X, u) with n = 3 outer and m = 3 hidden variables: Minkowski-like intersections
// (a = 1, 0, 0.5), an erosion-like max, smooth and nested forms.
std::vector<Expr> bodies() {
  const Expr d0 = x(0) - x(3), d1 = x(1) - x(4), d2 = x(2) - x(5);
  const Expr A = min(box3(d0, d1, d2, 1.0), len3(d0, d1, d2) - 1.2);  // cube minus ball
  const Expr B = 0.5 - len3(x(3), x(4), x(5));
  return {
      min(A, B),
      rAnd(A, B, 0.0),
      rAnd(A, B, 0.5),
      -max(-A, len3(x(3), x(4), x(5)) - 0.5),
      rOr(min(A, B), 0.2 - abs(d0 * d1) - square(x(5)), 0.0),
      min(A + 0.3 * sin(3.0 * x(3)) * cos(2.0 * x(4)), B * (1.0 + 0.5 * square(x(5)))),
      min(exp(-square(d0)) - 0.5, select(gt(x(3), 0.0), B, B - 0.1)),
  };
}

double eval(const Expr& e, const std::vector<double>& p) {
  PointEvaluator pe;
  return pe.eval(*Tape::compile(e, uint32_t(p.size())), p.data());
}

// A random outer point X in [-1.5, 1.5]^3 and a random parameter box [lo, hi] inside
// [-0.5, 0.5]^3 whose sides are 10^-decades .. 1 (log-uniform).
std::vector<double> randomPointAndBox(std::mt19937_64& rng, std::uniform_real_distribution<double>& U,
                                      double decades, double* lo, double* hi) {
  std::vector<double> X = {3 * U(rng) - 1.5, 3 * U(rng) - 1.5, 3 * U(rng) - 1.5};
  for (int k = 0; k < 3; ++k) {
    const double w = std::pow(10.0, -decades * U(rng));
    lo[k] = -0.5 + (1.0 - w) * U(rng);
    hi[k] = lo[k] + w;
  }
  return X;
}

}  // namespace

TEST(ExtremumTerms, MinOfTermsEqualsTheBody) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> U(-1.5, 1.5);
  for (const Expr& body : bodies()) {
    const std::vector<Expr> terms = detail::minTerms(body);
    ASSERT_GE(terms.size(), 1u);
    ASSERT_LE(terms.size(), detail::kMaxTerms);
    std::vector<TapePtr> tapes;
    for (const Expr& t : terms) tapes.push_back(Tape::compile(t, 6));
    TapePtr whole = Tape::compile(body, 6);
    PointEvaluator pe;
    for (int i = 0; i < 500; ++i) {
      std::vector<double> p(6);
      for (double& v : p) v = U(rng);
      double m = std::numeric_limits<double>::infinity();
      for (const TapePtr& t : tapes) m = std::min(m, pe.eval(*t, p.data()));
      const double g = pe.eval(*whole, p.data());
      ASSERT_EQ(m, g) << toString(body);  // bit for bit: the rewrite only moves exact operations
    }
  }
  // |a| splits into a and -a; sums distribute over min; an R-function stays one term.
  EXPECT_EQ(detail::minTerms(1.0 - abs(x(0))).size(), 2u);
  EXPECT_EQ(detail::minTerms(min(x(0), x(1)) + min(x(2), x(3))).size(), 4u);
  EXPECT_EQ(detail::minTerms(rAnd(min(x(0), x(1)), x(2), 0.0)).size(), 1u);
}

// Soundness of TermForm::contract: random X, boxes and cuts; every sampled point of the box whose
// (computed) body value reaches the cut must survive in the contracted box, and the bounds hold
// every sampled value.
TEST(ExtremumTerms, ContractionNeverLosesAPointAboveTheCut) {
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  int contracted = 0, emptied = 0, checked = 0;
  for (const Expr& body0 : bodies()) {
    for (int sign = 0; sign < 2; ++sign) {
      const Expr body = sign ? -body0 : body0;
      detail::TermForm tf;
      tf.build(body, 3, 3, {x(3), x(4), x(5)});
      ASSERT_TRUE(tf.ok());
      TapePtr tape = Tape::compile(body, 6);
      PointEvaluator pe;
      for (int trial = 0; trial < 150; ++trial) {
        double lo[3], hi[3];
        const std::vector<double> X = randomPointAndBox(rng, U, 2.0, lo, hi);  // sides 0.01 .. 1
        // sample the box (corners included) and pick a cut among the sampled values
        std::vector<std::array<double, 4>> pts;
        double p[6] = {X[0], X[1], X[2], 0, 0, 0};
        for (int s = 0; s < 400; ++s) {
          for (int k = 0; k < 3; ++k)
            p[3 + k] = s < 8 ? ((s >> k) & 1 ? hi[k] : lo[k]) : lo[k] + (hi[k] - lo[k]) * U(rng);
          pts.push_back({p[3], p[4], p[5], pe.eval(*tape, p)});
        }
        std::vector<double> vals;
        for (auto& q : pts) vals.push_back(q[3]);
        std::sort(vals.begin(), vals.end());
        const double theta = trial % 3 == 0 ? vals.back() + 0.01 * U(rng) : vals[size_t(U(rng) * 399)];
        tf.setX(X.data());
        double clo[3] = {lo[0], lo[1], lo[2]}, chi[3] = {hi[0], hi[1], hi[2]};
        double ub = 0, ub0 = 0;
        uint32_t passes = 0;
        const bool alive = tf.contract(clo, chi, theta, ub, ub0, passes);
        EXPECT_GE(passes, 1u);
        bool shrunk = false;
        for (int k = 0; k < 3; ++k) shrunk = shrunk || clo[k] > lo[k] || chi[k] < hi[k];
        contracted += alive && shrunk;
        emptied += !alive;
        for (auto& q : pts) {
          ++checked;
          ASSERT_LE(q[3], ub0 + 1e-12 * (1.0 + std::fabs(ub0))) << toString(body);
          if (q[3] < theta) continue;
          ASSERT_TRUE(alive) << "cut " << theta << " value " << q[3] << " in " << toString(body);
          for (int k = 0; k < 3; ++k) {
            ASSERT_GE(q[k], clo[k]);
            ASSERT_LE(q[k], chi[k]);
          }
          ASSERT_LE(q[3], ub + 1e-12 * (1.0 + std::fabs(ub)));
        }
      }
    }
  }
  // the test exercises both outcomes
  EXPECT_GT(contracted, 50);
  EXPECT_GT(emptied, 50);
  EXPECT_GT(checked, 100000);
}

// Soundness of the centred bound (interval gradients, mean-value form and the weighted
// combination of terms): on random boxes of every size it is >= every sampled value, for box
// parameters and for the ball's polar parameters (u = r (cos a cos b, ...)); and on small
// boxes around a smooth maximum it is far tighter than the natural bound.
TEST(ExtremumTerms, CentredBoundHoldsEverySampledValue) {
  std::mt19937_64 rng(15);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const Expr r = x(3), a = x(4), b = x(5);
  const std::vector<Expr> polar = {r * cos(a), r * sin(a) * cos(b), r * sin(a) * sin(b)};
  int tighter = 0, checked = 0;
  for (int param = 0; param < 2; ++param) {
    for (const Expr& body : bodies()) {
      detail::TermForm tf;
      tf.build(body, 3, 3, param ? polar : std::vector<Expr>{x(3), x(4), x(5)});
      ASSERT_TRUE(tf.ok());
      const Expr objective = param ? remap(body, {x(0), x(1), x(2), polar[0], polar[1], polar[2]}) : body;
      TapePtr tape = Tape::compile(objective, 6);
      PointEvaluator pe;
      IntervalEvaluator ie;
      for (int trial = 0; trial < 100; ++trial) {
        double lo[3], hi[3];
        const std::vector<double> X = randomPointAndBox(rng, U, 3.0, lo, hi);  // sides 0.001 .. 1
        tf.setX(X.data());
        const double ub = tf.upper(lo, hi);
        Interval box[6] = {X[0], X[1], X[2], {lo[0], hi[0]}, {lo[1], hi[1]}, {lo[2], hi[2]}};
        const double natural = ie.eval(*tape, box).hi;
        tighter += ub < natural - 1e-9;
        double p[6] = {X[0], X[1], X[2], 0, 0, 0};
        for (int s = 0; s < 300; ++s) {
          for (int k = 0; k < 3; ++k)
            p[3 + k] = s < 8 ? ((s >> k) & 1 ? hi[k] : lo[k]) : lo[k] + (hi[k] - lo[k]) * U(rng);
          const double v = pe.eval(*tape, p);
          ++checked;
          ASSERT_LE(v, ub) << toString(body) << (param ? " (polar)" : "");
        }
      }
    }
  }
  EXPECT_GT(tighter, 100);  // measured 183 of 1400 boxes (large boxes: the natural bound wins)
  EXPECT_GT(checked, 100000);
}

// Ball (+) ball with the paper's a = 0 R-intersection and quadratic (not distance) operands: a
// smooth maximum, where the natural bound needs ~(1/tol)^(3/2) boxes. The centred bound
// certifies 1e-4.
TEST(ExtremumTerms, SmoothMaximumCertifiesTightTolerance) {
  const Expr ball = 1.0 - square(x(0)) - square(x(1)) - square(x(2));
  MinkowskiOptions o;
  o.tolerance = 1e-4;
  o.a = 0.0;
  o.maxBoxes = 50000;
  TapePtr t = Tape::compile(minkowskiSum(ball, ball, 3, {{-1, -1, -1}, {1, 1, 1}}, o));
  ExtremumSolver solver(t->extrema()[0].spec, t->extrema()[0].body);
  std::mt19937_64 rng(16);
  std::uniform_real_distribution<double> U(-2.2, 2.2);
  for (int i = 0; i < 10; ++i) {
    const double p[3] = {U(rng), U(rng), U(rng)};
    ExtremumResult r = solver.solveBranchAndBound(p);
    ASSERT_TRUE(r.certified);
    EXPECT_LE(r.hi - r.lo, 1e-4 * (1 + 1e-9));
    // Pasko-Minkowski eq. 4.1 up to the positive factor (2 - sqrt 2) / 4 inside (extremum.md)
    const double q = 4.0 - (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    if (q > 0) {
      EXPECT_NEAR(r.value, (2.0 - std::sqrt(2.0)) / 4.0 * q, 1e-4);
    }
  }
}

TEST(ExtremumTerms, AscentOnlyClimbs) {
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> U(-0.5, 0.5);
  const double lo[3] = {-0.5, -0.5, -0.5}, hi[3] = {0.5, 0.5, 0.5};
  for (const Expr& body : bodies()) {
    detail::TermForm tf;
    tf.build(body, 3, 3, {x(3), x(4), x(5)});
    for (int i = 0; i < 50; ++i) {
      std::vector<double> X = {3 * U(rng), 3 * U(rng), 3 * U(rng)};
      tf.setX(X.data());
      double t[3] = {U(rng), U(rng), U(rng)};
      const double before = eval(body, {X[0], X[1], X[2], t[0], t[1], t[2]});
      const uint32_t calls = tf.ascend(t, lo, hi, 1e-3);
      EXPECT_GE(calls, 1u);
      EXPECT_LE(calls, 8u);
      const double after = eval(body, {X[0], X[1], X[2], t[0], t[1], t[2]});
      for (int k = 0; k < 3; ++k) {
        EXPECT_GE(t[k], lo[k]);
        EXPECT_LE(t[k], hi[k]);
      }
      EXPECT_GE(after, before - 1e-12) << toString(body);
    }
  }
}

// End to end: the certified [lo, hi] of B&B holds the best of dense random sampling of the
// domain, with hi - lo <= tolerance, for the builders (box, ball and 1D domains, max and min).
TEST(ExtremumTerms, CertifiedIntervalHoldsDenseSamples) {
  const Expr X = x(0), Y = x(1), Z = x(2);
  const Expr ballR = 0.3 - len3(X, Y, Z);
  const Expr cubeMinusBall = min(box3(X, Y, Z, 1.0), len3(X, Y, Z) - 1.2);
  MinkowskiOptions o1;
  o1.tolerance = 0.02;
  MinkowskiOptions o0 = o1;
  o0.a = 0.0;
  SearchOptions so;
  so.tolerance = 0.02;
  Motion helix;
  helix.translation = {cos(x(0)), sin(x(0)), 0.2 * x(0)};
  const Expr torus = 0.3 - sqrt(square(sqrt(square(X) + square(Y)) - 1.0) + square(Z));
  const std::vector<std::pair<const char*, Expr>> models = {
      {"minkowski a=1", minkowskiSum(cubeMinusBall, ballR, 3, {{-.3, -.3, -.3}, {.3, .3, .3}}, o1)},
      {"minkowski a=0", minkowskiSum(cubeMinusBall, ballR, 3, {{-.3, -.3, -.3}, {.3, .3, .3}}, o0)},
      {"erosion", minkowskiDifference(box3(X, Y, Z, 1.0), ballR, 3, {{-.3, -.3, -.3}, {.3, .3, .3}}, so)},
      {"offset (ball domain)", offsetRadius(torus, 3, 0.2, so)},
      {"sweep", sweep(ballR, 3, helix, 0.0, 3.0, so)},
  };
  std::mt19937_64 rng(14);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (const auto& [name, m] : models) {
    TapePtr t = Tape::compile(m);
    ASSERT_EQ(t->extrema().size(), 1u) << name;
    const ExtremumEntry& e = t->extrema()[0];
    const ExtremumSpec& s = *e.spec;
    ExtremumSolver solver(e.spec, e.body);
    PointEvaluator pe;
    std::vector<double> warm;
    for (int i = 0; i < 60; ++i) {
      const double Xp[3] = {3.2 * U(rng) - 1.6, 3.2 * U(rng) - 1.6, 3.2 * U(rng) - 1.6};
      ExtremumResult r = solver.solveBranchAndBound(Xp, i % 2 && !warm.empty() ? warm.data() : nullptr);
      warm = r.t;
      ASSERT_TRUE(r.certified) << name;
      EXPECT_LE(r.hi - r.lo, s.tolerance * (1 + 1e-12)) << name;
      EXPECT_LE(r.lo, r.value);
      EXPECT_LE(r.value, r.hi);
      // the value is a real body value at the reported arg-extremum
      std::vector<double> q = {Xp[0], Xp[1], Xp[2]};
      q.insert(q.end(), r.u.begin(), r.u.end());
      EXPECT_EQ(pe.eval(*e.body, q.data()), r.value) << name;
      double best = -std::numeric_limits<double>::infinity();
      for (int j = 0; j < 6000; ++j) {
        for (uint32_t k = 0; k < s.hidden; ++k)
          q[3 + k] = s.domain == DomainKind::Box ? s.lo[k] + (s.hi[k] - s.lo[k]) * U(rng) : (2 * U(rng) - 1) * s.radius;
        if (s.domain == DomainKind::Ball) {
          double r2 = 0;
          for (uint32_t k = 0; k < s.hidden; ++k) r2 += q[3 + k] * q[3 + k];
          if (r2 > s.radius * s.radius) continue;
        }
        const double v = pe.eval(*e.body, q.data());
        best = std::max(best, s.kind == ExtremumKind::Max ? v : -v);
      }
      if (s.kind == ExtremumKind::Max) {
        EXPECT_LE(best, r.hi) << name;
      } else {
        EXPECT_GE(-best, r.lo) << name;
      }
    }
  }
}

// Sampled values do not depend on how the grid is split into bricks (warm starts stay inside
// one batch of one leaf) nor on the thread count.
TEST(ExtremumTerms, SampledValuesAreTheSameForAnyBrickSplit) {
  const Expr X = x(0), Y = x(1), Z = x(2);
  MinkowskiOptions o;
  o.tolerance = 0.02;
  const Expr m = minkowskiSum(min(box3(X, Y, Z, 1.0), len3(X, Y, Z) - 1.2), 0.3 - len3(X, Y, Z), 3,
                              {{-.3, -.3, -.3}, {.3, .3, .3}}, o);
  TapePtr t = Tape::compile(m);
  GridSpec g = GridSpec::fromBounds({-1.6, -1.6, -1.6}, {1.6, 1.6, 1.6}, 32);
  SampleOptions whole;
  whole.threads = 1;
  SampleResult ref = sample(t, g, whole);
  std::map<std::array<int32_t, 3>, const LeafBlock*> byOrigin;
  for (const LeafBlock& l : ref.leaves) byOrigin[l.origin] = &l;
  size_t leaves = 0;
  for (int bx = 0; bx < 2; ++bx)
    for (int by = 0; by < 2; ++by)
      for (int bz = 0; bz < 2; ++bz) {
        SampleOptions brick;
        brick.threads = 2;
        brick.regionLo = {16 * bx, 16 * by, 16 * bz};
        brick.regionHi = {16 * bx + 16, 16 * by + 16, 16 * bz + 16};
        SampleResult r = sample(t, g, brick);
        for (const LeafBlock& l : r.leaves) {
          auto it = byOrigin.find(l.origin);
          ASSERT_TRUE(it != byOrigin.end());
          for (int off = 0; off < kLeafVoxels; ++off) {
            ASSERT_EQ(l.isActive(off), it->second->isActive(off));
            ASSERT_EQ(l.values[off], it->second->values[off]);
          }
          ++leaves;
        }
      }
  EXPECT_EQ(leaves, ref.leaves.size());
  EXPECT_GT(leaves, 10u);
}

// solveSign (the mesher's sampled signs) stops a cold search once the sign of its value is
// known: the sign bit must be the cold search's everywhere, also within the tolerance of the
// zero set (points found by bisection on the cold search's sign), for max and min, box, ball and
// 1D domains.
TEST(ExtremumTerms, SignSearchHasTheSignOfTheColdSearch) {
  const Expr X = x(0), Y = x(1), Z = x(2);
  const Expr ballR = 0.3 - len3(X, Y, Z);
  const Expr slab = min(min(min(1.0 - abs(X), 1.0 - abs(Y)), 0.25 - abs(Z)),
                        -min(min(min(X + 0.2, 1.3 - X), min(Y + 0.2, 1.3 - Y)), 1.0 - abs(Z)));
  MinkowskiOptions o1;
  o1.tolerance = 0.01;
  SearchOptions so;
  so.tolerance = 0.01;
  Motion helix;
  helix.translation = {cos(x(0)), sin(x(0)), 0.2 * x(0)};
  const Expr torus = 0.3 - sqrt(square(sqrt(square(X) + square(Y)) - 1.0) + square(Z));
  const std::vector<std::pair<const char*, Expr>> models = {
      {"non-convex slab + ball", minkowskiSum(slab, ballR, 3, {{-.3, -.3, -.3}, {.3, .3, .3}}, o1)},
      {"erosion", minkowskiDifference(box3(X, Y, Z, 1.0), ballR, 3, {{-.3, -.3, -.3}, {.3, .3, .3}}, so)},
      {"offset (ball domain)", offsetRadius(torus, 3, 0.2, so)},
      {"sweep", sweep(ballR, 3, helix, 0.0, 3.0, so)},
  };
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (const auto& [name, m] : models) {
    TapePtr t = Tape::compile(m);
    ASSERT_EQ(t->extrema().size(), 1u) << name;
    const ExtremumEntry& e = t->extrema()[0];
    ExtremumSolver cold(e.spec, e.body), signs(e.spec, e.body);
    uint64_t coldEvals = 0, signEvals = 0;
    int nearZero = 0, inside = 0, outside = 0;
    auto check = [&](const double* p) {
      const ExtremumResult a = cold.solve(p), b = signs.solveSign(p);
      ASSERT_EQ(std::signbit(a.value), std::signbit(b.value)) << name << " at " << p[0] << " " << p[1] << " " << p[2];
      ASSERT_EQ(std::isnan(a.value), std::isnan(b.value)) << name;
      coldEvals += a.pointEvals + a.intervalEvals;
      signEvals += b.pointEvals + b.intervalEvals;
      nearZero += std::fabs(a.value) <= e.spec->tolerance;
      (std::signbit(a.value) ? outside : inside) += 1;
    };
    for (int i = 0; i < 300; ++i) {
      const double p[3] = {3.2 * U(rng) - 1.6, 3.2 * U(rng) - 1.6, 3.2 * U(rng) - 1.6};
      check(p);
    }
    // Bisection between an inside and an outside point down to 1e-6: the last points lie within
    // the tolerance of the zero set, where the sign is decided by the full search.
    for (int i = 0; i < 40; ++i) {
      double a[3], b[3];
      for (int k = 0; k < 3; ++k) {
        a[k] = 3.2 * U(rng) - 1.6;
        b[k] = 3.2 * U(rng) - 1.6;
      }
      const bool ina = !std::signbit(cold.solve(a).value), inb = !std::signbit(cold.solve(b).value);
      if (ina == inb) continue;
      for (int it = 0; it < 22; ++it) {
        double c[3];
        for (int k = 0; k < 3; ++k) c[k] = 0.5 * (a[k] + b[k]);
        check(c);
        if (!std::signbit(cold.solve(c).value) == ina) std::copy(c, c + 3, a);
        else std::copy(c, c + 3, b);
      }
    }
    EXPECT_GT(nearZero, 20) << name;
    EXPECT_GT(inside, 20) << name;
    EXPECT_GT(outside, 20) << name;
    EXPECT_LT(signEvals, coldEvals) << name;
  }
}
