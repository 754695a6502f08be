// The min/max form of a model: every R-function (RAnd / ROr, any parameter a) that the sign of
// the whole depends on through sign-preserving operations only is replaced by min / max.
//
// R-functions are sign-equivalent to min and max: for every a in (-1, 1], R_a(f1, f2) is > 0,
// = 0 or < 0 exactly where min(f1, f2) is (Pasko-Survey, R-functions; the zero of
// f1 + f2 - sqrt(f1^2 + f2^2 - 2a f1 f2) needs f1 f2 = 0 and f1 + f2 >= 0). Min, max, negation,
// multiplication or division by a positive constant and the branches of a select pass the sign
// of their operands through, so rewriting beneath them keeps the set f >= 0 and its boundary
// f = 0 exactly, while anything else (sums, offsets, blends, products of fields) uses values
// and is left as it is. One product is also sign-equivalent to a min: p * q where p + q is a
// constant >= 0 (HyperFun's slab (x - v)(v + d - x) of hfBlock), since p and q cannot both be
// negative. The value changes: that is the point. The extremum searches (Minkowski
// sums, projections, sweeps, offsets) run their operands in this form, where interval bounds
// and constraint contraction are sharp (min/max of terms) instead of blurred by the sqrt of the
// R-functions (docs/extremum.md, "Operands in min/max form").
#pragma once

#include "frep/expressions/expr.h"

namespace frep {

Expr minMaxForm(const Expr& e);

// Whether minMaxForm(e) differs from e (e holds an R-function in sign position).
bool hasSignPositionRFunction(const Expr& e);

}  // namespace frep
