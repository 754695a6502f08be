// frepfarm's BatchEvaluator (float and double) against libfive's ArrayEvaluator (float, 256
// points per pass) on the same models and the same points, one thread, in one run. Not part of
// the build: compiled by bench_eval_libfive.sh against a libfive build kept outside this
// repository (libfive is not a dependency).
//   usage: bench_eval_libfive [points (default 1000000)] [rounds (default 7)]
// The libfive trees are translated node by node from the frepfarm expressions (bench_models.h),
// so both evaluate the same formula; the largest difference of the values is printed as a check.
// Timing: thread CPU time per pass over all points (input copy included: a sampler pays it too),
// the engines alternating within each round; medians over the rounds.
#include <time.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <random>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

#include "libfive/eval/eval_array.hpp"
#include "libfive/tree/tree.hpp"

#include "frep/evaluators/eval.h"
#include "frep/expressions/expr.h"
#include "frep/expressions/tape.h"
#include "bench_models.h"

namespace {

using frep::Node;
using frep::Op;
using libfive::Tree;

// The frepfarm DAG as a libfive tree (the ops these models use; anything else is an error).
Tree toLibfive(const Node& n, std::unordered_map<const Node*, Tree>& memo) {
  if (auto it = memo.find(&n); it != memo.end()) return it->second;
  auto arg = [&](int i) { return toLibfive(*n.args[i], memo); };
  Tree t = Tree(0.0);
  switch (n.op) {
    case Op::Const: t = Tree(n.value); break;
    case Op::Var: t = n.index == 0 ? Tree::X() : n.index == 1 ? Tree::Y() : Tree::Z(); break;
    case Op::Neg: t = -arg(0); break;
    case Op::Abs: t = abs(arg(0)); break;
    case Op::Sqrt: t = sqrt(arg(0)); break;  // only on sums of squares here (frep clamps at 0)
    case Op::Sin: t = sin(arg(0)); break;
    case Op::Cos: t = cos(arg(0)); break;
    case Op::PowI:
      if (n.value != 2.0) throw std::runtime_error("PowI other than 2");
      t = square(arg(0));
      break;
    case Op::Add: t = arg(0) + arg(1); break;
    case Op::Sub: t = arg(0) - arg(1); break;
    case Op::Mul: t = arg(0) * arg(1); break;
    case Op::Div: t = arg(0) / arg(1); break;
    case Op::Min: t = min(arg(0), arg(1)); break;
    case Op::Max: t = max(arg(0), arg(1)); break;
    case Op::RAnd: case Op::ROr: {
      // (a + b -+ sqrt(a^2 + b^2 - 2 alpha a b)) / (1 + alpha), Pasko's R-functions
      const Tree a = arg(0), b = arg(1), alpha = Tree(n.value);
      const Tree root = sqrt(square(a) + square(b) - Tree(2.0) * alpha * a * b);
      t = (a + b + (n.op == Op::ROr ? root : -root)) / (Tree(1.0) + alpha);
      break;
    }
    default: throw std::runtime_error("op not translated: " + std::to_string(int(n.op)));
  }
  memo.emplace(&n, t);
  return t;
}

double threadCpu() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

struct Points {
  std::vector<float> x, y, z;  // frep double gets the same (float) coordinates widened
};

Points randomPoints(size_t n, const std::array<double, 3>& lo, const std::array<double, 3>& hi) {
  std::mt19937_64 rng(42);
  Points p;
  std::vector<float>* c[3] = {&p.x, &p.y, &p.z};
  for (int k = 0; k < 3; ++k) {
    std::uniform_real_distribution<double> u(lo[k], hi[k]);
    c[k]->resize(n);
    for (auto& v : *c[k]) v = float(u(rng));
  }
  return p;
}

template <typename T>
double runFrep(const frep::Tape& tape, const Points& p, std::vector<float>* out) {
  frep::BatchEvaluator<T> be;
  be.reserve(tape);
  constexpr size_t B = frep::BatchEvaluator<T>::kBatch;
  const size_t n = p.x.size();
  const double t0 = threadCpu();
  double sink = 0;
  for (size_t s = 0; s < n; s += B) {
    const size_t m = std::min(B, n - s);
    T *ix = be.in(0), *iy = be.in(1), *iz = be.in(2);
    for (size_t k = 0; k < m; ++k) ix[k] = T(p.x[s + k]), iy[k] = T(p.y[s + k]), iz[k] = T(p.z[s + k]);
    const T* r = be.eval(tape, m);
    if (out) for (size_t k = 0; k < m; ++k) (*out)[s + k] = float(r[k]);
    sink += double(r[0]);
  }
  const double t = threadCpu() - t0;
  if (sink == 12345.678) std::puts("");  // keeps the results alive
  return t;
}

double runLibfive(libfive::ArrayEvaluator& e, const Points& p, std::vector<float>* out) {
  constexpr size_t B = libfive::ArrayEvaluator::N;
  const size_t n = p.x.size();
  const double t0 = threadCpu();
  double sink = 0;
  for (size_t s = 0; s < n; s += B) {
    const size_t m = std::min(B, n - s);
    for (size_t k = 0; k < m; ++k) e.set(Eigen::Vector3f(p.x[s + k], p.y[s + k], p.z[s + k]), k);
    const auto r = e.values(m);
    if (out) for (size_t k = 0; k < m; ++k) (*out)[s + k] = r(k);
    sink += double(r(0));
  }
  const double t = threadCpu() - t0;
  if (sink == 12345.678) std::puts("");
  return t;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  const size_t npts = argc > 1 ? size_t(std::atoll(argv[1])) : 1000000;
  const int rounds = argc > 2 ? std::atoi(argv[2]) : 7;
  struct Model {
    const char* name;
    frep::Expr expr;
    std::array<double, 3> lo, hi;
  };
  const Model models[] = {{"csg plate", frep::bench::csgModel(), frep::bench::kCsgLo, frep::bench::kCsgHi},
                          {"gyroid", frep::bench::gyroidModel(), frep::bench::kGyroidLo, frep::bench::kGyroidHi}};
  std::printf("%zu points, 1 thread, thread CPU time, median of %d alternating rounds\n\n", npts, rounds);
  std::printf("%-10s %-16s %12s %14s %10s\n", "model", "evaluator", "seconds", "points/s", "vs libfive");
  for (const Model& m : models) {
    frep::TapePtr tape = frep::Tape::compile(m.expr, 3);
    std::unordered_map<const Node*, Tree> memo;
    libfive::ArrayEvaluator lf(toLibfive(m.expr.node(), memo));
    const Points p = randomPoints(npts, m.lo, m.hi);
    // Same formula check: the values agree to float rounding.
    std::vector<float> vf(npts), vd(npts), vl(npts);
    runFrep<float>(*tape, p, &vf);
    runFrep<double>(*tape, p, &vd);
    runLibfive(lf, p, &vl);
    double maxDiffL = 0, maxDiffF = 0, maxAbs = 0;
    for (size_t i = 0; i < npts; ++i) {
      maxDiffL = std::max(maxDiffL, std::fabs(double(vl[i]) - double(vd[i])));
      maxDiffF = std::max(maxDiffF, std::fabs(double(vf[i]) - double(vd[i])));
      maxAbs = std::max(maxAbs, std::fabs(double(vd[i])));
    }
    std::vector<double> tf, td, tl;
    for (int r = 0; r < rounds; ++r) {
      tf.push_back(runFrep<float>(*tape, p, nullptr));
      td.push_back(runFrep<double>(*tape, p, nullptr));
      tl.push_back(runLibfive(lf, p, nullptr));
    }
    const double l = median(tl);
    auto row = [&](const char* which, double t) {
      std::printf("%-10s %-16s %12.4f %14.4g %9.2fx\n", m.name, which, t, double(npts) / t, l / t);
    };
    row("frep float", median(tf));
    row("frep double", median(td));
    row("libfive (float)", l);
    std::printf("%-10s %zu tape instructions; max |value - frep double|: frep float %.2g, libfive %.2g "
                "(max |f| %.3g)\n\n",
                m.name, tape->size(), maxDiffF, maxDiffL, maxAbs);
  }
  return 0;
}
