// Closed mesh ⊕ / ⊖ convex polytope without a search (mesh_convex_sum.h).
#include "frep/minkowski_algebra/mesh_convex_sum.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "frep/geometry/distance_fields.h"
#include "frep/minkowski_algebra/convex_polytope.h"
#include "frep/minkowski_algebra/registry.h"

namespace frep::minkowski {
namespace {

using V3 = std::array<double, 3>;

V3 sub(const V3& a, const V3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
V3 add(const V3& a, const V3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
double dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
V3 cross(const V3& a, const V3& b) { return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]}; }
double norm(const V3& a) { return std::sqrt(dot(a, a)); }

// A closed triangle mesh in world coordinates.
struct Mesh {
  std::vector<V3> v;
  std::vector<std::array<uint32_t, 3>> t;
  std::string what;
};

// x_i + k, k + x_i, x_i - k or x_i: the shift k (the field reads the mesh at x + k, so the
// solid is the mesh moved by -k).
bool coordinateShift(const Expr& e, uint32_t i, double& k) {
  auto isXi = [i](const Expr& v) { return v.op() == Op::Var && v.node().index == i; };
  k = 0;
  if (isXi(e)) return true;
  if (e.op() == Op::Add && isXi(e.arg(0)) && e.arg(1).isConst()) return k = e.arg(1).constValue(), true;
  if (e.op() == Op::Add && e.arg(0).isConst() && isXi(e.arg(1))) return k = e.arg(0).constValue(), true;
  if (e.op() == Op::Sub && isXi(e.arg(0)) && e.arg(1).isConst()) return k = -e.arg(1).constValue(), true;
  return false;
}

std::optional<Mesh> closedMeshOf(const Expr& e, bool* isPolytope) {
  *isPolytope = false;
  const Expr* field = &e;
  std::optional<ConvexPolytope> p;
  if (e.op() != Op::Field || !dynamic_cast<const MeshField*>(e.node().fn.get())) {
    p = convexPolytopeOf(e);
    if (!p) return std::nullopt;
    field = &p->field;
    *isPolytope = true;
  }
  const auto* m = dynamic_cast<const MeshField*>(field->node().fn.get());
  if (!m || !m->check().closed()) return std::nullopt;
  V3 shift{0, 0, 0};
  for (uint32_t i = 0; i < 3; ++i)
    if (!coordinateShift(field->arg(i), i, shift[i])) return std::nullopt;
  Mesh out;
  const std::vector<double>& xyz = m->vertices();
  for (size_t i = 0; i + 2 < xyz.size(); i += 3) out.v.push_back({xyz[i] - shift[0], xyz[i + 1] - shift[1], xyz[i + 2] - shift[2]});
  const std::vector<uint32_t>& tr = m->triangles();
  for (size_t i = 0; i + 2 < tr.size(); i += 3) out.t.push_back({tr[i], tr[i + 1], tr[i + 2]});
  out.what = *isPolytope ? "convex polytope (" + std::to_string(p->planes) + " planes)"
                         : m->describe() + " (" + std::to_string(out.t.size()) + " triangles)";
  return out;
}

// B as the convex polytope of a closed mesh: vertices, outward facet planes, edge directions.
struct Convex {
  std::vector<V3> v;
  std::vector<std::array<V3, 3>> faces;  // triangles
  std::vector<V3> faceN;                 // unit outward normals
  std::vector<std::array<uint32_t, 2>> edges;  // unique edges between non-coplanar faces
  double support(const V3& u) const {
    double h = -INFINITY;
    for (const V3& p : v) h = std::max(h, dot(u, p));
    return h;
  }
};

double extentOf(const std::vector<V3>& pts) {
  double s = 0;
  for (const V3& p : pts) s = std::max({s, std::abs(p[0]), std::abs(p[1]), std::abs(p[2])});
  return std::max(s, 1e-300);
}

// The mesh as a convex body, or nothing when some vertex lies outside a face's plane.
std::optional<Convex> convexOf(const Mesh& m, double scale) {
  Convex c;
  c.v = m.v;
  const double tol = 1e-9 * scale;
  std::map<std::pair<uint32_t, uint32_t>, std::vector<size_t>> edgeFaces;
  for (const auto& t : m.t) {
    const V3 n0 = cross(sub(m.v[t[1]], m.v[t[0]]), sub(m.v[t[2]], m.v[t[0]]));
    const double len = norm(n0);
    if (!(len > 0)) continue;  // a degenerate triangle bounds nothing
    const V3 n{n0[0] / len, n0[1] / len, n0[2] / len};
    const double h = dot(n, m.v[t[0]]);
    for (const V3& p : m.v)
      if (dot(n, p) > h + tol) return std::nullopt;
    c.faces.push_back({m.v[t[0]], m.v[t[1]], m.v[t[2]]});
    c.faceN.push_back(n);
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = t[size_t(k)], b = t[size_t((k + 1) % 3)];
      edgeFaces[{std::min(a, b), std::max(a, b)}].push_back(c.faces.size() - 1);
    }
  }
  for (const auto& [e, fs] : edgeFaces) {
    bool crease = fs.size() != 2;
    if (!crease) crease = dot(c.faceN[fs[0]], c.faceN[fs[1]]) < 1 - 1e-12;
    if (crease) c.edges.push_back({e.first, e.second});
  }
  if (c.faces.size() < 4) return std::nullopt;
  return c;
}

// See mesh_convex_sum.h. complement: the field of A^c ⊕ B (for the difference, B = -B).
class MeshConvexSumField : public DistanceField {
 public:
  MeshConvexSumField(const Mesh& a, std::shared_ptr<const MeshField> aField, const Convex& b, bool complement,
                     std::string name)
      : a_(std::move(aField)), complement_(complement), name_(std::move(name)) {
    b0_ = b.v[0];
    double scale = std::max(extentOf(a.v), extentOf(b.v));
    const double tol = 1e-9 * scale;
    // Edge directions of B, one per parallel class.
    std::vector<V3> bDirs;
    for (const auto& e : b.edges) {
      V3 d = sub(b.v[e[1]], b.v[e[0]]);
      const double l = norm(d);
      if (!(l > 0)) continue;
      for (double& x : d) x /= l;
      bool known = false;
      for (const V3& k : bDirs) known = known || std::abs(dot(k, d)) > 1 - 1e-12;
      if (!known) bDirs.push_back(d);
    }
    std::vector<double> soup;
    std::vector<uint32_t> soupTris;
    auto tri = [&](const V3& p, const V3& q, const V3& r) {
      const uint32_t base = uint32_t(soup.size() / 3);
      for (const V3* x : {&p, &q, &r}) soup.insert(soup.end(), x->begin(), x->end());
      soupTris.insert(soupTris.end(), {base, base + 1, base + 2});
    };
    std::vector<Bvh::Box> boxes;
    std::vector<V3> bLo(1, {INFINITY, INFINITY, INFINITY}), bHi(1, {-INFINITY, -INFINITY, -INFINITY});
    for (const V3& p : b.v)
      for (int k = 0; k < 3; ++k) bLo[0][size_t(k)] = std::min(bLo[0][size_t(k)], p[size_t(k)]), bHi[0][size_t(k)] = std::max(bHi[0][size_t(k)], p[size_t(k)]);
    for (const auto& t : a.t) {
      const V3 tv[3] = {a.v[t[0]], a.v[t[1]], a.v[t[2]]};
      auto hT = [&](const V3& u) { return std::max({dot(u, tv[0]), dot(u, tv[1]), dot(u, tv[2])}); };
      const uint32_t first = uint32_t(planes_.size());
      auto plane = [&](const V3& u) { planes_.push_back({u[0], u[1], u[2], hT(u) + b.support(u)}); };
      V3 n = cross(sub(tv[1], tv[0]), sub(tv[2], tv[0]));
      const double nl = norm(n);
      if (nl > 0) {
        for (double& x : n) x /= nl;
        for (double s : {1.0, -1.0}) {
          const V3 u{s * n[0], s * n[1], s * n[2]};
          plane(u);
          const double h = b.support(u);
          for (const V3& p : b.v)  // T + the face of B in direction u (every tied vertex)
            if (dot(u, p) >= h - tol) tri(add(tv[0], p), add(tv[1], p), add(tv[2], p));
        }
      }
      for (size_t f = 0; f < b.faces.size(); ++f) {
        const V3& u = b.faceN[f];
        plane(u);
        const double h = hT(u);
        for (const V3& p : tv)
          if (dot(u, p) >= h - tol) tri(add(b.faces[f][0], p), add(b.faces[f][1], p), add(b.faces[f][2], p));
      }
      for (int k = 0; k < 3; ++k) {
        const V3 &p0 = tv[k], &p1 = tv[(k + 1) % 3];
        const V3 eT = sub(p1, p0);
        for (const V3& d : bDirs) {
          V3 u = cross(eT, d);
          const double l = norm(u);
          if (!(l > 1e-12 * norm(eT))) continue;  // parallel: the sum of the edges is a segment
          for (double& x : u) x /= l;
          for (double s : {1.0, -1.0}) {
            const V3 us{s * u[0], s * u[1], s * u[2]};
            plane(us);
            const double h = hT(us);
            if (dot(us, p0) < h - tol || dot(us, p1) < h - tol) continue;
            const double hb = b.support(us);
            for (const auto& e : b.edges) {  // the parallelograms edge ⊕ edge of the face in direction us
              const V3 &q0 = b.v[e[0]], &q1 = b.v[e[1]];
              if (dot(us, q0) < hb - tol || dot(us, q1) < hb - tol) continue;
              tri(add(p0, q0), add(p1, q0), add(p1, q1));
              tri(add(p0, q0), add(p1, q1), add(p0, q1));
            }
          }
        }
      }
      cells_.push_back({first, uint32_t(planes_.size()) - first});
      Bvh::Box box;
      for (int k = 0; k < 3; ++k) {
        box.lo[k] = std::min({tv[0][size_t(k)], tv[1][size_t(k)], tv[2][size_t(k)]}) + bLo[0][size_t(k)] - tol;
        box.hi[k] = std::max({tv[0][size_t(k)], tv[1][size_t(k)], tv[2][size_t(k)]}) + bHi[0][size_t(k)] + tol;
      }
      boxes.push_back(box);
    }
    cellBvh_.build(boxes);
    pieces_ = soupTris.size() / 3;
    soup_ = std::make_shared<MeshField>(std::move(soup), std::move(soupTris), "boundary pieces");
    uint64_t h = a_->contentHash() ^ (complement_ ? 0x9e3779b97f4a7c15ULL : 0);
    for (const V3& p : b.v)
      for (double d : p) {
        uint64_t bits;
        std::memcpy(&bits, &d, sizeof bits);
        h = (h ^ bits) * 0x100000001b3ULL;
      }
    hash_ = h;
  }

