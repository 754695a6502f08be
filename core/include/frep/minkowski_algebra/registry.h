// Which expression nodes are exact Minkowski terms. The language's basic-set primitives and the
// exact frMinkowski / frMinkowskiDiff results register their field's node here, so a later
// Minkowski operation (or `frep pov`) sees that an operand is a basic-set sum and uses the
// algebra instead of the extremum search. Nodes are hash-consed, so equal fields share one
// entry; the table keeps registered nodes alive. Thread-safe.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "frep/expressions/expr.h"
#include "frep/minkowski_algebra/basic_set.h"

namespace frep::minkowski {

struct ExactTerm {
  // BallOffset: a distance-field operand plus or minus a ball (distance_offset.h);
  // MeshPolytope: a closed mesh plus or minus a convex polytope (mesh_convex_sum.h);
  // Distance: a field whose set is that of `twin`, an exact signed distance on both sides
  // (HyperFun's hfCylinder, hfTorus: sign-exact polynomials of a shape with a closed distance).
  enum class Kind { Sum, Erosion, BallOffset, MeshPolytope, Distance } kind = Kind::Sum;
  Expr twin;  // Distance
  Sum sum;         // Sum: the secondary object; Erosion: the subtracted sum C1 ⊕ … ⊕ CN; BallOffset: the ball
  Sum c0;          // Erosion: the solid eroded (a block or a sphere)
  int pieces = 0;  // primitives of the union (Sum) or intersection (Erosion)
  // BallOffset, MeshPolytope: "A ⊕ ball(...)" for reports, A ⊖ ball (else A ⊕ ball), and where the result
  // is itself an exact signed distance (so a further ball can take the same path).
  std::string operand;
  bool erosion = false, exactOutside = false, exactInside = false;
  double errorBound = 0;  // BallOffset, MeshPolytope: a sampled operand's (sampled_operand.h)
};

void registerExact(const Expr& e, const ExactTerm& t);
std::optional<ExactTerm> lookupExact(const Expr& e);

// One line per registered sum of two or more members (or chain) reachable in f ("exact Minkowski algebra (Roerdink): union of
// 28 primitives, error bound 0"), for job reports next to the extremum nodes' bounds.
std::vector<std::string> describeExact(const Expr& f);

}  // namespace frep::minkowski
