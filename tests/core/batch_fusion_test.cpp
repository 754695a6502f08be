// The batch evaluator's tape specialisation (eval_batch.cpp): constant operands read as scalars
// and fused chains ((x +- c)^2, d - (x +- c)^2, (x +- c)^2 - d, u - x^2, x^2 - u, min/max of a
// sum, difference or product; each intermediate read by nothing else) must
// give the point evaluator's bits on every lane, finite or not; the float path stays close.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "frep/evaluators/eval.h"
#include "frep/expressions/expr.h"

using namespace frep;

namespace {

const Expr X = Expr::x(0), Y = Expr::x(1), Z = Expr::x(2);

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

bool isSquare(const Instr& i) { return i.op == Op::PowI && i.imm == 2.0; }

// The chain shapes the evaluator fuses, counted on the tape (so the test knows it covers them).
struct Shapes {
  int shiftSquare = 0, shiftSquareThenSub = 0, squareThenSub = 0, squareThenSubElsewhere = 0, intoMinMax = 0;
};
Shapes shapesOf(const Tape& t) {
  Shapes s;  // (x +- c)^2 with c on either side; then d - . or . - d; x^2 then u - . or . - u
  const auto& c = t.code();
  const uint32_t nu = t.numUniforms();
  auto subInPlace = [](const Instr& n, uint32_t r) {
    return n.op == Op::Sub && n.out == r && ((n.b == r) != (n.a == r));
  };
  for (size_t k = 0; k + 1 < c.size(); ++k) {
    const uint32_t r = c[k].out;
    const bool sq = isSquare(c[k + 1]) && c[k + 1].a == r && c[k + 1].out == r;
    const bool ua = c[k].a < nu, ub = c[k].b < nu;
    if ((c[k].op == Op::Add || c[k].op == Op::Sub) && ua != ub && (ua ? c[k].b : c[k].a) != r && sq) {
      const bool third = k + 2 < c.size() && subInPlace(c[k + 2], r) &&
                         (c[k + 2].b == r ? c[k + 2].a : c[k + 2].b) < nu;
      ++(third ? s.shiftSquareThenSub : s.shiftSquare);
    }
    if (isSquare(c[k]) && c[k].a != r && subInPlace(c[k + 1], r)) ++s.squareThenSub;
    // t = a +-* b (or x^2) read only by the next min/max (sub), which overwrites t, or k + 2
    // overwrites t unread
    const Instr& n = c[k + 1];
    const bool mm = (n.op == Op::Min || n.op == Op::Max) && ((n.a == r) != (n.b == r));
    auto reads = [](const Instr& in, uint32_t q) {
      const int ar = opArity(in.op);
      return (ar > 0 && in.a == q) || (ar > 1 && in.b == q) || (ar > 2 && in.c == q);
    };
    const bool dead = n.out == r || (k + 2 < c.size() && c[k + 2].out == r && !reads(c[k + 2], r));
    if ((c[k].op == Op::Add || c[k].op == Op::Sub || c[k].op == Op::Mul) && mm && dead) ++s.intoMinMax;
    if (isSquare(c[k]) && c[k].a != r && n.op == Op::Sub && n.out != r && ((n.a == r) != (n.b == r)) && dead)
      ++s.squareThenSubElsewhere;
  }
  return s;
}

Expr model() {
  // cylinders and spheres as CSG writes them, constants on both sides of every binary op
  Expr cyl = 0.04 - square(X - 0.3) - square(Y + 0.2);
  Expr bowl = square(Z) - 0.5 + square(X - 1.0) * 0.25;
  Expr cap = 1.0 - square(Y);
  Expr shifted = square(Z + 0.7) - 2.0 + square(1.5 - X);
  Expr mix = min(X, 0.5) + max(0.25, Y) * (2.0 / (X + 3.0)) - Z / 3.0 + (3.0 - Y) * X;
  // a grid of holes as the CSG bench model writes it: max chains of differences
  Expr holes;
  for (int i = 0; i < 6; ++i) {
    Expr h = 0.04 - square(X - 0.4 * (i % 3)) - square(Y - 0.5 * (i / 3));
    holes = i ? max(holes, h) : h;
  }
  return max(min(cyl, bowl), cap) + shifted * mix - min(0.5, Z) + max(Y * Z, 0.1) + min(holes * X, Z - holes);
}

double coord(std::mt19937_64& rng) {
  static const double special[] = {0.0, -0.0, 0.3, -0.2, 1e-310, 1e200, -1e300,
                                   std::numeric_limits<double>::infinity(),
                                   -std::numeric_limits<double>::infinity(),
                                   std::numeric_limits<double>::quiet_NaN()};
  if (rng() % 12 == 0) return special[rng() % (sizeof special / sizeof special[0])];
  return std::uniform_real_distribution<double>(-3.0, 3.0)(rng);
}

// The models: the CSG-like one, and squares nobody else shares (hash-consing reuses x^2 across
// a model, which keeps its square alive).
std::vector<Expr> models() {
  return {model(), 1.0 - square(X) - square(Y) - square(Z), square(Z) - 0.5 + 2.0 * X};
}

TEST(BatchFusion, TapeHasEveryFusedShape) {
  Shapes s;
  for (const Expr& e : models()) {
    const Shapes m = shapesOf(*Tape::compile(e, 3));
    s.shiftSquare += m.shiftSquare;
    s.shiftSquareThenSub += m.shiftSquareThenSub;
    s.squareThenSub += m.squareThenSub;
    s.squareThenSubElsewhere += m.squareThenSubElsewhere;
    s.intoMinMax += m.intoMinMax;
  }
  EXPECT_GE(s.shiftSquare, 1);
  EXPECT_GE(s.shiftSquareThenSub, 1);
  EXPECT_GE(s.squareThenSub, 1);
  EXPECT_GE(s.squareThenSubElsewhere, 1);
  EXPECT_GE(s.intoMinMax, 2);
}

// Batch (double) against the point evaluator, bit for bit, special coordinates included.
void expectSameBits(const Tape& t) {
  constexpr size_t B = BatchEvaluator<double>::kBatch;
  PointEvaluator pe;
  BatchEvaluator<double> be;
  be.reserve(t);
  std::mt19937_64 rng(31);
  std::vector<double> p(B * 3);
  for (int rep = 0; rep < 40; ++rep) {
    const size_t n = rep % 5 == 4 ? 1 + rng() % B : B;  // short batches too
    for (size_t k = 0; k < n; ++k)
      for (uint32_t i = 0; i < 3; ++i) be.in(i)[k] = p[k * 3 + i] = coord(rng);
    const double* out = be.eval(t, n);
    for (size_t k = 0; k < n; ++k) {
      const double ref = pe.eval(t, &p[k * 3]);
      ASSERT_TRUE(sameBits(out[k], ref)) << "lane " << k << " at (" << p[k * 3] << ", " << p[k * 3 + 1] << ", "
                                         << p[k * 3 + 2] << "): batch " << out[k] << " point " << ref;
    }
  }
}

TEST(BatchFusion, SameBitsAsPointEvaluator) {
  for (const Expr& e : models()) {
    expectSameBits(*Tape::compile(e, 3));
    if (HasFatalFailure()) return;
  }
}

// The float path against the point evaluator at the same (float) coordinates.
void expectFloatClose(const Tape& t) {
  constexpr size_t B = BatchEvaluator<float>::kBatch;
  PointEvaluator pe;
  BatchEvaluator<float> bf;
  bf.reserve(t);
  std::mt19937_64 rng(32);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  std::vector<double> pts(B * 3);
  for (size_t k = 0; k < B; ++k)
    for (uint32_t i = 0; i < 3; ++i) bf.in(i)[k] = float(pts[k * 3 + i] = double(float(u(rng))));
  const float* out = bf.eval(t, B);
  for (size_t k = 0; k < B; ++k) {
    const double ref = pe.eval(t, &pts[k * 3]);
    EXPECT_NEAR(double(out[k]), ref, 1e-5 * (1 + std::fabs(ref))) << "lane " << k;
  }
}

TEST(BatchFusion, FloatPathClose) {
  for (const Expr& e : models()) expectFloatClose(*Tape::compile(e, 3));
}

}  // namespace
