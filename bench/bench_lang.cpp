// HyperFun compiled vs interpreted: a model in HyperFun's sample style (nine soft-object terms
// summed by a while loop, written with plain formulas so the interpreter is not slowed by
// library calls), evaluated by a direct AST interpreter (frep/lang/frontend/interpret.h, the
// baseline) and by the compiled tape (point and batch evaluators), on the same points in the same
// run.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>

#include "frep/evaluators/eval.h"
#include "frep/lang/hyperfun.h"
#include "frep/lang/frontend/interpret.h"

using namespace frep;

namespace {

const char* kModel = R"(
-- nine soft objects on a ring, summed in a while loop (Wyvill's soft field)
my_model(x[3], a[1]) {
  sum = 0;
  i = 1;
  while i <= 9 loop
    angle = 2 * 3.14159265358979 * (i - 1) / 9;
    dx = x[1] - 1.2 * cos(angle);
    dy = x[2] - 1.2 * sin(angle);
    dz = x[3] - 0.2 * sin(3 * angle);
    r2 = (dx * dx + dy * dy + dz * dz) / (0.9 * 0.9);
    if r2 < 1 then
      sum = sum + 1 - 22 / 9 * r2 + 17 / 9 * r2 * r2 - 4 / 9 * r2 * r2 * r2;
    endif;
    i = i + 1;
  endloop;
  my_model = sum - 0.3;
}
)";

double seconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

int main() {
  lang::CompileResult r = lang::compile(kModel, "soft9.hf");
  if (!r.ok) {
    for (auto& d : r.diagnostics) std::fprintf(stderr, "%s\n", d.format().c_str());
    return 1;
  }
  TapePtr tape = Tape::compile(bindParams(r.model.field, {Expr(0.0)}), 3);
  lang::Interpreter interp(kModel);

  const size_t n = 1 << 16;
  std::vector<double> px(n), py(n), pz(n);
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-2, 2);
  for (size_t i = 0; i < n; ++i) px[i] = u(rng), py[i] = u(rng), pz[i] = u(rng);

  // Interpreter: a subset (it is slow), scaled to points per second.
  const size_t ni = n / 16;
  double sinkI = 0;
  auto t0 = std::chrono::steady_clock::now();
  for (size_t i = 0; i < ni; ++i) sinkI += interp.eval({px[i], py[i], pz[i]}, {0.0});
  double interpRate = double(ni) / seconds(t0);

  PointEvaluator pe;
  double sinkP = 0, maxDiff = 0;
  t0 = std::chrono::steady_clock::now();
  for (size_t i = 0; i < n; ++i) {
    double p[3] = {px[i], py[i], pz[i]};
    sinkP += pe.eval(*tape, p);
  }
  double pointRate = double(n) / seconds(t0);
  for (size_t i = 0; i < ni; ++i) {
    double p[3] = {px[i], py[i], pz[i]};
    maxDiff = std::max(maxDiff, std::fabs(pe.eval(*tape, p) - interp.eval({px[i], py[i], pz[i]}, {0.0})));
  }

  BatchEvaluator<double> be;
  be.reserve(*tape);
  double sinkB = 0;
  const size_t B = BatchEvaluator<double>::kBatch;
  t0 = std::chrono::steady_clock::now();
  for (int rep = 0; rep < 4; ++rep)
    for (size_t s = 0; s < n; s += B) {
      for (size_t k = 0; k < B; ++k) be.in(0)[k] = px[s + k], be.in(1)[k] = py[s + k], be.in(2)[k] = pz[s + k];
      sinkB += be.eval(*tape, B)[0];
    }
  double batchRate = 4.0 * double(n) / seconds(t0);

  std::printf("soft9 model: %zu tape instructions\n", tape->size());
  std::printf("  AST interpreter   %12.0f points/s  (baseline)\n", interpRate);
  std::printf("  compiled, point   %12.0f points/s  %6.1fx\n", pointRate, pointRate / interpRate);
  std::printf("  compiled, batch   %12.0f points/s  %6.1fx   (target >= 20x)\n", batchRate, batchRate / interpRate);
  std::printf("  max |compiled - interpreted| = %.3g over %zu points\n", maxDiff, ni);
  if (sinkI + sinkP + sinkB == 1.2345) std::printf(" ");
  return 0;
}
