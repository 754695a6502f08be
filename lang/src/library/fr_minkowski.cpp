// Roerdink-Minkowski's basic set as fr* primitives (§IV.A, rotated variants eq. 17) and the
// exact Minkowski algebra path of frMinkowski / frMinkowskiSum / frMinkowskiDiff
// (frep/minkowski_algebra/, docs/language.md "The Minkowski basic set").
//
// frXLine(x, l [, c [, rot]])   segment from c to c + R·(l, 0, 0)      (Y, Z alike)
// frXDisc(x, r [, c [, rot]])   disc of radius r around c, normal R·e_x (Y, Z alike)
// frBall(x, r [, c])            solid sphere
// frBlock(x, lx, ly, lz [, c [, rot]])  block with corner c and edges R·(lx, 0, 0), ...
// c: array of 3 (default the origin), rot: array of 3 angles in radians (R = Rz·Ry·Rx).
// The field is the union of the reduction's primitives: for a segment or a disc (no interior)
// minus the distance to it, 0 exactly on it.
#include "library/fr_minkowski.h"

#include <cmath>
#include <string>

#include "frep/minkowski_algebra/reduction.h"
#include "frep/minkowski_algebra/registry.h"
#include "library/hf_util.h"

namespace frep::lang {
namespace {

using minkowski::ExactTerm;
using minkowski::Shape;
using minkowski::ShapeKind;
using minkowski::Sum;

bool identityCoords(const std::vector<Expr>& xs) {
  if (xs.size() < 3) return false;
  for (uint32_t i = 0; i < 3; ++i)
    if (!xs[i].same(Expr::x(i))) return false;
  return true;
}

std::vector<Expr> first3(const std::vector<Expr>& xs) { return {xs[0], xs[1], xs[2]}; }

// Builds, registers (when read at the plain coordinates) and returns the sum's field.
Expr exactField(const Sum& s, const std::vector<Expr>& xs) {
  minkowski::Reduction red = minkowski::reduce(s);
  if (!red.ok) throw LibraryError("internal: a basic-set sum did not reduce: " + red.reason);
  Expr f = minkowski::unionExpr(red, first3(xs));
  if (identityCoords(xs)) {
    ExactTerm t;
    t.sum = s;
    t.pieces = static_cast<int>(minkowski::primitives(red).size());
    minkowski::registerExact(f, t);
  }
  return f;
}

double constNumber(const char* fn, std::vector<Arg>& a, int i, const char* what) {
  double v = hf::constArg(fn, a, i, what);
  if (!std::isfinite(v)) throw LibraryError(std::string(fn) + ": " + what + " must be finite", i);
  return v;
}

// Optional trailing arrays: the placement c (3 constants) and the rotation (3 angles).
void placement(const char* fn, std::vector<Arg>& a, size_t first, Shape& s, bool rotatable) {
  const size_t maxArgs = first + (rotatable ? 2 : 1);
  if (a.size() > maxArgs)
    throw LibraryError(std::string(fn) + " takes at most " + std::to_string(maxArgs) + " arguments (got " +
                       std::to_string(a.size()) + ")");
  for (size_t k = first; k < a.size(); ++k) {
    const int i = static_cast<int>(k);
    const char* what = k == first ? "the placement c" : "the rotation [rx, ry, rz]";
    if (!a[k].isArray || !a[k].array)
      throw LibraryError(std::string(fn) + ": argument " + std::to_string(i + 1) + " (" + what +
                             ") must be an array of 3 constants",
                         i);
    const std::vector<Expr>& v = hf::arrayExactly(fn, a, i, 3, std::string(" (") + what + ")");
    double d[3];
    for (int j = 0; j < 3; ++j) {
      if (!v[j].isConst() || !std::isfinite(v[j].constValue()))
        throw LibraryError(std::string(fn) + ": " + a[k].name + "[" + std::to_string(j + 1) +
                               "] must be a finite constant known at compile time (" + what + ")",
                           i);
      d[j] = v[j].constValue();
    }
    if (k == first)
      s.pos = {d[0], d[1], d[2]};
    else
      s.rot = minkowski::rotationXYZ(d[0], d[1], d[2]);
  }
}

std::vector<Expr>& coords(const char* fn, std::vector<Arg>& a) {
  return hf::arrayAtLeast(fn, a, 0, 3, "x");
}

LibraryFunction lineOrDisc(const char* name, ShapeKind kind, int axis, const char* summary) {
  return {name, "*", summary, [name, kind, axis](std::vector<Arg>& a) {
            if (a.size() < 2) throw LibraryError(std::string(name) + " takes (x, size [, c [, rot]])");
            std::vector<Expr>& xs = coords(name, a);
            Shape s;
            s.kind = kind;
            s.axis = axis;
            s.size[0] = constNumber(name, a, 1, kind == ShapeKind::Disc ? "the radius" : "the length");
            if (kind == ShapeKind::Disc && s.size[0] < 0)
              throw LibraryError(std::string(name) + ": the radius must be >= 0", 1);
            placement(name, a, 2, s, true);
            return exactField(minkowski::sumOf(s), xs);
          }};
}

Expr frBall(std::vector<Arg>& a) {
  const char* fn = "frBall";
  if (a.size() < 2) throw LibraryError("frBall takes (x, r [, c])");
  std::vector<Expr>& xs = coords(fn, a);
  Shape s;
  s.kind = ShapeKind::Sphere;
  s.size[0] = constNumber(fn, a, 1, "the radius");
  if (s.size[0] < 0) throw LibraryError("frBall: the radius must be >= 0", 1);
  placement(fn, a, 2, s, false);
  return exactField(minkowski::sumOf(s), xs);
}

Expr frBlock(std::vector<Arg>& a) {
  const char* fn = "frBlock";
  if (a.size() < 4) throw LibraryError("frBlock takes (x, lx, ly, lz [, c [, rot]])");
  std::vector<Expr>& xs = coords(fn, a);
  Shape s;
  s.kind = ShapeKind::Block;
  const char* names[3] = {"lx", "ly", "lz"};
  for (int i = 0; i < 3; ++i) s.size[i] = constNumber(fn, a, 1 + i, names[i]);
  placement(fn, a, 4, s, true);
  return exactField(minkowski::sumOf(s), xs);
}

const bool registered = registerAll({
    lineOrDisc("frXLine", ShapeKind::Segment, 0, "segment from c to c + R (l, 0, 0): minus the distance (0 on it)"),
    lineOrDisc("frYLine", ShapeKind::Segment, 1, "segment from c to c + R (0, l, 0): minus the distance (0 on it)"),
    lineOrDisc("frZLine", ShapeKind::Segment, 2, "segment from c to c + R (0, 0, l): minus the distance (0 on it)"),
    lineOrDisc("frXDisc", ShapeKind::Disc, 0, "disc of radius r around c, normal R e_x: minus the distance (0 on it)"),
    lineOrDisc("frYDisc", ShapeKind::Disc, 1, "disc of radius r around c, normal R e_y: minus the distance (0 on it)"),
    lineOrDisc("frZDisc", ShapeKind::Disc, 2, "disc of radius r around c, normal R e_z: minus the distance (0 on it)"),
    {"frBall", "*", "solid sphere of radius r around c (minus the signed distance)", frBall},
    {"frBlock", "*", "block with corner c and edges R (lx, ly, lz) (minus the signed distance)", frBlock},
});

}  // namespace

Expr registerHyperFunShape(const Expr& field, const std::vector<Expr>& xs, bool block,
                           const std::vector<Expr>& place, const std::vector<Expr>& size) {
  if (!identityCoords(xs) || place.size() < 3) return field;
  Shape s;
  s.kind = block ? ShapeKind::Block : ShapeKind::Sphere;
  for (int i = 0; i < 3; ++i) {
    if (!place[size_t(i)].isConst() || !std::isfinite(place[size_t(i)].constValue())) return field;
    s.pos[size_t(i)] = place[size_t(i)].constValue();
  }
  for (size_t i = 0; i < size.size() && i < 3; ++i) {
    // A block of zero edge or a ball of radius 0 is a flat or empty set: left to the search.
    if (!size[i].isConst() || !(size[i].constValue() > 0) || !std::isfinite(size[i].constValue())) return field;
    s.size[i] = size[i].constValue();
  }
  Sum sum = minkowski::sumOf(s);
  if (!minkowski::reduce(sum).ok) return field;
  ExactTerm t;
  t.sum = sum;
  t.pieces = 1;
  minkowski::registerExact(field, t);
  return field;
}

Expr registerDistanceTwin(const Expr& field, const std::vector<Expr>& xs, const Expr& twin, const std::string& what) {
  if (!identityCoords(xs)) return field;
  ExactTerm t;
  t.kind = ExactTerm::Kind::Distance;
  t.twin = twin;
  t.operand = what;
  t.exactOutside = t.exactInside = true;
  minkowski::registerExact(field, t);
  return field;
}

bool exactMinkowskiSum(const std::vector<const Arg*>& operands, const std::vector<Expr>& xs, Expr* out) {
  if (xs.size() < 3) return false;
  Sum total;
  for (const Arg* op : operands) {
    if (op->objectDims != 3) return false;
    std::optional<ExactTerm> t = minkowski::lookupExact(op->value);
    if (!t || t->kind != ExactTerm::Kind::Sum) return false;
    if (!total.add(t->sum)) return false;
  }
  if (!minkowski::reduce(total).ok) return false;
  *out = exactField(total, xs);
  return true;
}

bool exactMinkowskiMorph(const Arg& A, const Arg& B, double t, const std::vector<Expr>& xs, Expr* out) {
  if (xs.size() < 3 || A.objectDims != 3 || B.objectDims != 3 || !(t > 0 && t < 1)) return false;
  std::optional<ExactTerm> ta = minkowski::lookupExact(A.value), tb = minkowski::lookupExact(B.value);
  if (!ta || !tb || ta->kind != ExactTerm::Kind::Sum || tb->kind != ExactTerm::Kind::Sum) return false;
  // (1 - t) A ⊕ t B (Pasko-Minkowski eq. 4.5): a basic-set sum scaled about the origin by s
  // has its position, edges, discs and ball scaled by s (each member's support function is).
  auto scaled = [](Sum s, double k) {
    for (int i = 0; i < 3; ++i) s.offset[size_t(i)] *= k, s.lengths[size_t(i)] *= k, s.disc[size_t(i)] *= k;
    s.ball *= k;
    return s;
  };
  Sum total = scaled(ta->sum, 1 - t);
  if (!total.add(scaled(tb->sum, t)) || !minkowski::reduce(total).ok) return false;
  *out = exactField(total, xs);
  return true;
}

bool exactMinkowskiDiff(const Arg& A, const Arg& B, const std::vector<Expr>& xs, Expr* out) {
  if (xs.size() < 3 || A.objectDims != 3 || B.objectDims != 3) return false;
  std::optional<ExactTerm> ta = minkowski::lookupExact(A.value), tb = minkowski::lookupExact(B.value);
  if (!ta || !tb || tb->kind != ExactTerm::Kind::Sum) return false;
  if (ta->kind != ExactTerm::Kind::Sum && ta->kind != ExactTerm::Kind::Erosion) return false;
  ExactTerm t;
  t.kind = ExactTerm::Kind::Erosion;
  if (ta->kind == ExactTerm::Kind::Sum) {
    t.c0 = ta->sum;
    t.sum = tb->sum;
  } else {  // (C0 ⊖ S) ⊖ B = C0 ⊖ (S ⊕ B), eq. 5
    t.c0 = ta->c0;
    t.sum = ta->sum;
    if (!t.sum.add(tb->sum)) return false;
  }
  minkowski::Reduction red = minkowski::reduce(t.sum);
  if (!red.ok) return false;
  Expr f;
  if (!minkowski::erosionExpr(t.c0, red, first3(xs), &f, nullptr)) return false;
  const bool ball = t.c0.ball > 0;
  t.pieces = ball ? static_cast<int>(red.pieces.size()) : 3;
  if (identityCoords(xs)) minkowski::registerExact(f, t);
  *out = f;
  return true;
}

}  // namespace frep::lang
