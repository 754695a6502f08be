// Minkowski sum / difference of an exact signed distance and a ball as an offset
// (distance_offset.h).
#include "frep/minkowski_algebra/distance_offset.h"

#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>

#include "frep/extremum/extremum.h"
#include "frep/geometry/field.h"
#include "frep/geometry/mesh_offset_field.h"
#include "frep/minkowski_algebra/convex_polytope.h"
#include "frep/minkowski_algebra/registry.h"

namespace frep::minkowski {

std::optional<Ball> ballOf(const Expr& e) {
  std::optional<ExactTerm> t = lookupExact(e);
  if (!t || t->kind != ExactTerm::Kind::Sum) return std::nullopt;
  const Sum& s = t->sum;
  for (int i = 0; i < 3; ++i)
    if (s.lengths[i] != 0 || s.disc[i] != 0) return std::nullopt;
  return Ball{s.offset, s.ball, s};
}

namespace {

// x_i, x_i + k or x_i - k (k constant): a translation keeps a distance exact.
bool translatedCoordinate(const Expr& e, uint32_t i) {
  auto isXi = [i](const Expr& v) { return v.op() == Op::Var && v.node().index == i; };
  if (isXi(e)) return true;
  if (e.op() == Op::Add) return (isXi(e.arg(0)) && e.arg(1).isConst()) || (e.arg(0).isConst() && isXi(e.arg(1)));
  if (e.op() == Op::Sub) return isXi(e.arg(0)) && e.arg(1).isConst();
  return false;
}

struct Exactness {
  bool outside = false, inside = false;
  std::string what;
  double bound = 0;  // a sampled operand's (sampled_operand.h)
};

Exactness exactnessOf(const Expr& e) {
  if (std::optional<ExactTerm> t = lookupExact(e); t && t->kind == ExactTerm::Kind::BallOffset)
    return {t->exactOutside, t->exactInside, "(" + t->operand + ")", t->errorBound};
  if (std::optional<ExactTerm> t = lookupExact(e); t && t->kind == ExactTerm::Kind::Distance)
    return {true, true, t->operand};
  if (e.op() != Op::Field) return {};
  const auto* d = dynamic_cast<const DistanceField*>(e.node().fn.get());
  if (!d) return {};
  for (int i = 0; i < d->dims(); ++i)
    if (!translatedCoordinate(e.arg(i), static_cast<uint32_t>(i))) return {};
  return {d->exactOutside(), d->exactInside(), d->describe(), d->setErrorBound()};
}

std::string ballText(const Ball& b) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "ball(r %g at (%g, %g, %g))", b.radius, b.centre[0], b.centre[1], b.centre[2]);
  return buf;
}

// The sum by minkowskiSum's analytic shortcut (f(x - c) + r), the difference as f(x + c) - r;
// registered as a BallOffset term.
Expr offsetField(const Expr& f, const Ball& b, bool erosion, ExactTerm t) {
  std::vector<Expr> xs;  // where the operand is read: x - c for the sum, x + c for the difference
  for (uint32_t i = 0; i < 3; ++i) xs.push_back(erosion ? Expr::x(i) + Expr(b.centre[i]) : Expr::x(i) - b.centre[i]);
  Expr r;
  const auto mesh = f.op() == Op::Field ? std::dynamic_pointer_cast<const MeshField>(f.node().fn) : nullptr;
  if (mesh && mesh->check().closed() && b.radius > 0 && std::isfinite(b.radius)) {
    // A mesh's offset as one field: the same values, and inside/outside from a triangle within
    // r (mesh_offset_field.h).
    const Expr g = fieldCall(std::make_shared<MeshOffsetField>(mesh, erosion ? -b.radius : b.radius), f.arg(0),
                             f.arg(1), f.arg(2));
    r = remap(g, xs);
  } else if (!erosion) {
    MinkowskiOptions o;
    o.aIsDistance = o.bIsBall = true;
    o.ballCenter.assign(b.centre.begin(), b.centre.end());
    o.ballRadius = b.radius;
    r = minkowskiSum(f, Expr(0.0), 3, Bounds{}, o);
  } else {
    r = remap(f, xs) - Expr(b.radius);
  }
  t.kind = ExactTerm::Kind::BallOffset;
  t.sum = b.sum;
  registerExact(r, t);
  return r;
}

// An operand that is not an exact distance but has a registered distance twin (hfCylinder,
// hfTorus), or is an intersection of half-spaces, is replaced by that exact signed distance,
// a union of such intersections by one exact outside (a sum) or inside (an erosion): the same
// set, so the result's is unchanged.
Expr exactOperand(const Expr& field, bool erosion, Exactness& x) {
  if (std::optional<ExactTerm> t = lookupExact(field); t && t->kind == ExactTerm::Kind::Distance) {
    x = {true, true, t->operand};
    return t->twin;  // the same set, read as its exact distance
  }
  // A small polyhedral mesh (an STL box or L-slab) as its convex pieces: the same set and the
  // exact distance outside, in closed form (batch and float evaluation, not mesh queries).
  std::string mesh;
  if (!erosion && field.op() == Op::Field)
    if (std::optional<PolytopeUnion> u = polytopeUnionOfMesh(field, &mesh)) {
      x = {true, false, mesh + (u->pieces > 1 ? " as a " + u->describe() : u->boxes ? " as a box" : " as a polytope")};
      return u->field;
    }
  x = exactnessOf(field);
  if (x.outside && x.inside) return field;
  if (std::optional<ConvexPolytope> p = convexPolytopeOf(field)) {
    x = exactnessOf(p->field);
    return p->field;
  }
  // A union of polytopes (a difference of blocks, say) is exact outside as such, and inside
  // through its complement: the side the operation needs.
  if (std::optional<PolytopeUnion> u = erosion ? polytopeComplementOf(field) : polytopeUnionOf(field)) {
    x = {!erosion, erosion, u->describe()};
    return u->field;
  }
  return field;
}

}  // namespace

bool distanceBallSum(const Expr& a, const Expr& b, uint32_t dims, Expr* out) {
  if (dims != 3) return false;
  for (int k = 0; k < 2; ++k) {
    std::optional<Ball> ball = ballOf(k == 0 ? b : a);
    if (!ball) continue;
    Exactness x;
    const Expr field = exactOperand(k == 0 ? a : b, false, x);
    if (!x.outside) continue;
    ExactTerm t;
    t.operand = x.what + " + " + ballText(*ball);
    t.exactOutside = true;  // dist(x, A ⊕ ball) = dist(x - c, A) - r outside
    t.errorBound = x.bound;
    *out = offsetField(field, *ball, false, t);
    return true;
  }
  return false;
}

bool distanceBallDifference(const Expr& a0, const Expr& b, uint32_t dims, Expr* out) {
  if (dims != 3) return false;
  std::optional<Ball> ball = ballOf(b);
  if (!ball) return false;
  Exactness x;
  const Expr a = exactOperand(a0, true, x);
  if (!x.inside) return false;
  ExactTerm t;
  t.operand = x.what + " - " + ballText(*ball);
  t.erosion = true;
  t.exactInside = true;  // dist(x, complement of A ⊖ ball) = dist(x + c, complement of A) - r inside
  t.errorBound = x.bound;
  *out = offsetField(a, *ball, true, t);
  return true;
}

}  // namespace frep::minkowski
