// Operands of the mesh ⊕ polytope sums (mesh_operands.h).
#include "mesh_operands.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "frep/geometry/distance_fields.h"
#include "frep/minkowski_algebra/convex_polytope.h"

namespace frep::minkowski::mesh_operands {

using namespace vec3;

namespace {

// e = s x_i + k with constants s != 0 and k (translations and scalings: a morph's (1 - t) A
// reads A at x / (1 - t)); the field reads the mesh at s x + k, so the solid is (mesh - k) / s.
bool axisMap(const Expr& e, uint32_t i, double& s, double& k) {
  if (e.op() == Op::Var) return e.node().index == i ? (s = 1, k = 0, true) : false;
  double s0, k0;
  switch (e.op()) {
    case Op::Add:
    case Op::Sub: {
      const bool constFirst = e.arg(0).isConst();
      if (!constFirst && !e.arg(1).isConst()) return false;
      if (!axisMap(e.arg(constFirst ? 1 : 0), i, s0, k0)) return false;
      const double c = e.arg(constFirst ? 0 : 1).constValue();
      if (e.op() == Op::Add) s = s0, k = k0 + c;
      else if (constFirst) s = -s0, k = c - k0;
      else s = s0, k = k0 - c;
      return true;
    }
    case Op::Mul:
    case Op::Div: {
      if (!e.arg(1).isConst() && !(e.op() == Op::Mul && e.arg(0).isConst())) return false;
      const bool constFirst = e.op() == Op::Mul && e.arg(0).isConst();
      if (!axisMap(e.arg(constFirst ? 1 : 0), i, s0, k0)) return false;
      double c = e.arg(constFirst ? 0 : 1).constValue();
      if (e.op() == Op::Div) c = 1 / c;
      s = s0 * c, k = k0 * c;
      return std::isfinite(s) && std::isfinite(k) && s != 0;
    }
    default:
      return false;
  }
}

}  // namespace

std::optional<Mesh> closedMeshOf(const Expr& e, bool* isPolytope) {
  *isPolytope = false;
  const Expr* field = &e;
  std::optional<ConvexPolytope> p;
  if (e.op() != Op::Field || !dynamic_cast<const MeshField*>(e.node().fn.get())) {
    p = convexPolytopeOf(e);
    if (!p) return std::nullopt;
    field = &p->mesh;
    *isPolytope = true;
  }
  const auto* m = dynamic_cast<const MeshField*>(field->node().fn.get());
  if (!m || !m->check().closed()) return std::nullopt;
  V3 scale{1, 1, 1}, shift{0, 0, 0};
  for (uint32_t i = 0; i < 3; ++i)
    if (!axisMap(field->arg(i), i, scale[i], shift[i])) return std::nullopt;
  Mesh out;
  const std::vector<double>& xyz = m->vertices();
  for (size_t i = 0; i + 2 < xyz.size(); i += 3)
    out.v.push_back(
        {(xyz[i] - shift[0]) / scale[0], (xyz[i + 1] - shift[1]) / scale[1], (xyz[i + 2] - shift[2]) / scale[2]});
  const std::vector<uint32_t>& tr = m->triangles();
  const bool mirrored = scale[0] * scale[1] * scale[2] < 0;  // keep the triangles outward
  for (size_t i = 0; i + 2 < tr.size(); i += 3)
    out.t.push_back(mirrored ? std::array<uint32_t, 3>{tr[i], tr[i + 2], tr[i + 1]}
                             : std::array<uint32_t, 3>{tr[i], tr[i + 1], tr[i + 2]});
  out.what = *isPolytope ? "convex polytope (" + std::to_string(p->planes) + " planes)"
                         : m->describe() + " (" + std::to_string(out.t.size()) + " triangles)";
  return out;
}

double extentOf(const std::vector<V3>& pts) {
  double s = 0;
  for (const V3& p : pts) s = std::max({s, std::abs(p[0]), std::abs(p[1]), std::abs(p[2])});
  return std::max(s, 1e-300);
}

std::optional<Convex> convexOf(const Mesh& m, double scale) {
  if (m.t.size() > 4096) return std::nullopt;  // a tool, not a part: the check is quadratic
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

void scaleMesh(Mesh& m, double s) {
  if (s == 1) return;
  for (V3& p : m.v)
    for (double& x : p) x *= s;
  char buf[48];
  std::snprintf(buf, sizeof buf, "%g × ", s);
  m.what = buf + m.what;
}

}  // namespace frep::minkowski::mesh_operands
