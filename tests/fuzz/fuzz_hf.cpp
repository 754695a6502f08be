// Fuzz target: the .hf front end (lexer, parser, lowering, hf*/fr* libraries) on arbitrary text,
// compiled to a tape as the farm's workers do, then evaluated at a few points against the core's
// contracts (docs/core.md): every error has a place; batch = point evaluation; the interval
// over a box holds every point value inside it; the pruned tape gives the full tape's bits.
// Models with extremum nodes are compiled only (each evaluation is a search, seconds under the
// sanitizers; their evaluators are tested in tests/core).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "frep/evaluators/eval.h"
#include "frep/evaluators/interval.h"
#include "frep/expressions/tape.h"
#include "frep/lang/field.h"
#include "frep/lang/hyperfun.h"
#include "fuzz_target.h"

namespace {
bool same(double a, double b) { return (std::isnan(a) && std::isnan(b)) || a == b; }
}  // namespace

void frep::fuzz::hf(const uint8_t* data, size_t size) {
  if (size > 8192) return;
  const std::string source(reinterpret_cast<const char*>(data), size);
  lang::CompileOptions options;
  options.maxLoopIterations = 2000;  // bounds each input's time, as the default bounds a compile
  const lang::CompileResult r = lang::compile(source, "fuzz.hf", options);
  for (const lang::Diagnostic& d : r.diagnostics) {
    if (d.severity == lang::Diagnostic::Severity::Error) FREP_FUZZ_CHECK(d.line >= 1 && d.column >= 1);
    (void)d.format();
  }
  if (!r.ok) return;
  // As frep sample does: x[4..] held at 0, a[] at 0.
  lang::FieldSpec spec;
  if (r.model.xSize > 3)
    for (int i = 0; i < r.model.xSize; ++i) {
      spec.axis.push_back(i < 3 ? i : -1);
      spec.constant.push_back(0.0);
    }
  TapePtr tape;
  try {
    tape = Tape::compile(lang::fieldOf(r.model, spec), uint32_t(std::min(r.model.xSize, 3)));
  } catch (const std::invalid_argument&) {
    return;  // refused with a message (e.g. a 2D model's x mapping), as frep does
  }
  if (tape->size() > 4096) return;  // evaluation time, not new code paths
  if (!tape->extrema().empty()) return;  // each evaluation is a search: compiled, not evaluated
  const uint32_t n = tape->numVars();
  const double points[4][3] = {{0, 0, 0}, {0.5, -0.25, 1}, {-1.5, 1.25, -0.75}, {1.9, 1.9, -1.9}};
  Interval box[3];
  for (uint32_t a = 0; a < 3; ++a) box[a] = Interval(-2, 2);
  IntervalEvaluator iv;
  const Interval whole = iv.eval(*tape, box);
  const TapePtr pruned = iv.pruned(tape);
  PointEvaluator pe;
  BatchEvaluator<double> be;
  be.reserve(*tape);
  GradientEvaluator ge;
  BatchGradientEvaluator bge;
  bge.reserve(*tape);
  double grad[3];
  for (size_t k = 0; k < 4; ++k)
    for (uint32_t a = 0; a < n; ++a) be.in(a)[k] = points[k][a];
  const double* batch = be.eval(*tape, 4);
  for (size_t k = 0; k < 4; ++k)
    for (uint32_t a = 0; a < n; ++a) bge.in(a)[k] = points[k][a];
  bge.eval(*tape, 4);
  double values[4];
  for (size_t k = 0; k < 4; ++k) values[k] = batch[k];
  for (size_t k = 0; k < 4; ++k) {
    const double v = pe.eval(*tape, points[k]);
    FREP_FUZZ_CHECK(same(v, values[k]));
    FREP_FUZZ_CHECK(std::isnan(v) || whole.contains(v));
    FREP_FUZZ_CHECK(same(pe.eval(*pruned, points[k]), v));
    std::fill_n(grad, 3, 0.0);
    const double gv = ge.eval(*tape, points[k], grad);  // the batch gradient gives its bits
    FREP_FUZZ_CHECK(same(bge.value()[k], gv));
    for (uint32_t a = 0; a < 3; ++a) FREP_FUZZ_CHECK(same(bge.partial(int(a))[k], a < n ? grad[a] : 0.0));
  }
}

FREP_FUZZ_ENTRY(frep::fuzz::hf)
