// The batch evaluator computes sin and cos of the same input with one ownSinCos (sin_cos.h) where
// the tape's sinCosPlan pairs them. The results must keep the bits of the point evaluator (ownSin,
// ownCos) on every lane: pairs adjacent and far apart, registers reused in between, pruned
// tapes, an extremum in between.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <set>
#include <vector>

#include "frep/evaluators/eval.h"
#include "frep/expressions/expr.h"
#include "frep/expressions/sin_cos.h"
#include "frep/extremum/extremum.h"

using namespace frep;

namespace {

const Expr X = Expr::x(0), Y = Expr::x(1), Z = Expr::x(2);

size_t numFused(const Tape& t) {
  const auto& p = t.sinCosPlan();
  return size_t(std::count(p.begin(), p.end(), Tape::kSinCosDone));
}

// Nodes a with both sin(a) and cos(a) in e: the most pairs a plan can fuse.
size_t numCandidates(const Expr& e) {
  std::set<const Node*> s, c;
  forEachNode(e, [&](const Node& n) {
    if (n.op == Op::Sin) s.insert(n.args[0].get());
    if (n.op == Op::Cos) c.insert(n.args[0].get());
  });
  return size_t(std::count_if(s.begin(), s.end(), [&](const Node* a) { return c.count(a) > 0; }));
}

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// A coordinate: mostly uniform in [-r, r], sometimes a value where sin/cos take special paths
// (tiny, huge, signed zero, non-finite).
double coord(std::mt19937_64& rng, double r) {
  static const double special[] = {0.0, -0.0, 1e-310, -3e-320, 1e-9, 1e6, -1e15, 1e22, 1e300,
                                   std::numeric_limits<double>::infinity(),
                                   std::numeric_limits<double>::quiet_NaN()};
  if (rng() % 16 == 0) return special[rng() % (sizeof special / sizeof special[0])];
  return std::uniform_real_distribution<double>(-r, r)(rng);
}

// Batch (full batches, so every lane loop runs at its full length) against the point evaluator,
// bit for bit. box: where the points are drawn (nullptr: coord(rng, r)).
void expectSameAsPoint(const Tape& tape, std::mt19937_64& rng, double r, size_t npts,
                       const Interval* box = nullptr) {
  constexpr size_t B = BatchEvaluator<double>::kBatch;
  PointEvaluator pe;
  BatchEvaluator<double> be;
  be.reserve(tape);
  std::vector<double> pts(B * 3);
  for (size_t done = 0; done < npts; done += B) {
    const size_t n = std::min(B, npts - done);
    for (size_t k = 0; k < n; ++k)
      for (uint32_t i = 0; i < 3; ++i) {
        double v = box ? std::uniform_real_distribution<double>(box[i].lo, box[i].hi)(rng) : coord(rng, r);
        be.in(i)[k] = pts[k * 3 + i] = v;
      }
    const double* out = be.eval(tape, n);
    for (size_t k = 0; k < n; ++k) {
      const double ref = pe.eval(tape, &pts[k * 3]);
      ASSERT_TRUE(sameBits(out[k], ref)) << "lane " << k << " at (" << pts[k * 3] << ", " << pts[k * 3 + 1]
                                         << ", " << pts[k * 3 + 2] << "): batch " << out[k] << " point " << ref;
    }
  }
}

Expr gyroidBall() {
  Expr g = sin(8 * X) * cos(8 * Y) + sin(8 * Y) * cos(8 * Z) + sin(8 * Z) * cos(8 * X);
  return min(1 - square(X) - square(Y) - square(Z), 0.3 - abs(g));
}

// Many temporaries live at once (a balanced sum of n distinct terms), so the registers freed
// inside it are reused by the allocator for whatever comes next.
Expr pressure(int n, const Expr& v) {
  std::vector<Expr> t;
  for (int i = 0; i < n; ++i) t.push_back(sqrt(square(v - 0.1 * i) + Y * (0.3 + i)));
  while (t.size() > 1) {
    std::vector<Expr> u;
    for (size_t i = 0; i + 1 < t.size(); i += 2) u.push_back(t[i] * t[i + 1] - t[i]);
    if (t.size() % 2) u.push_back(t.back());
    t = u;
  }
  return t[0];
}

TEST(SinCos, GyroidFusesEveryPair) {
  TapePtr t = Tape::compile(gyroidBall(), 3);
  EXPECT_EQ(numFused(*t), 3u);
  std::mt19937_64 rng(1);
  expectSameAsPoint(*t, rng, 1.1, 8192);
  expectSameAsPoint(*t, rng, 1e3, 2048);
}

TEST(SinCos, AdjacentPair) {
  for (const Expr& e : {sin(X) * cos(X), cos(2 * X + Y) - sin(2 * X + Y), atan2(sin(Z), cos(Z))}) {
    TapePtr t = Tape::compile(e, 3);
    EXPECT_EQ(numFused(*t), 1u) << toString(e);
    std::mt19937_64 rng(2);
    expectSameAsPoint(*t, rng, 10.0, 2048);
  }
}

TEST(SinCos, RotationsFuse) {
  // twist about z by an angle depending on z, then about x: x*cos t - y*sin t, ...
  Expr t1 = 1.7 * Z + 0.2, t2 = X - 0.5 * Z;
  Expr x1 = X * cos(t1) - Y * sin(t1), y1 = X * sin(t1) + Y * cos(t1);
  Expr y2 = y1 * cos(t2) - Z * sin(t2), z2 = y1 * sin(t2) + Z * cos(t2);
  Expr e = 0.8 - square(x1) - square(y2 * 2) - square(z2 * 0.5);
  TapePtr t = Tape::compile(e, 3);
  EXPECT_EQ(numFused(*t), 2u);
  std::mt19937_64 rng(3);
  expectSameAsPoint(*t, rng, 2.0, 8192);
}

TEST(SinCos, FarApartWithRegistersReusedBetween) {
  // sin(a) and cos(a) with a long expression using many temporaries between them: the pair may
  // be fused only if the allocator left the second one's output register untouched in between.
  // The bits must be right either way, and both cases must occur.
  const Expr a = 3 * X + Y;
  size_t farFused = 0, farNotFused = 0;
  for (int n : {1, 2, 5, 16, 40}) {
    for (const Expr& e : {sin(a) * pressure(n, X) + cos(a), cos(a) - pressure(n, Z) * sin(a),
                          sin(a) + pressure(n, a) * cos(a) + pressure(n + 1, sin(a) - Z)}) {
      TapePtr t = Tape::compile(e, 3);
      size_t at[2] = {0, 0};  // positions of the one Sin and the one Cos
      for (size_t k = 0; k < t->size(); ++k)
        if (t->code()[k].op == Op::Sin || t->code()[k].op == Op::Cos) at[t->code()[k].op == Op::Cos] = k;
      if (std::max(at[0], at[1]) - std::min(at[0], at[1]) > 50) (numFused(*t) ? farFused : farNotFused)++;
      std::mt19937_64 rng(4 + n);
      expectSameAsPoint(*t, rng, 3.0, 1024);
    }
  }
  EXPECT_GT(farFused, 0u);
  EXPECT_GT(farNotFused, 0u);
}

TEST(SinCos, OnlySinOrOnlyCosHasNoPlan) {
  for (const Expr& e : {sin(X) * sin(Y) + sin(2 * X), cos(X) + cos(Y) * cos(X + Y), sin(X) * cos(Y)}) {
    TapePtr t = Tape::compile(e, 3);
    EXPECT_TRUE(t->sinCosPlan().empty()) << toString(e);
    std::mt19937_64 rng(5);
    expectSameAsPoint(*t, rng, 5.0, 1024);
  }
}

TEST(SinCos, NestedTrigNeverPairs) {
  // sin(a) may overwrite a's register (its last reader); a cos reading that register then
  // reads sin(a), not a.
  for (const Expr& e : {cos(sin(3 * X + Y)), sin(cos(X * Y)) * Z, cos(sin(cos(Z - X)))}) {
    TapePtr t = Tape::compile(e, 3);
    EXPECT_EQ(numFused(*t), 0u) << toString(e);
    std::mt19937_64 rng(10);
    expectSameAsPoint(*t, rng, 5.0, 1024);
  }
}

TEST(SinCos, RegisterReusedForAnotherValue) {
  // sin(c) reads c's register, which is then reused for m; cos(m) reads the same register
  // (and gets a fresh output register) but must not be paired with sin(c).
  const Expr c = cos(X), m = (c * sqrt(Y)) * (sin(X) + 0.5);
  TapePtr t = Tape::compile((sqrt(X) * sin(c)) * (((m - sqrt(m)) - cos(m)) - sin(m)), 3);
  EXPECT_EQ(numFused(*t), 1u);  // cos(m) with sin(m)
  std::mt19937_64 rng(11);
  expectSameAsPoint(*t, rng, 5.0, 1024);
}

// Random models where sin and cos of a few shared arguments are scattered over a tree with
// min/max/select: pairs at every distance, some fusable and some not.
Expr randomModel(std::mt19937_64& rng, const std::vector<Expr>& args, int depth) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  if (depth == 0 || rng() % 5 == 0) {
    const Expr& a = args[rng() % args.size()];
    switch (rng() % 8) {
      case 0: return sin(a);
      case 1: return cos(a);
      case 2: return u(rng) * X + u(rng) * Y - Z;
      case 3: return cos(sin(a));  // sin(a) may land in a's register, then cos reads it
      case 4: return sin(cos(a)) * u(rng);
      case 5: return sin(a) * cos(a * 0.5);  // a * 0.5: another argument, never paired here
      // arguments of their own: registers freed at once and reused for other values
      case 6: return sin(u(rng) * X + Y);
      default: return cos(u(rng) * Z - Y);
    }
  }
  Expr a = randomModel(rng, args, depth - 1), b = randomModel(rng, args, depth - 1);
  switch (rng() % 6) {
    case 0: return a + b;
    case 1: return a * b - u(rng);
    case 2: return max(a, b);
    case 3: return min(a, -b);
    case 4: return select(gt(X, u(rng)), a, b);
    default: return a - sqrt(square(b) + u(rng) * u(rng));
  }
}

