// A program of a frepfarm user: compile a HyperFun model and evaluate it at one point.
#include <cstdio>
#include <frep/evaluators/eval.h>
#include <frep/lang/field.h>
int main() {
  auto r = frep::lang::compile("my_model(x[3], a[1]) { my_model = 1 - x[1]^2 - x[2]^2 - x[3]^2; }", "ball.hf");
  for (const auto& d : r.diagnostics) std::fprintf(stderr, "%s\n", d.format().c_str());
  if (!r.ok) return 1;
  frep::TapePtr tape = frep::Tape::compile(frep::lang::fieldOf(r.model, {}), 3);
  const double p[3] = {0.5, 0.25, 0.0};
  std::printf("%.17g\n", frep::PointEvaluator().eval(*tape, p));  // 1 - 0.25 - 0.0625 = 0.6875
}
