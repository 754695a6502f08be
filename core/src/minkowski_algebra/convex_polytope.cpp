// Intersections of half-spaces as convex polytopes (convex_polytope.h).
#include "frep/minkowski_algebra/convex_polytope.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <optional>
#include <vector>

#include "frep/expressions/min_max_form.h"
#include "frep/geometry/distance_fields.h"
#include "frep/minkowski_algebra/registry.h"

namespace frep::minkowski {
namespace {

using Affine = std::array<double, 4>;  // a x + b y + c z + d

// The coefficients of e when it is affine in x[0..2] (constants, coordinates, sums,
// differences, negation, products and quotients with a constant).
bool affineOf(const Expr& e, Affine& out) {
  out = {0, 0, 0, 0};
  switch (e.op()) {
    case Op::Const:
      out[3] = e.constValue();
      return std::isfinite(out[3]);
    case Op::Var:
      if (e.node().index > 2) return false;
      out[e.node().index] = 1;
      return true;
    case Op::Neg: {
      if (!affineOf(e.arg(0), out)) return false;
      for (double& c : out) c = -c;
      return true;
    }
    case Op::Add:
    case Op::Sub: {
      Affine b;
      if (!affineOf(e.arg(0), out) || !affineOf(e.arg(1), b)) return false;
      for (int i = 0; i < 4; ++i) out[size_t(i)] += (e.op() == Op::Add ? 1 : -1) * b[size_t(i)];
      return true;
    }
    case Op::Mul: {
      const bool firstConst = e.arg(0).isConst();
      if (!firstConst && !e.arg(1).isConst()) return false;
      const double k = (firstConst ? e.arg(0) : e.arg(1)).constValue();
      if (!affineOf(firstConst ? e.arg(1) : e.arg(0), out)) return false;
      for (double& c : out) c *= k;
      return std::isfinite(k);
    }
    case Op::Div: {
      if (!e.arg(1).isConst() || !(std::abs(e.arg(1).constValue()) > 0)) return false;
      if (!affineOf(e.arg(0), out)) return false;
      for (double& c : out) c /= e.arg(1).constValue();
      return true;
    }
    default:
      return false;
  }
}

// The half-spaces n . X + d >= 0 of a min of affine functions, normals scaled to unit length.
bool halfSpaces(const Expr& e, std::vector<Affine>& planes) {
  if (e.op() == Op::Min) return halfSpaces(e.arg(0), planes) && halfSpaces(e.arg(1), planes);
  Affine a;
  if (!affineOf(e, a)) return false;
  const double len = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
  if (!(len > 0)) return false;  // a constant: the whole space or nothing, not a polytope
  for (double& c : a) c /= len;
  planes.push_back(a);
  return planes.size() <= 64;
}

bool solve3(const Affine& p, const Affine& q, const Affine& r, std::array<double, 3>& x) {
  const double det =
      p[0] * (q[1] * r[2] - q[2] * r[1]) - p[1] * (q[0] * r[2] - q[2] * r[0]) + p[2] * (q[0] * r[1] - q[1] * r[0]);
  if (std::abs(det) < 1e-12) return false;
  const double b[3] = {-p[3], -q[3], -r[3]};
  x[0] =
      (b[0] * (q[1] * r[2] - q[2] * r[1]) - p[1] * (b[1] * r[2] - q[2] * b[2]) + p[2] * (b[1] * r[1] - q[1] * b[2])) /
      det;
  x[1] =
      (p[0] * (b[1] * r[2] - q[2] * b[2]) - b[0] * (q[0] * r[2] - q[2] * r[0]) + p[2] * (q[0] * b[2] - b[1] * r[0])) /
      det;
  x[2] =
      (p[0] * (q[1] * b[2] - b[1] * r[1]) - p[1] * (q[0] * b[2] - b[1] * r[0]) + b[0] * (q[0] * r[1] - q[1] * r[0])) /
      det;
  return std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]);
}