TEST(SinCos, RandomModelsKeepTheBits) {
  std::mt19937_64 rng(6);
  size_t fused = 0, missed = 0;
  for (int m = 0; m < 60; ++m) {
    std::uniform_real_distribution<double> u(-3.0, 3.0);
    std::vector<Expr> args = {X, Y * u(rng), u(rng) * X + Z, sqrt(square(X) + square(Y)) * u(rng)};
    Expr e = randomModel(rng, args, 7);
    TapePtr t = Tape::compile(e, 3);
    fused += numFused(*t);
    missed += numCandidates(e) - numFused(*t);
    expectSameAsPoint(*t, rng, 2.0, 512);
    if (HasFatalFailure()) return;
  }
  // Both sides of the plan's checks are exercised.
  EXPECT_GT(fused, 30u);
  EXPECT_GT(missed, 10u);
}

TEST(SinCos, PrunedTapes) {
  // A union of gyroid-like and rotated pieces: boxes decide the min/max, the pruned tapes keep
  // (or gain) pairs and must give the full tape's bits inside their box.
  Expr t1 = 2 * Z;
  Expr xr = X * cos(t1) - Y * sin(t1), yr = X * sin(t1) + Y * cos(t1);
  Expr twisted = 0.3 - square(xr - 0.5) - square(yr) * 4;
  Expr e = max(max(gyroidBall() - 0.1 * Z, twisted), min(sin(3 * Y) * cos(3 * Y) - X, 0.5 - abs(Z)));
  TapePtr full = Tape::compile(e, 3);
  EXPECT_GE(numFused(*full), 5u);
  std::mt19937_64 rng(7);
  IntervalEvaluator ie;
  size_t prunedWithPairs = 0;
  for (int b = 0; b < 200; ++b) {
    Interval box[3];
    const double size = 0.05 + 0.4 * std::uniform_real_distribution<double>(0.0, 1.0)(rng);
    for (auto& iv : box) {
      const double lo = std::uniform_real_distribution<double>(-1.5, 1.5 - size)(rng);
      iv = {lo, lo + size};
    }
    ie.eval(*full, box);
    TapePtr pruned = ie.pruned(full);
    if (pruned == full) continue;
    prunedWithPairs += numFused(*pruned) > 0;
    expectSameAsPoint(*pruned, rng, 0.0, 256, box);
    // and the same bits as the full tape there
    PointEvaluator pe;
    BatchEvaluator<double> be;
    be.reserve(*pruned);
    double p[3];
    for (int i = 0; i < 3; ++i) be.in(i)[0] = p[i] = 0.5 * (box[i].lo + box[i].hi);
    ASSERT_TRUE(sameBits(be.eval(*pruned, 1)[0], pe.eval(*full, p)));
    if (HasFatalFailure()) return;
  }
  EXPECT_GT(prunedWithPairs, 20u);
}

