// POV-Ray output of Roerdink's Minkowski algebra (Roerdink-Minkowski §IV.H, the preprocessor):
// a reduced sum as a POV `union` of box / cylinder / sphere / torus, a scene text's `$ … <+> … $`
// terms replaced by such unions, and a frepfarm model built from basic-set terms with union,
// intersection and difference as POV CSG. Used by `frep pov` (pov_command.cpp).
#pragma once

#include <stdexcept>
#include <string>

#include "frep/expressions/expr.h"
#include "frep/minkowski_algebra/reduction.h"

namespace frep::io {

// A place in the input and what is wrong there (file:line:column: message).
struct PovError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
// A number to write is not finite (sizes of 1e308 summed overflow): POV-Ray would read `inf` as
// an identifier. translateScene turns it into a PovError naming the term; from povFromField it
// comes as it is (no place in a scene to name).
struct PovNonFinite : PovError {
  using PovError::PovError;
};

// POV text of the union (one object, in world coordinates). Pieces without interior (the sum is
// a segment, a disc, a rectangle: Remark 6) are drawn `thin` thick.
std::string povUnion(const minkowski::Reduction& r, double thin);

// Replaces every `$ t1 <+> t2 … $` (sums; not in POV comments or strings) and `$ c0 <-> t1 <-> … $` (a block eroded by the
// rest, eq. 19–21) of a POV scene by its POV object; terms: xline(l), yline(l), zline(l),
// xdisc(r), ydisc(r), zdisc(r), sphere(r), block(lx, ly, lz), each optionally followed by its
// placement `, x, y, z` inside the parentheses. Throws PovError naming file:line:column.
std::string translateScene(const std::string& text, const std::string& fileName, double thin);

// The model's field as one POV object: exact basic-set terms (registry.h) combined by max /
// min / R-functions (union, intersection) and negation (`inverse`). Throws PovError when a part
// of the field is not such a term; `where` names it (set by the caller from the model's objects).
std::string povFromField(const Expr& field, double thin, Expr* offending);

}  // namespace frep::io
