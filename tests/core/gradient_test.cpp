// GradientEvaluator (forward mode) against exact gradients, central differences and the
// symbolic derivative(); plus derivative() conventions at the branch points of piecewise ops.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "frep/evaluators/eval.h"
#include "frep/evaluators/interval.h"
#include "frep/expressions/expr.h"

using namespace frep;

namespace {

const Expr X = Expr::x(0), Y = Expr::x(1), Z = Expr::x(2);

// R-functions with a = 0 (Pasko-Survey, the sqrt system), written out so the test has no
// dependency on the operation library.
Expr rUnion0(const Expr& f, const Expr& g) { return f + g + sqrt(square(f) + square(g)); }
Expr rInter0(const Expr& f, const Expr& g) { return f + g - sqrt(square(f) + square(g)); }

std::vector<double> gradient(const Expr& e, const std::vector<double>& x, double* value = nullptr) {
  auto tape = Tape::compile(e, static_cast<uint32_t>(x.size()));
  GradientEvaluator ge;
  std::vector<double> g(tape->numVars());
  double v = ge.eval(*tape, x.data(), g.data());
  if (value) *value = v;
  return g;
}

// Central differences with step h relative to the coordinate's scale.
std::vector<double> centralDiff(const Expr& e, std::vector<double> x) {
  auto tape = Tape::compile(e, static_cast<uint32_t>(x.size()));
  PointEvaluator pe;
  std::vector<double> g(x.size());
  for (size_t i = 0; i < x.size(); ++i) {
    const double h = 1e-5 * std::max(1.0, std::fabs(x[i]));
    const double x0 = x[i];
    x[i] = x0 + h;
    const double fp = pe.eval(*tape, x.data());
    x[i] = x0 - h;
    const double fm = pe.eval(*tape, x.data());
    x[i] = x0;
    g[i] = (fp - fm) / (2.0 * h);
  }
  return g;
}

void expectMatchesCentralDiff(const Expr& e, const std::vector<double>& x) {
  auto g = gradient(e, x);
  auto c = centralDiff(e, x);
  for (size_t i = 0; i < x.size(); ++i)
    EXPECT_NEAR(g[i], c[i], 1e-6 * std::max(1.0, std::fabs(c[i])))
        << toString(e) << " d/dx" << i;
}

// Deterministic random expressions; `smooth` restricts to ops that are C^inf where evaluated.
struct RandomExpr {
  std::mt19937_64 rng;
  bool smooth;
  explicit RandomExpr(uint64_t seed, bool smoothOnly) : rng(seed), smooth(smoothOnly) {}
  int pick(int n) { return static_cast<int>(rng() % static_cast<uint64_t>(n)); }
  double coef() { return 0.25 * (1 + pick(8)); }

  Expr leaf() {
    int k = pick(4);
    if (k == 3) return Expr(coef());
    return Expr::x(static_cast<uint32_t>(k));
  }
  Expr gen(int depth) {
    if (depth == 0) return leaf();
    Expr a = gen(depth - 1);
    Expr b = gen(depth - 1);
    const int nSmooth = 12;
    int k = pick(smooth ? nSmooth : nSmooth + 8);
    switch (k) {
      case 0: return a + b;
      case 1: return a - coef() * b;
      case 2: return a * b;
      case 3: return a / (1.5 + sin(b));               // denominator in [0.5, 2.5]
      case 4: return sin(a) + cos(b);
      case 5: return exp(tanh(a)) * b;                 // bounded exponent
      case 6: return atan(a) - tanh(b);
      case 7: return sqrt(1.0 + square(a)) * b;        // argument >= 1
      case 8: return log(1.0 + square(a)) + b;         // argument >= 1
      case 9: return atan2(a, 2.0 + square(b));        // denominator > 0
      case 10: return pow(1.0 + square(a), 0.5 * coef()) - b;  // non-integer exponent, base >= 1
      case 11: return Expr::powi(a, 3) * 0.1 + sinh(0.1 * b) + cosh(0.1 * a);
      // piecewise ops (derivative of the active branch)
      case 12: return min(a, b);
      case 13: return max(a, b);
      case 14: return abs(a) - b;
      case 15: return floor(a) + b;
      case 16: return select(gt(a, b), a * b, a - b);
      case 17: return fmod(a, 2.0 + square(b));
      case 18: return rUnion0(a, b);
      default: return frac(a) * b + asin(tanh(b));
    }
  }
};

std::vector<double> randomPoint(std::mt19937_64& rng) {
  std::vector<double> x(3);
  for (auto& v : x) v = -1.5 + 3.0 * static_cast<double>(rng() % 1000003) / 1000003.0;
  return x;
}

}  // namespace

