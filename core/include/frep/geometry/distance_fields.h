// Signed distance fields of boundary representations (Choporov-Hybrid eq. 1-3: f = sign * dist,
// positive inside): a closed polygon in the plane and a triangle mesh in space.
//
// dist is exact (closest point on a segment / triangle, eq. 6 and its 3D analogue) and found
// through a bounding volume hierarchy (O(log n) primitives per query). The sign replaces the
// paper's parity test (eq. 7), which flips on rays through vertices or along edges:
//  - closed, consistently oriented boundaries: the angle-weighted pseudonormal of the closest
//    feature (face, edge or vertex): inside iff (p - q) . N < 0. Exact for every point whose
//    closest point is computed exactly; there is no ray, so no alignment can flip it.
//  - a mesh with open edges: the generalised winding number w(p) (sum of signed solid angles /
//    4 pi), inside iff w > 0.5. O(n) per query (docs/language.md, frMesh).
// Interval bounds: dist is 1-Lipschitz, so f over a box lies in f(centre) ± half-diagonal
// (DistanceField::bound, geometry/field.h).
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "frep/geometry/cell_lists.h"
#include "frep/geometry/field.h"

namespace frep {
namespace mesh_topology {
struct EdgeUses;  // geometry/mesh_topology.h (internal)
}

// An axis-aligned box hierarchy over primitives' boxes, for nearest-primitive queries.
class Bvh {
 public:
  struct Box {
    double lo[3], hi[3];
  };
  void build(const std::vector<Box>& boxes);
  // Calls dist2(i, best2) for candidate primitives in near-first order, pruning boxes farther
  // than the best squared distance found (or than best2's starting value, when finite: then
  // only primitives nearer than it count); returns the nearest primitive (or -1 if none).
  template <typename F>
  int64_t nearest(const double* p, F&& dist2, double& best2) const;
  // Calls visit(slot, i) for the primitives of every leaf whose box is within sqrt(bound2) of p
  // (inclusive: equal-distance primitives are all seen), near-first; visit may lower bound2.
  template <typename F>
  void nearAll(const double* p, F&& visit, double& bound2) const;
  // Calls visit(slot, i) for the primitives of every leaf whose box is within `gap` of box q
  // (a visit returning false stops).
  template <typename F>
  void nearBox(const Box& q, double gap, F&& visit) const;
  // Calls visit(i) for every primitive whose box contains p (a visit returning false stops).
  template <typename F>
  void containing(const double* p, F&& visit) const;
  size_t numNodes() const { return nodes_.size(); }
  // Primitive of each leaf slot (leaves hold consecutive slots): for data stored in slot order.
  const std::vector<uint32_t>& order() const { return order_; }
  // A lower bound of the distance between box q and every primitive: the least distance from q
  // to a leaf's box (0 when q touches one).
  double boxGap(const Box& q) const;

 private:
  struct NodeB {
    Box box;
    uint32_t first, count;  // leaf: primitives order_[first, first + count); inner: count = 0
    uint32_t left, right;
  };
  static double boxDist2(const Box& b, const double* p);
  uint32_t buildRange(const std::vector<Box>& boxes, std::vector<double>& centres, uint32_t lo, uint32_t hi);
  std::vector<NodeB> nodes_;
  std::vector<uint32_t> order_;
};

// Closed polygon (one loop) in the x-y plane; orientation is normalised to counter-clockwise.
class PolygonField : public DistanceField {
 public:
  // xy: 2 doubles per vertex; the loop closes itself (a repeated first vertex is dropped).
  // Throws std::invalid_argument for fewer than 3 distinct vertices or zero area.
  PolygonField(std::vector<double> xy, std::string name);
  double value(const double p[3]) const override;
  double gradient(const double p[3], double g[3]) const override;
  uint64_t contentHash() const override { return hash_; }
  std::string describe() const override { return name_; }
  int dims() const override { return 2; }
  // One closed loop: its edges are the boundary of the solid (for a simple polygon; the sign
  // assumes that too).
  bool exactOutside() const override { return true; }
  bool exactInside() const override { return true; }
  size_t size() const { return xy_.size() / 2; }
  double area() const { return area_; }
  const std::vector<double>& vertices() const { return xy_; }
  // Unsigned distance and closest point (qx, qy).
  double distance(double x, double y, double* q = nullptr) const;

