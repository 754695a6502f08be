// A small closed mesh read as a union of convex polytopes (convex_polytope.h): an STL box or
// L-slab then takes the closed-form distances of hfBlock models instead of the mesh node.
#include <algorithm>
#include <cmath>

#include "frep/geometry/distance_fields.h"
#include "frep/minkowski_algebra/convex_cover.h"
#include "frep/minkowski_algebra/convex_polytope.h"
#include "mesh_operands.h"

namespace frep::minkowski {
namespace {

constexpr size_t kMaxTriangles = 256, kMaxPieces = 8;

using Affine = std::array<double, 4>;

// The distinct face planes of a closed, outward, convex triangle mesh, inside n . X + d >= 0.
std::vector<Affine> facePlanes(const std::vector<Vec3>& v, const std::vector<std::array<uint32_t, 3>>& t, double tol) {
  std::vector<Affine> planes;
  for (const auto& tr : t) {
    Vec3 n = vec3::cross(vec3::sub(v[tr[1]], v[tr[0]]), vec3::sub(v[tr[2]], v[tr[0]]));
    const double len = vec3::norm(n);
    if (!(len > 0)) continue;      // a sliver: its neighbours carry the plane
    n = vec3::scale(n, -1 / len);  // inward
    const Affine p{n[0], n[1], n[2], -vec3::dot(n, v[tr[0]])};
    const bool known = std::any_of(planes.begin(), planes.end(), [&](const Affine& q) {
      return std::abs(p[0] - q[0]) <= 1e-9 && std::abs(p[1] - q[1]) <= 1e-9 && std::abs(p[2] - q[2]) <= 1e-9 &&
             std::abs(p[3] - q[3]) <= tol;
    });
    if (!known) planes.push_back(p);
  }
  return planes;
}

}  // namespace

std::optional<PolytopeUnion> polytopeUnionOfMesh(const Expr& e, std::string* what) {
  // A mesh standing for another model's set (a sampled operand) carries that model's error.
  const auto* field = e.op() == Op::Field ? dynamic_cast<const MeshField*>(e.node().fn.get()) : nullptr;
  // Sized before the world-space copy: a part of thousands of triangles is refused at once.
  if (!field || field->setErrorBound() != 0 || field->numTriangles() > kMaxTriangles) return std::nullopt;
  bool isPolytope = false;
  const std::optional<mesh_operands::Mesh> m = mesh_operands::closedMeshOf(e, &isPolytope);
  if (!m || isPolytope) return std::nullopt;
  const double scale = mesh_operands::extentOf(m->v), tol = 1e-9 * scale;
  std::vector<std::vector<Affine>> pieces;
  if (mesh_operands::convexOf(*m, scale)) {
    pieces.push_back(facePlanes(m->v, m->t, tol));
  } else {
    const std::optional<std::vector<PieceMesh>> cover = convexCover(m->v, m->t, kMaxPieces);
    if (!cover) return std::nullopt;
    for (const PieceMesh& k : *cover) pieces.push_back(facePlanes(k.v, k.t, tol));
  }
  std::optional<PolytopeUnion> u = polytopeUnionOfPieces(pieces);
  // Every piece bounded and kept (none flat): the union is the mesh's solid.
  if (!u || u->pieces != pieces.size()) return std::nullopt;
  *what = m->what;
  return u;
}

}  // namespace frep::minkowski