double eval(const Affine& a, const std::array<double, 3>& x) { return a[0] * x[0] + a[1] * x[1] + a[2] * x[2] + a[3]; }

using Point = std::array<double, 3>;

// The vertices of the intersection of `planes`: feasible intersections of three planes, merged
// within `tol`.
std::vector<Point> verticesOf(const std::vector<Affine>& planes, double tol) {
  std::vector<Point> verts;
  for (size_t i = 0; i < planes.size(); ++i)
    for (size_t j = i + 1; j < planes.size(); ++j)
      for (size_t k = j + 1; k < planes.size(); ++k) {
        Point x;
        if (!solve3(planes[i], planes[j], planes[k], x)) continue;
        bool feasible = true;
        for (const Affine& p : planes) feasible = feasible && eval(p, x) >= -tol;
        if (!feasible) continue;
        bool known = false;
        for (const auto& v : verts)
          known =
              known || (std::abs(v[0] - x[0]) <= tol && std::abs(v[1] - x[1]) <= tol && std::abs(v[2] - x[2]) <= tol);
        if (!known) verts.push_back(x);
      }
  return verts;
}

// The merge tolerance of a set of planes: relative to their largest offset.
double toleranceOf(const std::vector<Affine>& planes) {
  double scale = 1;
  for (const Affine& p : planes) scale = std::max(scale, std::abs(p[3]));
  return 1e-9 * scale;
}

// a . X + d as an expression, zero coefficients left out.
Expr affineExpr(const Affine& a) {
  std::optional<Expr> e;
  for (uint32_t i = 0; i < 3; ++i) {
    if (a[i] == 0) continue;
    const Expr t = a[i] == 1 ? Expr::x(i) : Expr(a[i]) * Expr::x(i);
    e = e ? *e + t : t;
  }
  return e ? (a[3] == 0 ? *e : *e + Expr(a[3])) : Expr(a[3]);
}

// A facet: its plane (inside n . X + d >= 0, unit n) and its vertices in order around it.
struct Facet {
  Affine plane;
  std::vector<uint32_t> ring;
};

