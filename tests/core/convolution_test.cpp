// Convolution kernels x skeletons (Vyatkin-Perturbation eq. 1-7, frep/primitives/convolution.h):
// every kernel over every skeleton against an independent reference (the kernels written out
// again here from eq. 1-6, integrated over the skeleton's parametrisation by Boost's adaptive
// Gauss-Kronrod), sound interval bounds over random boxes, batch = point bit for bit, and the
// gradient against central differences.
#include <gtest/gtest.h>

#include <boost/math/quadrature/gauss_kronrod.hpp>
#include <cmath>
#include <random>

#include "frep/evaluators/eval.h"
#include "frep/expressions/tape.h"
#include "frep/primitives/convolution.h"

using namespace frep;

namespace {

constexpr double kPi = 3.14159265358979323846;

// eq. 1-6 as printed in expanded form (soft objects with Wyvill's coefficients).
double h(ConvKernel k, double q) {
  switch (k) {
    case ConvKernel::Gauss: return std::exp(-q * q);
    case ConvKernel::Inverse: return 1 / q;
    case ConvKernel::InverseSquare: return 1 / (q * q);
    case ConvKernel::Metaball: return q <= 1.0 / 3 ? 1 - 3 * q * q : q <= 1 ? 1.5 * (1 - q) * (1 - q) : 0.0;
    case ConvKernel::Soft:
      return q < 1 ? 1 - 4.0 / 9 * std::pow(q, 6) + 17.0 / 9 * std::pow(q, 4) - 22.0 / 9 * q * q : 0.0;
    case ConvKernel::Quartic: return q < 1 ? (1 - q * q) * (1 - q * q) : 0.0;
  }
  return 0;
}

const ConvKernel kKernels[] = {ConvKernel::Gauss,    ConvKernel::Inverse, ConvKernel::InverseSquare,
                               ConvKernel::Metaball, ConvKernel::Soft,    ConvKernel::Quartic};
const ConvSkeleton kSkeletons[] = {ConvSkeleton::Point, ConvSkeleton::Segment, ConvSkeleton::Arc,
                                   ConvSkeleton::Triangle, ConvSkeleton::Plane};

bool diverges(ConvKernel k, ConvSkeleton s) {
  return s == ConvSkeleton::Plane && (k == ConvKernel::Inverse || k == ConvKernel::InverseSquare);
}

double gk(const std::function<double(double)>& f, double a, double b) {
  using boost::math::quadrature::gauss_kronrod;
  if (!(b > a)) return 0.0;
  return gauss_kronrod<double, 61>::integrate(f, a, b, 8, 1e-11);
}

struct Rand {
  std::mt19937_64 rng;
  explicit Rand(unsigned seed) : rng(seed) {}
  double operator()(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); }
};