 private:
  std::vector<double> xy_, edgeN_, vertN_;  // unit edge normals, vertex pseudonormals
  Bvh bvh_;
  double area_ = 0.0;
  uint64_t hash_ = 0;
  std::string name_;
  double signedDistance(const double* p, double* q) const;
  bool sameGeometry(const DistanceField& o) const override {
    return static_cast<const PolygonField&>(o).xy_ == xy_;
  }
};

struct MeshCheck {
  size_t openEdges = 0;         // edges used by exactly one triangle
  size_t nonManifoldEdges = 0;  // edges used by more than two
  size_t degenerateTriangles = 0;
  std::vector<std::array<uint32_t, 2>> firstOpen;  // up to 5 (vertex indices after welding)
  bool closed() const { return openEdges == 0 && nonManifoldEdges == 0; }
};

class MeshField : public DistanceField {
 public:
  // Vertices (xyz) and triangles (3 indices each, counter-clockwise seen from outside). Equal
  // vertex coordinates are welded first (STL soups). Throws std::invalid_argument for an empty
  // mesh or an index out of range.
  MeshField(std::vector<double> xyz, std::vector<uint32_t> tris, std::string name);
  double value(const double p[3]) const override;
  // A value with value(p)'s sign (0 only where value is 0): on a closed mesh, in a lattice cell
  // that no triangle meets, the class of the cell's centre (one query a cell and thread), else
  // value(p). For callers that ask only inside or outside.
  double classValue(const double p[3]) const;
  double gradient(const double p[3], double g[3]) const override;
  // The class of value(p) + level (>= 0 inside; a value of 0 may read as outside), level != 0:
  // a ball sum's (r) or difference's (-r) offset, mostly from a triangle within r rather than
  // the nearest (mesh_offset_field.h). Any other call: value(p) + level.
  double offsetClass(const double p[3], double level) const;
  uint64_t contentHash() const override { return hash_; }
  std::string describe() const override { return name_; }
  const MeshCheck& check() const { return check_; }
  // A closed (watertight, 2-manifold) mesh is the boundary of its solid, so sign * dist is its
  // signed distance; with open edges the winding-number solid's boundary is not the triangles.
  bool exactOutside() const override { return check_.closed(); }
  bool exactInside() const override { return check_.closed(); }
  size_t numTriangles() const { return tris_.size() / 3; }
  size_t numVertices() const { return xyz_.size() / 3; }
  const std::vector<double>& vertices() const { return xyz_; }
  const std::vector<uint32_t>& triangles() const { return tris_; }
  double distance(const double* p, double* q = nullptr) const;  // unsigned, closest point
  // The same when it is known to be at most `atMost` (the search prunes by it; a larger
  // bound is only slower, never wrong).
  double distance(const double* p, double* q, double atMost) const;
  // The Lipschitz bound, and on a closed mesh a box that touches no leaf box of the hierarchy
  // has one sign and |f| >= its gap to them: the bound of a box near, not on, the surface
  // then excludes 0 (the sampler keeps fewer voxels).
  Interval bound(const Interval box[3]) const override;
  double windingNumber(const double* p) const;                   // exact sum, O(n)
  double volume() const;                                          // divergence theorem
  // Tests: answer every query through the whole hierarchy (false) or through the lattice's
  // candidate cells where they apply (true, the default). The answers are the same.
  static void useCandidateCells(bool on);
  // A mesh made from a model (a sampled operand): its distance from the model's surface.
  void setSetErrorBound(double e) { setError_ = e; }
  double setErrorBound() const override { return setError_; }