  double value(const double p[3]) const override {
    const double f = sumField(p, nullptr);
    return complement_ ? -f : f;
  }
  double gradient(const double p[3], double g[3]) const override {
    double q[3];
    const double f = sumField(p, q);
    if (f < 0) {  // outside the sum: the exact distance's gradient from the nearest point
      gradientFromNearest(f, p, q, g);
      if (complement_) g[0] = -g[0], g[1] = -g[1], g[2] = -g[2];
      return complement_ ? -f : f;
    }
    return DistanceField::gradient(p, g);
  }
  uint64_t contentHash() const override { return hash_; }
  std::string describe() const override { return name_; }
  bool exactOutside() const override { return !complement_; }
  bool exactInside() const override { return complement_; }
  size_t pieces() const { return pieces_; }

 private:
  std::shared_ptr<const MeshField> a_;
  bool complement_;
  std::string name_;
  V3 b0_{};
  std::vector<std::array<double, 4>> planes_;  // u . x <= h
  struct Cell {
    uint32_t first, count;
  };
  std::vector<Cell> cells_;
  Bvh cellBvh_;
  std::shared_ptr<const MeshField> soup_;
  size_t pieces_ = 0;
  uint64_t hash_ = 0;

  // The field of (A or A^c) ⊕ B, q the nearest boundary point where it is negative.
  double sumField(const double* p, double* q) const {
    const double shifted[3] = {p[0] - b0_[0], p[1] - b0_[1], p[2] - b0_[2]};
    double g = a_->value(shifted);
    if (complement_) g = -g;
    cellBvh_.containing(p, [&](uint32_t i) {
      const Cell& c = cells_[i];
      double m = INFINITY;
      for (uint32_t k = c.first; k < c.first + c.count && m > g; ++k) {
        const auto& u = planes_[k];
        m = std::min(m, u[3] - (u[0] * p[0] + u[1] * p[1] + u[2] * p[2]));
      }
      g = std::max(g, m);
    });
    if (g >= 0) return g;
    return -soup_->distance(p, q);
  }
  bool sameGeometry(const DistanceField& o) const override {
    const auto& m = static_cast<const MeshConvexSumField&>(o);
    return m.complement_ == complement_ && m.planes_ == planes_ && m.a_->sameContent(*a_);
  }
};

bool build(const Expr& aExpr, const Expr& bExpr, bool difference, Expr* out) {
  bool aPoly = false, bPoly = false;
  std::optional<Mesh> b = closedMeshOf(bExpr, &bPoly);
  if (!b) return false;
  std::optional<Mesh> a = closedMeshOf(aExpr, &aPoly);
  if (!a) return false;
  std::optional<Convex> cb = convexOf(*b, std::max(extentOf(a->v), extentOf(b->v)));
  if (!cb) return false;
  if (difference)
    for (V3& p : cb->v) p = {-p[0], -p[1], -p[2]};
  if (difference) {
    for (auto& f : cb->faces)
      for (V3& p : f) p = {-p[0], -p[1], -p[2]};
    for (V3& n : cb->faceN) n = {-n[0], -n[1], -n[2]};
  }
  std::vector<double> xyz;
  for (const V3& p : a->v) xyz.insert(xyz.end(), p.begin(), p.end());
  std::vector<uint32_t> tris;
  for (const auto& t : a->t) tris.insert(tris.end(), t.begin(), t.end());
  auto aField = std::make_shared<MeshField>(std::move(xyz), std::move(tris), a->what);
  const std::string name = a->what + (difference ? " ⊖ " : " ⊕ ") + b->what;
  auto field = std::make_shared<MeshConvexSumField>(*a, aField, *cb, difference, name);
  *out = fieldExpr(field, Expr::x(0), Expr::x(1), Expr::x(2));
  ExactTerm t;
  t.kind = ExactTerm::Kind::MeshPolytope;
  t.operand = name + " as the union of the mesh's translate and " + std::to_string(field->pieces()) +
              " boundary pieces of triangle ⊕ polytope sums";
  t.erosion = difference;
  t.exactOutside = !difference;
  t.exactInside = difference;
  registerExact(*out, t);
  return true;
}

}  // namespace

bool meshConvexSum(const Expr& a, const Expr& b, uint32_t dims, Expr* out) {
  if (dims != 3) return false;
  return build(a, b, false, out) || build(b, a, false, out);
}

bool meshConvexDifference(const Expr& a, const Expr& b, uint32_t dims, Expr* out) {
  if (dims != 3) return false;
  return build(a, b, true, out);
}

}  // namespace frep::minkowski
