// The reduction of a secondary Minkowski object into a union of ray-tracer primitives
// (Roerdink-Minkowski §III.D eq. 16, §IV.B, §IV.D, Theorem 5) and its exact F-rep.
//
// Implemented for sums whose circle part has at most one disc axis (after discs of one axis
// are added): block ⊕ disc ⊕ sphere and all its degenerate cases (segments, rectangles,
// blocks, discs, cylinders, discus, rounded blocks, ...), in any frame. Sums of discs along two
// or three axes need the paper's bicircle / tricircle surfaces (degree 4 and higher, R9–R16),
// for which no closed-form distance exists; reduce() reports them as not reducible and the
// caller falls back to the certified extremum search.
//
// Grouping (§IV.D): the lines form one group (the block), the circles and the sphere another
// (the core K = disc ⊕ ball), and the pieces are the offset by the ball of the faces, edges and
// arcs of block ⊕ disc, so collinear cylinders come out merged.
#pragma once

#include <string>
#include <vector>

#include "frep/expressions/expr.h"
#include "frep/minkowski_algebra/basic_set.h"

namespace frep::minkowski {

enum class PieceKind { Block, Cylinder, Sphere, Torus };

// One ray-tracer primitive in the sum's local frame (see Sum): a block [lo, hi]; a cylinder
// of radius `radius` around the segment from `base` along `axis` of length `length`; a
// sphere (centre `base`, radius); a torus around `axis` through `base` (major radius `radius`,
// minor `minor`).
struct Piece {
  PieceKind kind = PieceKind::Block;
  int axis = 0;
  Vec3 lo{0, 0, 0}, hi{0, 0, 0};
  Vec3 base{0, 0, 0};
  double radius = 0, length = 0, minor = 0;
  int dimension() const;  // 0..3: a block of zero thickness, a cylinder of length 0, ...
  std::string describe() const;
};

struct Reduction {
  bool ok = false;
  std::string reason;         // why not, when !ok
  std::vector<Piece> pieces;  // local frame of `sum`
  Sum sum;
  int count(PieceKind k) const;
};

Reduction reduce(const Sum& sum);

// F-rep of the union (inside >= 0): max over the pieces of minus their exact signed distance,
// read at the local point R^T (X − offset) of the world coordinates x0, x1, x2. Each piece is
// an exact SDF, so the union is exact outside and 1-Lipschitz and sign-exact inside. Solids of
// empty interior (a segment, a disc, a rectangle) come out as minus the distance: 0 on the
// set, negative elsewhere.
Expr unionExpr(const Reduction& r);
Expr unionExpr(const Reduction& r, const std::vector<Expr>& coords);
// The same value evaluated directly (tests, the POV writer's checks).
double unionValue(const Reduction& r, const Vec3& world);

// Support function h(n) = max over the union of n·X, world frame, |n| = 1.
double supportValue(const Reduction& r, const Vec3& n);

// Subtraction chains (eq. 19–21): C0 ⊖ (C1 ⊕ … ⊕ CN) = ∩_j C0 ⊖ R_j with frMinkowskiDiff's
// convention {X : X + B ⊂ C0}. Exact when C0 is a block (each C0 ⊖ R_j is the block moved in by
// R_j's support function: a block) or a sphere (C0 ⊖ R_j: the points whose farthest point of
// X + R_j is within the radius, in closed form for each primitive). c0 is a sum that is a block
// (segments and blocks only) or a sphere (spheres only), in any frame. Returns false otherwise.
bool erosionExpr(const Sum& c0, const Reduction& r, const std::vector<Expr>& coords, Expr* out,
                 std::string* reason);

}  // namespace frep::minkowski