TEST(Gradient, SphereIsExact) {
  Expr s = 1.0 - square(X) - square(Y) - square(Z);
  double v = 0;
  auto g = gradient(s, {0.5, -0.25, 2.0}, &v);
  EXPECT_EQ(v, 1.0 - 0.25 - 0.0625 - 4.0);
  EXPECT_EQ(g[0], -1.0);
  EXPECT_EQ(g[1], 0.5);
  EXPECT_EQ(g[2], -4.0);
}

TEST(Gradient, ValueIsBitIdenticalToPointEvaluator) {
  RandomExpr gen(7, false);
  std::mt19937_64 rng(11);
  PointEvaluator pe;
  GradientEvaluator ge;
  for (int t = 0; t < 50; ++t) {
    Expr e = gen.gen(4);
    auto tape = Tape::compile(e, 3);
    std::vector<double> g(3);
    auto x = randomPoint(rng);
    const double pv = pe.eval(*tape, x.data());
    const double gv = ge.eval(*tape, x.data(), g.data());
    EXPECT_TRUE(pv == gv || (std::isnan(pv) && std::isnan(gv))) << toString(e);
  }
}

TEST(Gradient, PrimitivesMatchCentralDifferences) {
  Expr sphere = 1.0 - square(X) - square(Y) - square(Z);
  Expr torus = square(0.5) - square(2.0 - sqrt(square(X) + square(Y))) - square(Z);
  Expr slab = 0.5 - abs(Z);  // away from z = 0
  Expr unionA0 = rUnion0(sphere, 1.0 - square(X - 1.5) - square(Y) - square(Z));
  Expr interA0 = rInter0(sphere, slab);
  Expr waves = sin(3.0 * X) * exp(0.5 * Y) + atan2(Y, X + 3.0) + pow(1.0 + square(Z), 1.5);
  Expr logs = log(2.0 + X * Y) + log10(3.0 + Z) + asin(0.3 * X) + acos(0.2 * Y) + tan(0.4 * Z);
  std::vector<std::vector<double>> pts = {{0.3, 0.4, 0.2}, {-0.7, 0.1, 0.35}, {1.1, -0.9, -0.4}};
  for (const auto& p : pts)
    for (const Expr& e : {sphere, torus, slab, unionA0, interA0, waves, logs})
      expectMatchesCentralDiff(e, p);
}

TEST(Gradient, RandomSmoothExpressionsMatchCentralDifferences) {
  RandomExpr gen(1234, true);
  std::mt19937_64 rng(99);
  for (int t = 0; t < 200; ++t) {
    Expr e = gen.gen(1 + t % 4);
    expectMatchesCentralDiff(e, randomPoint(rng));
  }
}

// The evaluator and the symbolic derivative follow the same conventions, including piecewise
// ops, so they agree to rounding everywhere (not only where f is smooth).
TEST(Gradient, MatchesSymbolicDerivativeTapes) {
  RandomExpr gen(4321, false);
  std::mt19937_64 rng(5);
  PointEvaluator pe;
  GradientEvaluator ge;
  int compared = 0;
  for (int t = 0; t < 200; ++t) {
    Expr e = gen.gen(1 + t % 5);
    auto tape = Tape::compile(e, 3);
    auto x = randomPoint(rng);
    std::vector<double> g(3);
    ge.eval(*tape, x.data(), g.data());
    for (uint32_t i = 0; i < 3; ++i) {
      auto dt = Tape::compile(derivative(e, i), 3);
      const double s = pe.eval(*dt, x.data());
      if (std::isnan(s)) {
        EXPECT_TRUE(std::isnan(g[i])) << toString(e);
        continue;
      }
      EXPECT_NEAR(g[i], s, 1e-12 * std::max(1.0, std::fabs(s))) << toString(e) << " d/dx" << i;
      ++compared;
    }
  }
  EXPECT_GT(compared, 500);
}