double dist(const double* a, const double* b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

ConvElement randomElement(ConvSkeleton s, Rand& r) {
  ConvElement e;
  e.S = r(0.6, 1.8);
  auto pt = [&] {
    for (int k = 0; k < 3; ++k) e.geometry.push_back(r(-1, 1));
  };
  switch (s) {
    case ConvSkeleton::Point: pt(); break;
    case ConvSkeleton::Segment: pt(), pt(); break;
    case ConvSkeleton::Triangle: pt(), pt(), pt(); break;
    case ConvSkeleton::Plane:
      pt();
      for (int k = 0; k < 3; ++k) e.geometry.push_back(r(-1, 1));
      break;
    case ConvSkeleton::Arc: {
      pt();
      double u[3] = {r(-1, 1), r(-1, 1), r(-1, 1)}, w[3] = {r(-1, 1), r(-1, 1), r(-1, 1)};
      double ul = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
      for (double& c : u) c /= ul;
      double d = u[0] * w[0] + u[1] * w[1] + u[2] * w[2];
      for (int k = 0; k < 3; ++k) w[k] -= d * u[k];
      double wl = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
      for (double& c : w) c /= wl;
      for (double c : u) e.geometry.push_back(c);
      for (double c : w) e.geometry.push_back(c);
      e.geometry.push_back(r(0.3, 1.0));
      e.geometry.push_back(r(0.5, 2 * kPi));
      break;
    }
  }
  return e;
}

// Independent reference: the kernel integrated over the element's parametrisation.
double reference(ConvKernel k, ConvSkeleton s, const ConvElement& e, const double* p) {
  const double* g = e.geometry.data();
  auto at = [&](const double* q) { return h(k, e.S * dist(p, q)); };
  switch (s) {
    case ConvSkeleton::Point: return at(g);
    case ConvSkeleton::Segment: {
      double L = dist(g, g + 3);
      auto f = [&](double t) {
        double q[3];
        for (int c = 0; c < 3; ++c) q[c] = g[c] + t / L * (g[3 + c] - g[c]);
        return at(q);
      };
      double t0 = 0;  // split at the nearest point
      for (int c = 0; c < 3; ++c) t0 += (p[c] - g[c]) * (g[3 + c] - g[c]) / L;
      t0 = std::min(std::max(t0, 0.0), L);
      return gk(f, 0, t0) + gk(f, t0, L);
    }
    case ConvSkeleton::Arc: {
      const double *u = g + 3, *v = g + 6;
      double r = g[9], th = g[10];
      auto f = [&](double t) {
        double q[3];
        for (int c = 0; c < 3; ++c) q[c] = g[c] + r * (std::cos(t) * u[c] + std::sin(t) * v[c]);
        return r * at(q);
      };
      double n = 64;  // panels keep the Kronrod error estimate honest on peaked integrands
      double sum = 0;
      for (int i = 0; i < n; ++i) sum += gk(f, th * i / n, th * (i + 1) / n);
      return sum;
    }
    case ConvSkeleton::Triangle: {
      double e1[3], e2[3];
      for (int c = 0; c < 3; ++c) e1[c] = g[3 + c] - g[c], e2[c] = g[6 + c] - g[c];
      double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
      double jac = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      auto outer = [&](double a) {
        auto inner = [&](double b) {
          double q[3];
          for (int c = 0; c < 3; ++c) q[c] = g[c] + a * e1[c] + b * e2[c];
          return at(q);
        };
        double sum = 0;
        for (int i = 0; i < 8; ++i) sum += gk(inner, (1 - a) * i / 8, (1 - a) * (i + 1) / 8);
        return sum;
      };
      double sum = 0;
      for (int i = 0; i < 8; ++i) sum += gk(outer, i / 8.0, (i + 1) / 8.0);
      return jac * sum;
    }
    case ConvSkeleton::Plane: {
      double nl = std::sqrt(g[3] * g[3] + g[4] * g[4] + g[5] * g[5]), d = 0;
      for (int c = 0; c < 3; ++c) d += (p[c] - g[c]) * g[3 + c] / nl;
      auto f = [&](double rho) { return 2 * kPi * rho * h(k, e.S * std::sqrt(d * d + rho * rho)); };
      double end = 12.0 / e.S;
      double sum = 0;
      for (int i = 0; i < 48; ++i) sum += gk(f, end * i / 48, end * (i + 1) / 48);
      return sum;
    }
  }
  return 0;
}

// Distance from p to the skeleton, roughly (to keep singular kernels' points off the skeleton).
double nearSkeleton(ConvSkeleton s, const ConvElement& e, const double* p) {
  const double* g = e.geometry.data();
  double best = 1e9;
  auto see = [&](const double* q) { best = std::min(best, dist(p, q)); };
  switch (s) {
    case ConvSkeleton::Point: see(g); break;
    case ConvSkeleton::Segment:
      for (int i = 0; i <= 400; ++i) {
        double q[3];
        for (int c = 0; c < 3; ++c) q[c] = g[c] + i / 400.0 * (g[3 + c] - g[c]);
        see(q);
      }
      break;
    case ConvSkeleton::Arc:
      for (int i = 0; i <= 400; ++i) {
        double t = g[10] * i / 400, q[3];
        for (int c = 0; c < 3; ++c) q[c] = g[c] + g[9] * (std::cos(t) * g[3 + c] + std::sin(t) * g[6 + c]);
        see(q);
      }
      break;
    case ConvSkeleton::Triangle:
      for (int i = 0; i <= 60; ++i)
        for (int j = 0; i + j <= 60; ++j) {
          double q[3];
          for (int c = 0; c < 3; ++c) q[c] = g[c] + i / 60.0 * (g[3 + c] - g[c]) + j / 60.0 * (g[6 + c] - g[c]);
          see(q);
        }
      break;
    case ConvSkeleton::Plane: break;
  }
  return best;
}

class ConvolutionAll : public ::testing::TestWithParam<std::tuple<ConvKernel, ConvSkeleton>> {};

TEST_P(ConvolutionAll, MatchesNumericalIntegration) {
  auto [k, s] = GetParam();
  if (diverges(k, s)) {
    EXPECT_THROW(Convolution::make(k, s, {}), std::invalid_argument);
    return;
  }
  Rand r(1000 + 10 * int(k) + int(s));
  const int points = s == ConvSkeleton::Triangle ? 12 : 40;
  int nonZero = 0;
  for (int i = 0; i < points; ++i) {
    std::vector<ConvElement> els = {randomElement(s, r)};
    auto conv = Convolution::make(k, s, els);
    double p[3];
    do {  // half the points near the element's first point, so compact kernels are seen
      bool near = i % 2 == 0;
      for (int c = 0; c < 3; ++c) p[c] = near ? els[0].geometry[size_t(c)] + r(-0.7, 0.7) : r(-1.5, 1.5);
    } while (nearSkeleton(s, els[0], p) < 0.1);
    double ref = reference(k, s, els[0], p);
    double got = conv->rawElementValue(0, p);
    double tol = 1e-8 * std::fabs(ref) + 1e-13;
    EXPECT_NEAR(got, ref, tol) << convKernelName(k) << " " << convSkeletonName(s) << " point " << i;
    EXPECT_NEAR(conv->value(p), ref, tol);
    nonZero += ref > 1e-6;
  }
  EXPECT_GE(nonZero, points / 4);  // the random points see the field, not only its zero tail
}

TEST_P(ConvolutionAll, BoundsSoundBatchEqualsPointGradientMatches) {
  auto [k, s] = GetParam();
  if (diverges(k, s)) return;
  Rand r(2000 + 10 * int(k) + int(s));
  std::vector<ConvElement> els = {randomElement(s, r), randomElement(s, r)};
  auto conv = Convolution::make(k, s, els);
  Expr f = fieldCall(conv, Expr::x(0), Expr::x(1), Expr::x(2)) - 0.3;
  TapePtr t = Tape::compile(f, 3);
  IntervalEvaluator ie;
  PointEvaluator pe;
  GradientEvaluator ge;
  BatchEvaluator<double> be;
  be.reserve(*t);
  const int boxes = s == ConvSkeleton::Triangle || s == ConvSkeleton::Arc ? 60 : 200;
  size_t lane = 0;
  std::vector<std::array<double, 3>> pts;
  for (int b = 0; b < boxes; ++b) {
    Interval box[3];
    double w = r(0, 1) < 0.2 ? 0.0 : r(0.0, 0.6);
    for (auto& iv : box) {
      double lo = r(-1.8, 1.8);
      iv = Interval(lo, lo + w);
    }
    Interval got = ie.eval(*t, box);
    for (int j = 0; j < 8; ++j) {
      double x[3];
      for (int a = 0; a < 3; ++a) x[a] = box[a].lo + r(0, 1) * box[a].width();
      double v = pe.eval(*t, x);
      ASSERT_TRUE(got.contains(v)) << convKernelName(k) << " " << convSkeletonName(s) << ": " << v << " not in ["
                                   << got.lo << ", " << got.hi << "]";
      if (lane < BatchEvaluator<double>::kBatch) {
        for (int a = 0; a < 3; ++a) be.in(uint32_t(a))[lane] = x[a];
        pts.push_back({x[0], x[1], x[2]});
        ++lane;
      }
    }
  }
  const double* out = be.eval(*t, lane);
  for (size_t i = 0; i < lane; ++i) ASSERT_EQ(out[i], pe.eval(*t, pts[i].data())) << i;
  // Gradient against central differences, away from the skeleton (singular kernels).
  int checked = 0;
  for (int i = 0; i < 200 && checked < 15; ++i) {
    double x[3] = {r(-1.5, 1.5), r(-1.5, 1.5), r(-1.5, 1.5)}, g[3];
    if (nearSkeleton(s, els[0], x) < 0.15 || nearSkeleton(s, els[1], x) < 0.15) continue;
    ++checked;
    double v = ge.eval(*t, x, g);
    EXPECT_EQ(v, pe.eval(*t, x));
    for (int a = 0; a < 3; ++a) {
      const double step = 1e-5;
      double xp[3] = {x[0], x[1], x[2]}, xm[3] = {x[0], x[1], x[2]};
      xp[a] += step, xm[a] -= step;
      double fd = (pe.eval(*t, xp) - pe.eval(*t, xm)) / (2 * step);
      EXPECT_NEAR(g[a], fd, 1e-6 * std::max(1.0, std::fabs(g[a])))
          << convKernelName(k) << " " << convSkeletonName(s) << " axis " << a;
    }
  }
  EXPECT_GE(checked, 5);
}

// Small boxes (a ray caster's footprint): the bound stays sound and shrinks with the box, as
// the slope bound makes it; the pieces alone stop at the piece size (a fat surface in renders).
TEST_P(ConvolutionAll, SmallBoxBoundsShrinkWithTheBox) {
  auto [k, s] = GetParam();
  if (diverges(k, s) || s == ConvSkeleton::Plane) return;
  Rand r(4000 + 10 * int(k) + int(s));
  std::vector<ConvElement> els = {randomElement(s, r), randomElement(s, r)};
  auto conv = Convolution::make(k, s, els);
  Expr f = fieldCall(conv, Expr::x(0), Expr::x(1), Expr::x(2));
  TapePtr t = Tape::compile(f, 3);
  IntervalEvaluator ie;
  PointEvaluator pe;
  int checked = 0;
  for (int i = 0; i < 400 && checked < 20; ++i) {
    double c[3] = {r(-1.5, 1.5), r(-1.5, 1.5), r(-1.5, 1.5)};
    if (nearSkeleton(s, els[0], c) < 0.15 || nearSkeleton(s, els[1], c) < 0.15) continue;
    ++checked;
    for (double w : {1e-2, 1e-4}) {
      Interval box[3];
      for (int a = 0; a < 3; ++a) box[a] = Interval(c[a], c[a] + w);
      Interval got = ie.eval(*t, box);
      for (int j = 0; j < 8; ++j) {
        double x[3];
        for (int a = 0; a < 3; ++a) x[a] = box[a].lo + r(0, 1) * w;
        double v = pe.eval(*t, x);
        ASSERT_TRUE(got.contains(v)) << convKernelName(k) << " " << convSkeletonName(s) << ": " << v << " not in ["
                                     << got.lo << ", " << got.hi << "]";
      }
      // The bounded kernels' slope is at most 1.6 S per unit of measure (a few units here); the
      // singular kernels' grows as 1/q^2, 1/q^3 towards the skeleton: soundness only.
      if (k != ConvKernel::Inverse && k != ConvKernel::InverseSquare && s != ConvSkeleton::Triangle)
        EXPECT_LT(got.width(), 100 * w) << convKernelName(k) << " " << convSkeletonName(s) << " w " << w;
    }
  }
  EXPECT_GE(checked, 10);
}

INSTANTIATE_TEST_SUITE_P(KernelsBySkeletons, ConvolutionAll,
                         ::testing::Combine(::testing::ValuesIn(kKernels), ::testing::ValuesIn(kSkeletons)),
                         [](const auto& info) {
                           return std::string(convKernelName(std::get<0>(info.param))) +
                                  convSkeletonName(std::get<1>(info.param));
                         });

// Exact values: the plane's Gaussian closed form and a full circle's quartic at its centre.
TEST(Convolution, ExactValues) {
  auto plane = Convolution::make(ConvKernel::Gauss, ConvSkeleton::Plane, {{{0, 0, 0, 0, 0, 2}, 1.5}});
  double p[3] = {0.3, -2.0, 0.4};
  EXPECT_NEAR(plane->value(p), kPi / (1.5 * 1.5) * std::exp(-1.5 * 1.5 * 0.16), 1e-15);
  // Circle of radius 0.5, S = 1: every point at distance 0.5: 2 pi 0.5 (1 - 0.25)^2.
  auto circle = Convolution::make(ConvKernel::Quartic, ConvSkeleton::Arc,
                                  {{{1, 2, 3, 1, 0, 0, 0, 1, 0, 0.5, 2 * kPi}, 1.0}});
  double c[3] = {1, 2, 3};
  EXPECT_NEAR(circle->value(c), 2 * kPi * 0.5 * 0.5625, 1e-13);
  // A unit segment's inverse-square field on its axis beyond the end: int_1^2 du / u^2 = 1/2.
  auto seg = Convolution::make(ConvKernel::InverseSquare, ConvSkeleton::Segment, {{{1, 0, 0, 2, 0, 0}, 1.0}});
  double o[3] = {0, 0, 0};
  EXPECT_NEAR(seg->value(o), 0.5, 1e-15);
}

TEST(Convolution, RefusesBadElements) {
  EXPECT_THROW(Convolution::make(ConvKernel::Gauss, ConvSkeleton::Segment, {{{0, 0, 0, 0, 0, 0}, 1}}),
               std::invalid_argument);
  EXPECT_THROW(Convolution::make(ConvKernel::Gauss, ConvSkeleton::Point, {{{0, 0, 0}, 0}}), std::invalid_argument);
  EXPECT_THROW(Convolution::make(ConvKernel::Gauss, ConvSkeleton::Triangle, {{{0, 0, 0, 1, 1, 1, 2, 2, 2}, 1}}),
               std::invalid_argument);
  EXPECT_THROW(Convolution::make(ConvKernel::Soft, ConvSkeleton::Plane, {{{0, 0, 0, 0, 0, 0}, 1}}),
               std::invalid_argument);
}

}  // namespace