 private:
  std::vector<double> xyz_;
  std::vector<uint32_t> tris_;
  std::vector<double> faceN_, vertN_, edgeN_;  // pseudonormals
  std::vector<uint32_t> triEdge_;              // 3 edge ids per triangle (edge k: v[k]-v[k+1])
  std::vector<double> corners_;                // 9 coordinates per triangle, in bvh_.order()
  std::vector<double> slotPlanes_;             // unit normal and offset per triangle, same order
  uint64_t id_ = CellLists::newOwner();        // per-thread caches' key (an address may be reused)
  uint64_t classId_ = CellLists::newOwner();   // the lists of classValue's cells
  CellLattice lattice_;                        // of the candidate cells
  double scale_ = 1;                           // the largest coordinate or extent
  struct Nearest;  // mesh_field.cpp
  void offer(const double* p, uint32_t slot, Nearest& n) const;
  void searchAll(const double* p, Nearest& n) const;
  const uint32_t* cellCandidates(const double* p, uint32_t& count, double& fromCentre, double& centreValue,
                                 double* pc) const;
  bool insideAt(const double* p, uint32_t t, int region, const double* q) const;
  double planeGap(const double* p, uint32_t slot) const;
  double setError_ = 0;
  Bvh bvh_;
  MeshCheck check_;
  uint64_t hash_ = 0;
  std::string name_;
  double signedDistance(const double* p, double* q) const;
  int64_t nearestTriangle(const double* p, double* q, int& region, double& best2, double start2 = INFINITY) const;
  void orientConsistently(const mesh_topology::EdgeUses& edges);
  bool sameGeometry(const DistanceField& o) const override {
    const auto& m = static_cast<const MeshField&>(o);
    return m.xyz_ == xyz_ && m.tris_ == tris_;
  }
};

// Choporov-Hybrid's nonuniform-curve-mesh for closed composite Bezier curves: `ctrl` holds
// arcs of `degree` + 1 control points each, consecutive arcs sharing their end point, the last
// arc ending at the first point (2 doubles per point: count = arcs * degree + 1, closed). Each
// arc starts with n uniform parameter samples; an edge whose deviation from the arc (distance
// of the arc at its parameter midpoint and quarter points from the chord) exceeds delta is
// split at the midpoint until none does. Returns the polygon's vertices (2 per point, not
// repeating the first). Throws std::invalid_argument for a bad count or a degenerate control
// polygon (all points of an arc equal).
std::vector<double> tessellateBezierLoop(const std::vector<double>& ctrl, int degree, int n, double delta);
// One point of a Bezier arc (de Casteljau), dims 2 or 3.
void bezierPoint(const double* ctrl, int degree, int dims, double t, double* out);

// Choporov-Hybrid's nonuniform-surface-mesh for a closed surface of tensor-product Bezier
// patches: `ctrl` holds patches of (du + 1) x (dv + 1) points (3 doubles each, point (i, j) at
// i * (dv + 1) + j). Every patch is cut into the same m x m parameter grid (two triangles per
// cell), m starting at n and growing until the surface deviates from every triangle by at most
// delta (checked at edge midpoints and centroids). One m for all patches keeps shared patch
// edges sampled at the same points (bit-identical: boundary curves are evaluated in a canonical
// direction), so the mesh is watertight; a per-edge split as in the paper would leave cracks
// at T-junctions between patches. Throws std::invalid_argument for a bad count or degree.
struct TriangleMesh {
  std::vector<double> xyz;
  std::vector<uint32_t> tris;
  int cells = 0;  // m
};
TriangleMesh tessellateBezierPatches(const std::vector<double>& ctrl, int du, int dv, int n, double delta);

inline double Bvh::boxDist2(const Box& b, const double* p) {
  double s = 0.0;
  for (int i = 0; i < 3; ++i) {
    const double d = p[i] < b.lo[i] ? b.lo[i] - p[i] : (p[i] > b.hi[i] ? p[i] - b.hi[i] : 0.0);
    s += d * d;
  }
  return s;
}

// The first primitive in near-first order that reaches the least distance: a later one
// replaces it only when strictly nearer, so visiting the tied boxes nearAll includes changes
// nothing.
template <typename F>
int64_t Bvh::nearest(const double* p, F&& dist2, double& best2) const {
  int64_t best = -1;
  nearAll(p, [&](uint32_t slot, uint32_t id) {
    double d;
    if constexpr (std::is_invocable_v<F, uint32_t, uint32_t, double>)
      d = dist2(slot, id, best2);
    else
      d = dist2(id, best2);
    if (d < best2 || (best < 0 && best2 == INFINITY)) {
      best2 = d;
      best = id;
    }
  }, best2);
  return best;
}

template <typename F>
void Bvh::nearAll(const double* p, F&& visit, double& bound2) const {
  if (nodes_.empty()) return;
  struct Entry {
    uint32_t node;
    double gap2;
  };
  Entry stack[128];
  int sp = 0;
  stack[sp++] = {0, boxDist2(nodes_[0].box, p)};
  while (sp > 0) {
    const Entry e = stack[--sp];
    if (e.gap2 > bound2) continue;
    const NodeB& n = nodes_[e.node];
    if (n.count > 0) {
      for (uint32_t k = n.first; k < n.first + n.count; ++k) visit(k, order_[k]);
      continue;
    }
    const double dl = boxDist2(nodes_[n.left].box, p), dr = boxDist2(nodes_[n.right].box, p);
    if (dl <= dr) {
      stack[sp++] = {n.right, dr};
      stack[sp++] = {n.left, dl};
    } else {
      stack[sp++] = {n.left, dl};
      stack[sp++] = {n.right, dr};
    }
  }
}

template <typename F>
void Bvh::nearBox(const Box& q, double gap, F&& visit) const {
  if (nodes_.empty()) return;
  auto within = [&](const Box& b) {
    double s = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double d = std::max({0.0, b.lo[k] - q.hi[k], q.lo[k] - b.hi[k]});
      s += d * d;
    }
    return s <= gap * gap;
  };
  uint32_t stack[128];
  int sp = 0;
  stack[sp++] = 0;
  while (sp > 0) {
    const NodeB& n = nodes_[stack[--sp]];
    if (!within(n.box)) continue;
    if (n.count > 0) {
      for (uint32_t k = n.first; k < n.first + n.count; ++k) {
        if constexpr (std::is_same_v<std::invoke_result_t<F, uint32_t, uint32_t>, bool>) {
          if (!visit(k, order_[k])) return;
        } else {
          visit(k, order_[k]);
        }
      }
      continue;
    }
    stack[sp++] = n.left;
    stack[sp++] = n.right;
  }
}

template <typename F>
void Bvh::containing(const double* p, F&& visit) const {
  if (nodes_.empty()) return;
  uint32_t stack[128];
  int sp = 0;
  stack[sp++] = 0;
  while (sp > 0) {
    const NodeB& n = nodes_[stack[--sp]];
    if (boxDist2(n.box, p) > 0.0) continue;
    if (n.count > 0) {
      for (uint32_t k = n.first; k < n.first + n.count; ++k) {
        if constexpr (std::is_same_v<std::invoke_result_t<F, uint32_t>, bool>) {
          if (!visit(order_[k])) return;  // the visitor has its answer
        } else {
          visit(order_[k]);
        }
      }
      continue;
    }
    stack[sp++] = n.left;
    stack[sp++] = n.right;
  }
}

}  // namespace frep