TEST(Gradient, RegisterReuseIsHandled) {
  // A chain of unary ops compiles to instructions whose output register is their input.
  Expr e = sin(sin(sin(X * Y)));
  auto tape = Tape::compile(e, 2);
  bool reuse = false;
  for (const Instr& ins : tape->code()) reuse = reuse || ins.out == ins.a;
  ASSERT_TRUE(reuse) << "the tape no longer reuses registers; this test needs another model";
  const double x = 0.7, y = -0.4;
  const double u = x * y, s1 = std::sin(u), s2 = std::sin(s1);
  const double chain = std::cos(s2) * std::cos(s1) * std::cos(u);
  auto g = gradient(e, {x, y});
  EXPECT_NEAR(g[0], chain * y, 1e-15);
  EXPECT_NEAR(g[1], chain * x, 1e-15);
}

TEST(Gradient, PiecewiseConventions) {
  // min picks b's derivative only when b < a (ties take a's), as applyOp picks the value.
  EXPECT_EQ(gradient(min(2.0 * X, 3.0 * Y), {1.0, 1.0})[0], 2.0);
  EXPECT_EQ(gradient(min(2.0 * X, 3.0 * Y), {1.0, 1.0})[1], 0.0);
  auto tie = gradient(min(2.0 * X, 2.0 * Y), {1.0, 1.0});
  auto tieSym = derivative(min(2.0 * X, 2.0 * Y), 0);
  PointEvaluator pe;
  double p[2] = {1.0, 1.0};
  EXPECT_EQ(tie[0], pe.eval(*Tape::compile(tieSym, 2), p));
  EXPECT_EQ(gradient(max(X, 3.0 * Y), {1.0, 1.0})[1], 3.0);
  // sqrt at and below 0, floor, comparisons: derivative 0.
  EXPECT_EQ(gradient(sqrt(X), {0.0})[0], 0.0);
  EXPECT_EQ(gradient(sqrt(X), {-1.0})[0], 0.0);
  EXPECT_EQ(gradient(floor(3.0 * X), {0.4})[0], 0.0);
  EXPECT_EQ(gradient(lt(X, Y) + X, {0.4, 1.0})[0], 1.0);
  // abs: sign, 0 at 0.
  EXPECT_EQ(gradient(abs(X), {-2.0})[0], -1.0);
  EXPECT_EQ(gradient(abs(X), {0.0})[0], 0.0);
  // select takes the live branch's derivative.
  EXPECT_EQ(gradient(select(gt(X, 0.0), 5.0 * X, -7.0 * X), {1.0})[0], 5.0);
  EXPECT_EQ(gradient(select(gt(X, 0.0), 5.0 * X, -7.0 * X), {-1.0})[0], -7.0);
}

TEST(Gradient, PowAtZeroBaseIsFinite) {
  // d/dx x^2.5 = 2.5 x^1.5 is 0 at x = 0; the former symbolic form p*b/x gave NaN there.
  Expr e = pow(X, Expr(2.5));
  EXPECT_EQ(gradient(e, {0.0})[0], 0.0);
  PointEvaluator pe;
  double z = 0.0;
  EXPECT_EQ(pe.eval(*Tape::compile(derivative(e, 0), 1), &z), 0.0);
  // A constant sub-expression next to an infinite partial stays 0: sqrt(x) * 0-derivative.
  EXPECT_EQ(gradient(sqrt(X) + Y, {0.0, 2.0})[1], 1.0);
  // Variable exponent: d/dy 2^y = 2^y ln 2.
  EXPECT_NEAR(gradient(pow(Expr(2.0), Y), {0.0, 3.0})[1], 8.0 * std::log(2.0), 1e-14);
}