TEST(SinCos, NoPairAcrossAnExtremum) {
  // ext(x) = max over u in [-1, 1] of x - u^2 = x exactly (the grid holds u = 0), so the point
  // and batch evaluators agree bitwise whatever their search does.
  ExtremumSpec s;
  s.body = Expr::x(0) - square(Expr::x(1));
  s.inputs = {sin(X) + 0.25};
  s.hidden = 1;
  s.lo = {-1.0};
  s.hi = {1.0};
  s.method = ExtremumMethod::Grid;
  s.eps = 0.25;
  Expr ext = extremum(s);
  Expr e = (ext - cos(X)) * sin(X);
  TapePtr t = Tape::compile(e, 3);
  // code: sin(x), +0.25, extremum, cos(x), ...: the extremum separates sin and cos of x
  size_t sinAt = t->size(), extAt = t->size(), cosAt = t->size();
  for (size_t k = 0; k < t->size(); ++k) {
    const Op op = t->code()[k].op;
    if (op == Op::Sin && sinAt == t->size()) sinAt = k;
    if (op == Op::Extremum) extAt = k;
    if (op == Op::Cos) cosAt = k;
  }
  ASSERT_TRUE(sinAt < extAt && extAt < cosAt);
  EXPECT_EQ(numFused(*t), 0u);
  std::mt19937_64 rng(8);
  expectSameAsPoint(*t, rng, 3.0, 512);
}

