// Sweeps by translation along a polyline (path_sweep.h).
#include "frep/minkowski_algebra/path_sweep.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>

#include "frep/geometry/distance_fields.h"
#include "frep/geometry/vec3.h"
#include "frep/minkowski_algebra/convex_cover.h"
#include "frep/minkowski_algebra/convex_polytope.h"
#include "frep/minkowski_algebra/distance_offset.h"
#include "frep/minkowski_algebra/mesh_convex_sum.h"
#include "frep/minkowski_algebra/registry.h"

namespace frep::minkowski {
namespace {

using namespace vec3;

constexpr size_t kMaxPieces = 256;

// r − dist(X − c, [p, q]): the capsule's exact signed distance (a ball where p = q).
Expr capsule(const Ball& b, const Vec3& p, const Vec3& q) {
  const Vec3 a = add(b.centre, p), d = sub(q, p);
  const double len2 = dot(d, d);
  Expr w[3], along;
  for (int i = 0; i < 3; ++i) w[i] = Expr::x(uint32_t(i)) - Expr(a[size_t(i)]);
  if (len2 > 0) {
    const Expr s = (w[0] * Expr(d[0]) + w[1] * Expr(d[1]) + w[2] * Expr(d[2])) / Expr(len2);
    along = min(max(s, Expr(0.0)), Expr(1.0));
  }
  Expr dist2;
  for (int i = 0; i < 3; ++i) {
    const Expr e = len2 > 0 ? w[i] - along * Expr(d[size_t(i)]) : w[i];
    dist2 = i == 0 ? square(e) : dist2 + square(e);
  }
  return Expr(b.radius) - sqrt(dist2);
}

// The hull of the piece at both ends of [p, q] as its exact signed distance.
std::optional<Expr> sweptPiece(const std::vector<Vec3>& corners, const Vec3& p, const Vec3& q) {
  std::vector<Vec3> pts;
  double scale = 1;
  for (const Vec3& c : corners) {
    pts.push_back(add(c, p));
    pts.push_back(add(c, q));
    for (double x : c) scale = std::max(scale, std::abs(x));
  }
  std::optional<PieceMesh> hull = convexHullMesh(pts, 1e-9 * scale);
  if (!hull) return std::nullopt;
  std::vector<double> xyz;
  std::vector<uint32_t> tris;
  for (const Vec3& v : hull->v) xyz.insert(xyz.end(), v.begin(), v.end());
  for (const auto& t : hull->t) tris.insert(tris.end(), t.begin(), t.end());
  auto mesh = std::make_shared<MeshField>(xyz, tris, "swept convex piece");
  if (!mesh->check().closed()) return std::nullopt;
  return fieldExpr(mesh, Expr::x(0), Expr::x(1), Expr::x(2));
}

std::string pointText(const Vec3& p) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%g, %g, %g)", p[0], p[1], p[2]);
  return buf;
}

}  // namespace

bool translationSweep(const Expr& a, const std::vector<Vec3>& path, Expr* out) {
  if (path.empty()) return false;
  // The segments (a single point: the operand moved there).
  std::vector<std::pair<Vec3, Vec3>> segments;
  for (size_t i = 0; i + 1 < path.size(); ++i) segments.push_back({path[i], path[i + 1]});
  if (segments.empty()) segments.push_back({path[0], path[0]});
  Expr field;
  size_t pieces = 0;
  std::string what;
  auto add = [&](const Expr& piece) { field = pieces++ == 0 ? piece : max(field, piece); };
  if (std::optional<Ball> b = ballOf(a)) {
    if (segments.size() > kMaxPieces) return false;
    for (const auto& [p, q] : segments) add(capsule(*b, p, q));
    char r[32];
    std::snprintf(r, sizeof r, "%g", b->radius);
    what = "ball(r " + std::string(r) + " at " + pointText(b->centre) + ")";
  } else {
    std::vector<std::vector<Vec3>> corners;
    if (std::optional<ConvexPolytope> k = convexPolytopeOf(a)) {
      corners.push_back(k->corners);
      what = "convex polytope of " + std::to_string(k->facets) + " facets";
    } else if (std::optional<PolytopeUnion> u = polytopeUnionOf(a)) {
      if (u->corners.size() != u->pieces) return false;
      corners = u->corners;
      what = u->describe();
    } else {
      // A closed mesh (an STL part, a non-convex tool): the sum with the path's segments
      // (mesh_convex_sum.h), registered there.
      return meshPathSum(a, path, out);
    }
    if (segments.size() * corners.size() > kMaxPieces) return false;
    for (const auto& [p, q] : segments)
      for (const auto& c : corners) {
        std::optional<Expr> piece = sweptPiece(c, p, q);
        if (!piece) return false;
        add(*piece);
      }
  }
  ExactTerm t;
  t.kind = ExactTerm::Kind::MeshPolytope;
  t.operand = "sweep of " + what + " along a path of " + std::to_string(path.size()) + " points (" +
              std::to_string(pieces) + " convex pieces)";
  t.exactOutside = true;
  registerExact(field, t);
  *out = field;
  return true;
}

bool keyframeSweep(const Expr& a, const std::vector<Expr>& positions, Expr* out) {
  if (positions.empty() || positions.size() % 3 != 0) return false;
  std::vector<Vec3> path(positions.size() / 3);
  for (size_t j = 0; j < positions.size(); ++j) {
    if (!positions[j].isConst()) return false;
    path[j / 3][j % 3] = positions[j].constValue();
  }
  return translationSweep(a, path, out);
}

}  // namespace frep::minkowski