TEST(Gradient, UnusedCoordinatesHaveZeroDerivative) {
  auto tape = Tape::compile(square(Y), 5);
  GradientEvaluator ge;
  double x[5] = {1, 3, 1, 1, 1};
  double g[5];
  EXPECT_EQ(ge.eval(*tape, x, g), 9.0);
  EXPECT_EQ(g[0], 0.0);
  EXPECT_EQ(g[1], 6.0);
  EXPECT_EQ(g[2], 0.0);
  EXPECT_EQ(g[4], 0.0);
}

TEST(Gradient, ResultIsACoordinateOrAConstant) {
  // The result register can be a coordinate's or a uniform's own register (no instructions).
  auto g = gradient(Y, {4.0, 5.0});
  EXPECT_EQ(g[0], 0.0);
  EXPECT_EQ(g[1], 1.0);
  double v = 0;
  g = gradient(Expr(3.0), {4.0, 5.0}, &v);
  EXPECT_EQ(v, 3.0);
  EXPECT_EQ(g[0], 0.0);
  EXPECT_EQ(g[1], 0.0);
}

TEST(Gradient, SwitchingTapesRebindsRegisters) {
  GradientEvaluator ge;
  auto t1 = Tape::compile(3.0 * X + 2.0 * Y, 2);
  auto t2 = Tape::compile(X * X * X, 3);
  double x[3] = {2, 1, 0};
  double g[3];
  EXPECT_EQ(ge.eval(*t1, x, g), 8.0);
  EXPECT_EQ(g[1], 2.0);
  EXPECT_EQ(ge.eval(*t2, x, g), 8.0);
  EXPECT_EQ(g[0], 12.0);
  EXPECT_EQ(g[2], 0.0);
}

TEST(Gradient, NewtonStepsOnSphereReachTheSurface) {
  // f = 4 - |x|^2 (radius 2); Newton along the gradient converges quadratically to |x| = 2.
  Expr f = 4.0 - square(X) - square(Y) - square(Z);
  auto tape = Tape::compile(f);
  GradientEvaluator ge;
  double x[3] = {3.0, -1.0, 0.5};
  const double dir[3] = {3.0 / std::sqrt(10.25), -1.0 / std::sqrt(10.25), 0.5 / std::sqrt(10.25)};
  double g[3];
  int steps = 0;
  for (double v = ge.eval(*tape, x, g); std::fabs(v) > 1e-14 && steps < 20; v = ge.eval(*tape, x, g)) {
    const double s = v / (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    for (int i = 0; i < 3; ++i) x[i] -= s * g[i];
    ++steps;
  }
  EXPECT_LE(steps, 6);
  EXPECT_NEAR(std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]), 2.0, 1e-14);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(x[i], 2.0 * dir[i], 1e-14);  // moved along the ray
}

// ---- BatchGradientEvaluator: the scalar evaluator's bits, lane by lane ------------------------

