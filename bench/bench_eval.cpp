// Evaluator throughput (points/second) on a sphere, a ~100-node CSG model and the gyroid ball: the naive tree
// walker (baseline, tree_walker.h) and its memoised variant, PointEvaluator, BatchEvaluator<double> and <float>.
// Prints, from the same run, the ratios against the tree walker and the float-vs-double error.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <unistd.h>

#include "frep/evaluators/eval.h"
#include "frep/expressions/expr.h"
#include "bench_models.h"
#include "tree_walker.h"

using namespace frep;

namespace {

const Expr X = Expr::x(0), Y = Expr::x(1), Z = Expr::x(2);

using bench::csgModel;
using bench::sphereModel;

constexpr size_t kPoints = 4096;

struct Model {
  std::string name;
  Expr expr;
  TapePtr tape;
  std::vector<double> pts;  // kPoints x 3, point-major
};

std::vector<double> samplePoints(const double half[3]) {
  std::mt19937_64 rng(42);
  std::vector<double> p(kPoints * 3);
  for (size_t i = 0; i < p.size(); ++i)
    p[i] = half[i % 3] * (2.0 * double(rng() % 1000001) / 1000000.0 - 1.0);
  return p;
}

template <typename T>
void evalAll(BatchEvaluator<T>& be, const Model& m, std::vector<T>* out) {
  be.reserve(*m.tape);
  for (size_t s = 0; s < kPoints; s += BatchEvaluator<T>::kBatch) {
    const size_t n = std::min(BatchEvaluator<T>::kBatch, kPoints - s);
    for (uint32_t v = 0; v < 3; ++v) {
      T* in = be.in(v);
      for (size_t k = 0; k < n; ++k) in[k] = T(m.pts[(s + k) * 3 + v]);
    }
    const T* r = be.eval(*m.tape, n);
    if (out) std::copy(r, r + n, out->begin() + long(s));
    else benchmark::DoNotOptimize(r[0]);
  }
}

void registerModel(const Model& m) {
  benchmark::RegisterBenchmark((m.name + "/tree").c_str(), [&m](benchmark::State& st) {
    for (auto _ : st)
      for (size_t i = 0; i < kPoints; ++i) benchmark::DoNotOptimize(bench::treeWalk(m.expr.node(), &m.pts[i * 3]));
    st.SetItemsProcessed(int64_t(st.iterations()) * int64_t(kPoints));
  });
  benchmark::RegisterBenchmark((m.name + "/memo_tree").c_str(), [&m](benchmark::State& st) {
    bench::MemoWalker walker(m.expr);
    for (auto _ : st)
      for (size_t i = 0; i < kPoints; ++i) benchmark::DoNotOptimize(walker.eval(&m.pts[i * 3]));
    st.SetItemsProcessed(int64_t(st.iterations()) * int64_t(kPoints));
  });
  benchmark::RegisterBenchmark((m.name + "/point").c_str(), [&m](benchmark::State& st) {
    PointEvaluator pe;
    for (auto _ : st)
      for (size_t i = 0; i < kPoints; ++i) benchmark::DoNotOptimize(pe.eval(*m.tape, &m.pts[i * 3]));
    st.SetItemsProcessed(int64_t(st.iterations()) * int64_t(kPoints));
  });
  // Input transposition (point-major to SoA) is included: a sampler pays it too.
  benchmark::RegisterBenchmark((m.name + "/batch_double").c_str(), [&m](benchmark::State& st) {
    BatchEvaluator<double> be;
    for (auto _ : st) evalAll<double>(be, m, nullptr);
    st.SetItemsProcessed(int64_t(st.iterations()) * int64_t(kPoints));
  });
  benchmark::RegisterBenchmark((m.name + "/batch_float").c_str(), [&m](benchmark::State& st) {
    BatchEvaluator<float> be;
    for (auto _ : st) evalAll<float>(be, m, nullptr);
    st.SetItemsProcessed(int64_t(st.iterations()) * int64_t(kPoints));
  });
}

// Keeps the console output and remembers points/second per benchmark name.
class RateReporter : public benchmark::ConsoleReporter {
 public:
  RateReporter() : ConsoleReporter(isatty(1) ? OO_Defaults : OO_Tabular) {}
  std::map<std::string, double> rate;
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& r : runs) {
      auto it = r.counters.find("items_per_second");
      if (r.run_type == Run::RT_Iteration && it != r.counters.end()) rate[r.benchmark_name()] = it->second;
    }
  }
};

// Float vs double over the same points. Relative error is reported only where |f| >= 0.01,
// since near the surface the pointwise relative error is unbounded by construction.
void reportFloatError(const Model& m) {
  BatchEvaluator<double> bd;
  BatchEvaluator<float> bf;
  std::vector<double> d(kPoints);
  std::vector<float> f(kPoints);
  evalAll(bd, m, &d);
  evalAll(bf, m, &f);
  double maxAbs = 0, maxRel = 0, maxVal = 0;
  for (size_t i = 0; i < kPoints; ++i) {
    const double e = std::fabs(double(f[i]) - d[i]);
    maxAbs = std::max(maxAbs, e);
    maxVal = std::max(maxVal, std::fabs(d[i]));
    if (std::fabs(d[i]) >= 0.01) maxRel = std::max(maxRel, e / std::fabs(d[i]));
  }
  std::printf("%-8s float vs double over %zu points: max abs err %.3g (%.3g of max|f| %.3g), "
              "max rel err (|f|>=0.01) %.3g\n",
              m.name.c_str(), kPoints, maxAbs, maxAbs / maxVal, maxVal, maxRel);
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  std::vector<Model> models(3);
  models[0].name = "sphere";
  models[0].expr = sphereModel();
  models[1].name = "csg";
  models[1].expr = csgModel();
  models[2].name = "gyroid";
  models[2].expr = bench::gyroidModel();
  const double csgHalf[3] = {2.2, 1.4, 1.0}, gyroidHalf[3] = {1.1, 1.1, 1.1};
  for (auto& m : models) {
    m.tape = Tape::compile(m.expr, 3);
    m.pts = samplePoints(m.name == "gyroid" ? gyroidHalf : csgHalf);
    std::printf("%-8s %zu DAG nodes, %zu tree nodes (visits per point of the tree walker), "
                "%zu tape instructions, %u registers\n",
                m.name.c_str(), nodeCount(m.expr), bench::treeSize(m.expr.node()), m.tape->size(),
                m.tape->numRegs());
    registerModel(m);
  }
  RateReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  std::printf("\n");
  for (const auto& m : models) {
    const double tree = reporter.rate[m.name + "/tree"];
    const double memo = reporter.rate[m.name + "/memo_tree"];
    if (tree <= 0 || memo <= 0) continue;
    for (const char* which : {"memo_tree", "point", "batch_double", "batch_float"}) {
      const double r = reporter.rate[m.name + "/" + which];
      if (r > 0)
        std::printf("%-8s %-13s %10.3g points/s  %7.1fx tree walker  %6.1fx memoised walker\n",
                    m.name.c_str(), which, r, r / tree, r / memo);
    }
  }
  for (const auto& m : models) reportFloatError(m);
  benchmark::Shutdown();
  return 0;
}