TEST(SinCos, FloatMatchesOwnSinCosFloat) {
  // No float reference evaluator: compare with the same formula evaluated in float by hand, sin
  // and cos being ownSinCosFloat (NaNs only as NaNs: which operand's NaN
  // propagates depends on the order of operands).
  TapePtr t = Tape::compile(sin(X) * cos(X) - cos(Y) + sin(Y) * Z, 3);
  EXPECT_EQ(numFused(*t), 1u);  // sin(y), cos(y): cos(y)'s register is used between them
  BatchEvaluator<float> be;
  be.reserve(*t);
  constexpr size_t B = BatchEvaluator<float>::kBatch;
  std::mt19937_64 rng(9);
  for (int rep = 0; rep < 16; ++rep) {
    float p[B][3];
    for (size_t k = 0; k < B; ++k)
      for (int i = 0; i < 3; ++i) be.in(i)[k] = p[k][i] = float(coord(rng, rep < 8 ? 4.0 : 1e5));
    const float* out = be.eval(*t, B);
    for (size_t k = 0; k < B; ++k) {
      const float x = p[k][0], y = p[k][1], z = p[k][2];
      auto fsin = [](float v) { float s, c; ownSinCosFloat(v, s, c); return s; };
      auto fcos = [](float v) { float s, c; ownSinCosFloat(v, s, c); return c; };
      const float ref = fsin(x) * fcos(x) - fcos(y) + fsin(y) * z;
      ASSERT_TRUE(std::memcmp(&out[k], &ref, sizeof ref) == 0 || (std::isnan(out[k]) && std::isnan(ref)))
          << x << " " << y << " " << z << ": " << out[k] << " vs " << ref;
    }
  }
}

}  // namespace
