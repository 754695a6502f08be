// The exact Minkowski algebra path of frMinkowski / frMinkowskiSum / frMinkowskiDiff
// (lib_fr_minkowski.cpp): used when every operand is a basic-set term (registry.h).
#pragma once

#include <vector>

#include "frep/expressions/expr.h"
#include "frep/lang/library.h"

namespace frep::lang {

// The union of primitives of A1 ⊕ … ⊕ Ak over the caller's coordinates xs, when every operand
// is an exact basic-set sum in one frame and the sum reduces (reduction.h); false otherwise.
bool exactMinkowskiSum(const std::vector<const Arg*>& operands, const std::vector<Expr>& xs, Expr* out);
// A ⊖ B (frMinkowskiDiff's convention) by eq. 19–21 when A is a block or sphere (or an exact
// chain A' ⊖ B') and B an exact sum; false otherwise.
bool exactMinkowskiDiff(const Arg& A, const Arg& B, const std::vector<Expr>& xs, Expr* out);

}  // namespace frep::lang