// The polytope's exact signed distance in closed form, with min, max, sqrt and arithmetic alone:
// interval pruning then keeps a box's few nearest features and the float sign checks apply
// (a mesh distance node allows neither). With P_f the facets' plane distances and m = min_f P_f:
//  - inside, m is the exact distance to the boundary (the nearest facet plane's foot lies on it);
//  - dist^2, the squared distance to the boundary on either side, is the min over candidates
//    each at least it and equal to it for the nearest
//    feature: for each edge its segment's squared distance, for each facet
//    P_f^2 + K_f max(0, -inFace_f)^2, where inFace_f is the least signed distance of X's foot
//    to the facet's edge lines (>= 0 iff the foot lies in the facet: then the term is the
//    squared distance to the facet) and K_f = 1 / sin^2(theta_f / 2), theta_f its least
//    interior angle, so that K_f inFace_f^2 bounds the squared in-plane distance to the facet
//    (at a corner of angle theta the edge lines are at least sin(theta / 2) of it);
//  - so sqrt(dist^2) is the distance to the boundary on both sides, and 2 max(m, 0) - sqrt(dist^2)
//    the signed distance (m inside, -dist outside) with no factor that would inflate the float
//    error bound (the sign is m's but within rounding of the boundary).
Expr closedFormDistance(const std::vector<Facet>& facets, const std::vector<Point>& verts) {
  auto sub3 = [](const Point& a, const Point& b) { return Point{a[0] - b[0], a[1] - b[1], a[2] - b[2]}; };
  auto dot3 = [](const Point& a, const Point& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
  auto cross3 = [](const Point& a, const Point& b) {
    return Point{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
  };
  std::optional<Expr> m, d2;
  auto least = [](std::optional<Expr>& acc, const Expr& e) { acc = acc ? min(*acc, e) : e; };
  std::vector<std::array<uint32_t, 2>> edges;
  for (const Facet& f : facets) {
    const Expr plane = affineExpr(f.plane);
    least(m, plane);
    const Point n{f.plane[0], f.plane[1], f.plane[2]};
    const size_t k = f.ring.size();
    Point c{0, 0, 0};
    for (uint32_t v : f.ring)
      for (int a = 0; a < 3; ++a) c[size_t(a)] += verts[v][size_t(a)] / double(k);
    double sinHalf = 1;  // of the least interior angle
    for (size_t j = 0; j < k; ++j) {
      const Point& p = verts[f.ring[j]];
      const Point u = sub3(verts[f.ring[(j + k - 1) % k]], p), w = sub3(verts[f.ring[(j + 1) % k]], p);
      const double cosA = std::clamp(dot3(u, w) / std::sqrt(dot3(u, u) * dot3(w, w)), -1.0, 1.0);
      sinHalf = std::min(sinHalf, std::sqrt(0.5 * (1 - cosA)));
    }
    const double scale = (1 + 1e-9) / sinHalf;
    std::optional<Expr> inFace;
    for (size_t j = 0; j < k; ++j) {
      const uint32_t a = f.ring[j], b = f.ring[(j + 1) % k];
      edges.push_back({std::min(a, b), std::max(a, b)});
      Point w = cross3(n, sub3(verts[b], verts[a]));  // in the plane, across the edge
      const double len = std::sqrt(dot3(w, w)), sign = dot3(w, sub3(c, verts[a])) < 0 ? -1 : 1;
      for (double& x : w) x *= sign * scale / len;
      least(inFace, affineExpr({w[0], w[1], w[2], -dot3(w, verts[a])}));
    }
    least(d2, square(plane) + square(max(-*inFace, Expr(0.0))));
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  for (const auto& [a, b] : edges) {
    const Point& p = verts[a];
    const Point d = sub3(verts[b], p);
    const double l2 = dot3(d, d);
    const Expr t = min(max(affineExpr({d[0] / l2, d[1] / l2, d[2] / l2, -dot3(p, d) / l2}), Expr(0.0)), Expr(1.0));
    Expr s2 = Expr(0.0);
    for (uint32_t i = 0; i < 3; ++i) {
      const Expr r = (Expr::x(i) - Expr(p[i])) - t * Expr(d[i]);
      s2 = i == 0 ? square(r) : s2 + square(r);
    }
    least(d2, s2);
  }
  return Expr(2.0) * max(*m, Expr(0.0)) - sqrt(*d2);
}

// Polytopes with more facets keep the mesh distance as their field (the closed form grows with
// the edges; a mesh query does not).
constexpr size_t kClosedFormFacets = 32;

// The closed outward mesh of the polytope with these planes and vertices, and its exact signed
// distance; nothing when the facets do not close (unbounded) or enclose no volume (flat).
std::optional<ConvexPolytope> meshOf(const std::vector<Affine>& planes, const std::vector<Point>& verts, double tol) {
  if (verts.size() < 4) return std::nullopt;
  // Facets: the vertices on each plane, ordered by angle about their centroid, fanned outward
  // (the outward normal is -n: inside is n . X + d >= 0).
  std::vector<double> xyz;
  for (const auto& v : verts) xyz.insert(xyz.end(), v.begin(), v.end());
  std::vector<uint32_t> tris;
  std::vector<Facet> facets;
  for (const Affine& p : planes) {
    std::vector<uint32_t> on;
    for (uint32_t v = 0; v < verts.size(); ++v)
      if (std::abs(eval(p, verts[v])) <= 1e3 * tol) on.push_back(v);
    if (on.size() < 3) continue;
    Point c{0, 0, 0};
    for (uint32_t v : on)
      for (int a = 0; a < 3; ++a) c[size_t(a)] += verts[v][size_t(a)] / double(on.size());
    // A basis (u, w) of the plane with u x w = -n, so counter-clockwise in it is outward.
    const Point n{p[0], p[1], p[2]};
    Point u = std::abs(n[0]) < 0.9 ? Point{0, -n[2], n[1]} : Point{n[2], 0, -n[0]};
    const double ul = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (double& x : u) x /= ul;
    const Point w{-(n[1] * u[2] - n[2] * u[1]), -(n[2] * u[0] - n[0] * u[2]), -(n[0] * u[1] - n[1] * u[0])};
    std::vector<std::pair<double, uint32_t>> ring;
    for (uint32_t v : on) {
      const double dx = verts[v][0] - c[0], dy = verts[v][1] - c[1], dz = verts[v][2] - c[2];
      ring.push_back({std::atan2(dx * w[0] + dy * w[1] + dz * w[2], dx * u[0] + dy * u[1] + dz * u[2]), v});
    }
    std::sort(ring.begin(), ring.end());
    for (size_t t = 1; t + 1 < ring.size(); ++t)
      tris.insert(tris.end(), {ring[0].second, ring[t].second, ring[t + 1].second});
    facets.push_back({p, {}});
    for (const auto& r : ring) facets.back().ring.push_back(r.second);
  }
  auto mesh = std::make_shared<MeshField>(xyz, tris, "convex polytope of " + std::to_string(facets.size()) + " facets");
  // An unbounded or flat intersection leaves open facets: not a polytope.
  if (!mesh->check().closed() || !(mesh->volume() > 0)) return std::nullopt;
  ConvexPolytope out;
  out.mesh = fieldExpr(mesh, Expr::x(0), Expr::x(1), Expr::x(2));
  out.field = out.mesh;
  if (facets.size() <= kClosedFormFacets) {
    out.field = closedFormDistance(facets, verts);
    ExactTerm t;  // its own exact distance: later operations read it as one
    t.kind = ExactTerm::Kind::Distance;
    t.twin = out.field;
    t.operand = mesh->describe();
    registerExact(out.field, t);
  }
  out.planes = planes.size();
  out.facets = facets.size();
  out.vertices = verts.size();
  out.corners = verts;
  return out;
}

// ---- unions of polytopes ----

using Term = std::vector<Affine>;  // an intersection of half-spaces (none: the whole space)
constexpr size_t kMaxTerms = 64, kMaxTermPlanes = 64;

// The disjunctive normal form of e (negated when `negated`): the union of `out`'s terms. False
// when a leaf is not affine or the form outgrows the limits.
bool normalForm(const Expr& e, bool negated, std::vector<Term>& out) {
  out.clear();
  if (e.op() == Op::Neg) return normalForm(e.arg(0), !negated, out);
  if (e.op() == Op::Min || e.op() == Op::Max) {
    std::vector<Term> a, b;
    if (!normalForm(e.arg(0), negated, a) || !normalForm(e.arg(1), negated, b)) return false;
    if ((e.op() == Op::Min) != negated) {  // an intersection: every pair of terms
      if (a.size() * b.size() > kMaxTerms) return false;
      for (const Term& s : a)
        for (const Term& t : b) {
          if (s.size() + t.size() > kMaxTermPlanes) return false;
          out.push_back(s);
          out.back().insert(out.back().end(), t.begin(), t.end());
        }
      return true;
    }
    if (a.size() + b.size() > kMaxTerms) return false;
    out = std::move(a);
    out.insert(out.end(), b.begin(), b.end());
    return true;
  }
  Affine a;
  if (!affineOf(e, a)) return false;
  if (negated)
    for (double& c : a) c = -c;
  const double len = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
  if (!(len > 0)) {  // a constant: the whole space or nothing
    if (a[3] >= 0) out.push_back({});
    return true;
  }
  for (double& c : a) c /= len;
  out.push_back({a});
  return true;
}

enum class Extent { Bounded, Empty, Unbounded };

// A term whose normals all lie along the axes: the box [lo, hi], empty when flat.
Extent boxOf(const Term& t, Point& lo, Point& hi) {
  lo.fill(-INFINITY);
  hi.fill(INFINITY);
  for (const Affine& p : t) {
    const int axis = p[0] != 0 ? 0 : p[1] != 0 ? 1 : 2;
    if (p[axis] > 0) lo[size_t(axis)] = std::max(lo[size_t(axis)], -p[3] / p[axis]);
    else hi[size_t(axis)] = std::min(hi[size_t(axis)], -p[3] / p[axis]);
  }
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(lo[size_t(a)]) || !std::isfinite(hi[size_t(a)])) return Extent::Unbounded;
  for (int a = 0; a < 3; ++a)
    if (!(lo[size_t(a)] < hi[size_t(a)])) return Extent::Empty;
  return Extent::Bounded;
}

bool axisAligned(const Term& t) {
  for (const Affine& p : t)
    if (int(p[0] != 0) + int(p[1] != 0) + int(p[2] != 0) != 1) return false;
  return true;
}

// The exact signed distance of the box [lo, hi] (positive inside), some bounds possibly
// infinite (an unbounded box: a half-space, a quadrant, a slab): with q_a the signed distance
// outside the interval of axis a (|x - c| - h when both bounds are finite), -(|max(q, 0)| +
// min(max_a q_a, 0)) over the bounded axes. Nothing when no axis is bounded (the whole space).
std::optional<Expr> boxDistance(const Point& lo, const Point& hi) {
  std::vector<Expr> q;
  for (int a = 0; a < 3; ++a) {
    const Expr x = Expr::x(uint32_t(a));
    const double l = lo[size_t(a)], h = hi[size_t(a)];
    if (std::isfinite(l) && std::isfinite(h)) q.push_back(abs(x - Expr(0.5 * (l + h))) - Expr(0.5 * (h - l)));
    else if (std::isfinite(l)) q.push_back(Expr(l) - x);
    else if (std::isfinite(h)) q.push_back(x - Expr(h));
  }
  if (q.empty()) return std::nullopt;
  Expr outside2 = square(max(q[0], Expr(0.0))), deepest = q[0];
  for (size_t a = 1; a < q.size(); ++a) {
    outside2 = outside2 + square(max(q[a], Expr(0.0)));
    deepest = a == 1 ? max(q[0], q[1]) : max(q[0], max(q[1], q[2]));
  }
  return -(sqrt(outside2) + min(deepest, Expr(0.0)));
}

// A general term as a polytope. Bounded when no vertex of it clipped by a far box lies on that
// box; an unbounded one is kept clipped when `clip` (the far box, 10^6 times the planes'
// offsets away, is never the nearest feature to a point of the model's region).
Extent polytopeOfTerm(const Term& t, bool clip, std::optional<ConvexPolytope>& out) {
  const double tol = toleranceOf(t);
  const double far = 1e6 * (tol / 1e-9);
  Term clipped = t;
  for (int a = 0; a < 3; ++a)
    for (double s : {1.0, -1.0}) {
      Affine p{0, 0, 0, far};
      p[size_t(a)] = s;
      clipped.push_back(p);
    }
  const std::vector<Point> verts = verticesOf(clipped, tol);
  bool bounded = true;
  for (const Point& v : verts)
    for (double c : v) bounded = bounded && std::abs(c) < far * (1 - 1e-9);
  if (!bounded && !clip) return Extent::Unbounded;
  out = meshOf(bounded ? t : clipped, verts, tol);
  return out ? (bounded ? Extent::Bounded : Extent::Unbounded) : Extent::Empty;
}

// The union of the normal form's terms as one field: max of their exact signed distances.
// `clip`: unbounded terms are kept (clipped far away) instead of refusing the form.
std::optional<PolytopeUnion> unionOfTerms(const std::vector<Term>& terms, bool clip) {
  PolytopeUnion u;
  for (const Term& t : terms) {
    std::optional<Expr> piece;
    if (axisAligned(t)) {
      Point lo, hi;
      const Extent x = boxOf(t, lo, hi);
      if (x == Extent::Unbounded && !clip) return std::nullopt;
      if (x == Extent::Empty) continue;
      piece = boxDistance(lo, hi);
      if (!piece) return std::nullopt;  // the whole space
      ++u.boxes;
      if (x == Extent::Bounded) {
        u.halfSpaces.push_back(t);
        u.corners.emplace_back();
        for (int k = 0; k < 8; ++k)
          u.corners.back().push_back({k & 4 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 1 ? hi[2] : lo[2]});
      }
    } else {
      std::optional<ConvexPolytope> p;
      const Extent x = polytopeOfTerm(t, clip, p);
      if (x == Extent::Unbounded && !clip) return std::nullopt;
      if (x == Extent::Empty) continue;
      piece = p->field;
      if (x == Extent::Bounded) {
        u.halfSpaces.push_back(t);
        u.corners.push_back(p->corners);
      }
    }
    u.field = u.pieces++ == 0 ? *piece : max(u.field, *piece);
  }
  if (u.pieces == 0) return std::nullopt;
  return u;
}

}  // namespace

std::optional<ConvexPolytope> convexPolytopeOf(const Expr& e) {
  std::vector<Affine> planes;
  if (!halfSpaces(minMaxForm(e), planes) || planes.size() < 4) return std::nullopt;
  const double tol = toleranceOf(planes);
  return meshOf(planes, verticesOf(planes, tol), tol);
}

std::string PolytopeUnion::describe() const {
  const std::string what = std::to_string(pieces) + " convex pieces (" + std::to_string(boxes) + " of them boxes)";
  return exactInside ? "complement of a union of " + what : "union of " + what;
}

bool PolytopeUnion::connected() const {
  const size_t n = halfSpaces.size();
  if (n != pieces) return false;
  // Two convex pieces meet iff their half-spaces together have a feasible vertex (both are
  // bounded, so a non-empty intersection has one); the pieces are connected when the graph of
  // meeting pairs is.
  std::vector<size_t> root(n);
  for (size_t i = 0; i < n; ++i) root[i] = i;
  auto find = [&](size_t i) {
    while (root[i] != i) i = root[i] = root[root[i]];
    return i;
  };
  size_t components = n;
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 1; j < n; ++j) {
      if (find(i) == find(j)) continue;
      Term both = halfSpaces[i];
      both.insert(both.end(), halfSpaces[j].begin(), halfSpaces[j].end());
      if (verticesOf(both, toleranceOf(both)).empty()) continue;
      root[find(i)] = find(j);
      --components;
    }
  return components == 1;
}

std::optional<PolytopeUnion> polytopeUnionOfPieces(const std::vector<std::vector<std::array<double, 4>>>& pieces) {
  if (pieces.empty() || pieces.size() > kMaxTerms) return std::nullopt;
  for (const Term& t : pieces)
    if (t.size() > kMaxTermPlanes) return std::nullopt;
  return unionOfTerms(pieces, false);
}

std::optional<PolytopeUnion> polytopeUnionOf(const Expr& e) {
  std::vector<Term> terms;
  if (!normalForm(minMaxForm(e), false, terms)) return std::nullopt;
  return unionOfTerms(terms, false);
}

std::optional<PolytopeUnion> polytopeComplementOf(const Expr& e) {
  std::vector<Term> terms;  // -e's normal form: the complement of e's set
  if (!normalForm(minMaxForm(e), true, terms)) return std::nullopt;
  std::optional<PolytopeUnion> u = unionOfTerms(terms, true);
  if (!u) return std::nullopt;
  u->field = -u->field;
  u->exactInside = true;
  return u;
}

}  // namespace frep::minkowski
