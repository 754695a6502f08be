// The exact Minkowski algebra path of frMinkowski / frMinkowskiSum / frMinkowskiDiff
// (fr_minkowski.cpp): used when every operand is a basic-set term (registry.h).
#pragma once

#include <vector>

#include "frep/expressions/expr.h"
#include "frep/lang/library/library.h"

namespace frep::lang {

// The union of primitives of A1 ⊕ … ⊕ Ak over the caller's coordinates xs, when every operand
// is an exact basic-set sum in one frame and the sum reduces (reduction.h); false otherwise.
bool exactMinkowskiSum(const std::vector<const Arg*>& operands, const std::vector<Expr>& xs, Expr* out);
// A ⊖ B (frMinkowskiDiff's convention) by eq. 19–21 when A is a block or sphere (or an exact
// chain A' ⊖ B') and B an exact sum; false otherwise.
bool exactMinkowskiDiff(const Arg& A, const Arg& B, const std::vector<Expr>& xs, Expr* out);

// HyperFun's own primitives whose set is a basic set (hfSphere: a ball, hfBlock: a block; their
// fields are sign-exact, not distances): registers `field` as that shape when it is read at the
// plain coordinates with constant placement, so Minkowski operations take the exact algebra or
// the offset path on models written the HyperFun way. Returns field.
// frMorphMinkowski of two basic-set sums by the algebra: (1 - t) A ⊕ t B, each scaled about the
// origin (eq. 4.5); false when either is not a registered sum.
bool exactMinkowskiMorph(const Arg& A, const Arg& B, double t, const std::vector<Expr>& xs, Expr* out);
Expr registerHyperFunShape(const Expr& field, const std::vector<Expr>& xs, bool block,
                           const std::vector<Expr>& place, const std::vector<Expr>& size);
// A HyperFun primitive whose sign-exact field has a closed-form exact signed distance `twin`
// (the same set): registered, when read at the plain coordinates, so a Minkowski sum or
// difference with a ball is the offset of the twin. Returns field.
Expr registerDistanceTwin(const Expr& field, const std::vector<Expr>& xs, const Expr& twin, const std::string& what);

}  // namespace frep::lang
