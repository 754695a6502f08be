// The reduction of a secondary Minkowski object into a union of ray-tracer primitives
// (Roerdink-Minkowski §III.D eq. 16, §IV.B, §IV.D, Theorem 5) and its exact F-rep.
//
// Sums whose circle part has at most one disc axis (after discs of one axis are added):
// block ⊕ disc ⊕ sphere and all its degenerate cases (segments, rectangles, blocks, discs,
// cylinders, discus, rounded blocks, ...), in any frame, reduce to closed-form primitives; two disc
// axes without a sphere: block ⊕ bidisc (bidisc.h), one closed-form piece whose ray-tracer form is
// bicircles, cylinders and blocks (primitives()). A sphere with two disc axes, or three disc axes
// (the bicircle-sphere, tricircle and tricircle-sphere surfaces R12–R16, degree above 4, §IV.E):
// one DiscSum piece, the exact distance of disc_sum_distance.h (convex projection by support
// functions, no search); its ray-tracer form is 6 blocks, 12 cylinders and 8 tridiscspheres (the
// convex hulls of the tricircle-spheres at the block's corners, Appendix B), see primitives().
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

enum class PieceKind { Block, Cylinder, Sphere, Torus, Bidisc, Bicircle, DiscSum, Tridiscsphere };

// One ray-tracer primitive in the sum's local frame (see Sum): a block [lo, hi]; a cylinder
// of radius `radius` around the segment from `base` along `axis` of length `length`; a
// sphere (centre `base`, radius); a torus around `axis` through `base` (major radius `radius`,
// minor `minor`); block [lo, hi] ⊕ bidisc (disc of radius `radius` normal to `axis`, disc of
// radius `minor` normal to `axis2`; an F-rep piece, see bidisc.h); the bicircle solid of that
// bidisc centred at `base` (a ray-tracer primitive only: a POV quartic); block [lo, hi] ⊕
// xdisc(discs[0]) ⊕ ydisc(discs[1]) ⊕ zdisc(discs[2]) ⊕ ball(ball) (DiscSum, an F-rep piece:
// disc_sum_distance.h); the same discs and ball centred at `base` (Tridiscsphere, a ray-tracer
// primitive: POV mesh2).
struct Piece {
  PieceKind kind = PieceKind::Block;
  int axis = 0, axis2 = 1;
  Vec3 lo{0, 0, 0}, hi{0, 0, 0};
  Vec3 base{0, 0, 0};
  double radius = 0, length = 0, minor = 0;
  Vec3 discs{0, 0, 0};
  double ball = 0;
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

// The ray-tracer primitives of the union (Theorem 5's R1–R16): the pieces with each Bidisc
// expanded into blocks, cylinders and bicircles (4 blocks, 16 cylinders and 8 bicircles for
// block ⊕ bidisc; bicircle + 2 cylinders for a bidisc alone, §IV.B) and each DiscSum into blocks,
// cylinders and tridiscspheres (6 blocks, 12 cylinders, 8 tridiscspheres for Appendix B's B*;
// one tridiscsphere without a block). Their count is the one the job report and `frep pov` give.
std::vector<Piece> primitives(const Reduction& r);
// Whether a local point lies in one primitive (tests: the primitives' union is the sum).
bool primitiveHolds(const Piece& p, const Vec3& local);

// F-rep of the sum (inside >= 0), read at the local point R^T (X − offset) of the world
// coordinates x0, x1, x2: exact outside, 1-Lipschitz and sign-exact inside, error bound 0. Solids
// of empty interior (a segment, a disc, a rectangle) come out as minus the distance: 0 on the
// set, negative elsewhere. One closed form for a sphere and at most one disc axis (the discus's
// distance at the excess over the block), else the pieces' union (piecesUnionExpr: the bidisc gauge, or the
// DiscSum piece's convex-projection field).
Expr unionExpr(const Reduction& r);
Expr unionExpr(const Reduction& r, const std::vector<Expr>& coords);
// Max over the pieces of minus their signed distance (the union of eq. 16 as an F-rep; the same
// set and, outside, the same values as unionExpr).
Expr piecesUnionExpr(const Reduction& r, const std::vector<Expr>& coords);
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