namespace {

bool sameBits(double a, double b) { return (std::isnan(a) && std::isnan(b)) || std::memcmp(&a, &b, sizeof a) == 0; }

// Every lane of one batch against GradientEvaluator at the same point: value and the partials
// along x[1..3] (0 past the tape's vars), bit for bit (NaN against NaN).
void expectBatchMatchesScalar(const TapePtr& tape, const std::vector<std::vector<double>>& points, BatchGradientEvaluator& be) {
  const uint32_t nv = tape->numVars();
  be.reserve(*tape);
  for (size_t l = 0; l < points.size(); ++l)
    for (uint32_t i = 0; i < nv; ++i) be.in(i)[l] = points[l][i];
  be.eval(*tape, points.size());
  GradientEvaluator ge;
  std::vector<double> g(nv);
  for (size_t l = 0; l < points.size(); ++l) {
    std::fill(g.begin(), g.end(), 0.0);
    const double v = ge.eval(*tape, points[l].data(), g.data());
    ASSERT_TRUE(sameBits(be.value()[l], v)) << "lane " << l << ": " << be.value()[l] << " vs " << v;
    for (uint32_t j = 0; j < 3; ++j)
      ASSERT_TRUE(sameBits(be.partial(int(j))[l], j < nv ? g[j] : 0.0))
          << "lane " << l << " d/dx" << j << ": " << be.partial(int(j))[l] << " vs " << (j < nv ? g[j] : 0.0);
  }
}

// Points that reach every branch: random ones, zeros (abs, sqrt, the zero-derivative rule), ties
// (min/max), arguments past the own sin/cos range, infinities and NaN.
std::vector<std::vector<double>> branchPoints(std::mt19937_64& rng, uint32_t nv, size_t n) {
  const double special[] = {0.0, -0.0, 1.0, -1.0, 0.5, 1e9, -3e12, INFINITY, -INFINITY, NAN};
  std::vector<std::vector<double>> pts(n, std::vector<double>(nv));
  for (size_t l = 0; l < n; ++l)
    for (uint32_t i = 0; i < nv; ++i)
      pts[l][i] = rng() % 5 == 0 ? special[rng() % 10] : -1.5 + 3.0 * double(rng() % 1000003) / 1000003.0;
  return pts;
}

}  // namespace

TEST(BatchGradient, EveryOpBitIdenticalToGradientEvaluator) {
  // Random expressions over every op RandomExpr has (smooth and piecewise), with 2, 3 and 4
  // vars (x[4] is a fixed coordinate), full and partial batches, and one evaluator reused
  // across tapes (rebinding).
  BatchGradientEvaluator be;
  std::mt19937_64 rng(17);
  for (uint64_t seed = 0; seed < 120; ++seed) {
    RandomExpr gen(seed, false);
    Expr e = gen.gen(1 + int(seed % 5));
    const uint32_t nv = 2 + uint32_t(seed % 3);
    if (nv == 4) e = e + Expr::x(3) * Expr::x(0);
    auto tape = Tape::compile(e, nv);
    const size_t n = seed % 4 == 0 ? BatchGradientEvaluator::kBatch : 1 + rng() % BatchGradientEvaluator::kBatch;
    // The tape's vars, not nv: an expression that uses x[3] has three even when nv is 2 (ASan
    // found this test reading past points of two coordinates).
    expectBatchMatchesScalar(tape, branchPoints(rng, tape->numVars(), n), be);
  }
}

TEST(BatchGradient, RegisterReuseAndPrunedTapes) {
  // In-place instructions (out == a), and tapes pruned over boxes (as the mesher's block
  // tapes are), which share their root's register layout.
  BatchGradientEvaluator be;
  std::mt19937_64 rng(5);
  const Expr gyroid = sin(8.0 * X) * cos(8.0 * Y) + sin(8.0 * Y) * cos(8.0 * Z) + sin(8.0 * Z) * cos(8.0 * X);
  const Expr model = min(1.0 - X * X - Y * Y - Z * Z, 0.3 - abs(gyroid));
  auto tape = Tape::compile(model, 3);
  expectBatchMatchesScalar(Tape::compile(sin(sin(sin(X * Y))), 2), branchPoints(rng, 2, 64), be);
  IntervalEvaluator iv;
  for (int k = 0; k < 20; ++k) {
    Interval box[3];
    for (auto& b : box) {
      const double lo = -1.2 + 2.0 * double(rng() % 1000) / 1000.0;
      b = Interval(lo, lo + 0.05);
    }
    (void)iv.eval(*tape, box);
    const TapePtr pruned = iv.pruned(tape);
    std::vector<std::vector<double>> pts(1 + rng() % 200, std::vector<double>(3));
    for (auto& p : pts)
      for (int a = 0; a < 3; ++a) p[size_t(a)] = box[a].lo + 0.05 * double(rng() % 1000) / 1000.0;
    expectBatchMatchesScalar(pruned, pts, be);
    expectBatchMatchesScalar(tape, pts, be);
  }
}
