// A certified bound on how far a tape's single-precision batch value (BatchEvaluator<float>) can
// be from its double-precision one (BatchEvaluator<double>) anywhere in a box: where |f_float|
// exceeds the bound, f_double is nonzero and has f_float's sign, so a sign image can be computed
// in float and only the lanes below the bound recomputed in double (frep/sampling/plane.h).
#pragma once

#include <vector>

#include "frep/evaluators/interval.h"
#include "frep/expressions/dense_tape.h"
#include "frep/expressions/tape.h"

namespace frep {

class FloatErrorBound {
 public:
  // Whether the bound covers every op of the tape: + - * / neg abs min max sqrt square copy (the
  // correctly rounded ones) and the R-functions (RAnd, ROr; parameter in (-1, 1)). Other tapes
  // get +inf from bound(); a division by an enclosure that may reach 0 too.
  static bool supports(const Tape& tape);
  // B >= |f_float(x) - f_double(x)| for every x in the box (box[i]: var i, the coordinates as
  // the caller passes them in double; the float lanes get them rounded to float). +inf when the
  // tape is not supported or a value may leave float's range.
  double bound(const Tape& tape, const Interval* box);
  // The same for a DenseTape (every op of which is covered), after bind(root) with the root
  // tape it derives from: the constants are entered once per root, not per call (a call of
  // the Tape overload in between enters its own: bind again).
  void bind(const Tape& root);
  double bound(const DenseTape& tape, const Interval* box);

 private:
  struct Reg {
    double lo, hi;  // encloses the exact (real) value over the box
    double ef, ed;  // bounds on |float value - exact| and |double value - exact|
  };
  template <typename I>
  double propagate(const I* code, size_t size, uint32_t result);
  void enterConstants(const std::vector<double>& uniforms);
  std::vector<Reg> regs_;
};

}  // namespace frep
