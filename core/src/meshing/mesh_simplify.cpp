// Adaptive, feature-preserving edge collapses checked against the model (mesh_simplify.h).
#include "frep/meshing/mesh_simplify.h"

#include <Eigen/Eigenvalues>
#include <boost/container/small_vector.hpp>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <map>
#include <memory>
#include <functional>
#include <queue>
#include <unordered_map>

#include "frep/evaluators/eval.h"
#include "frep/meshing/mesh_predicates.h"
#include "sampling/parallel_chunks.h"


namespace frep {

namespace {

using V3 = std::array<double, 3>;
using Tri = std::array<uint32_t, 3>;

V3 add(const V3& a, const V3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
V3 sub(const V3& a, const V3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
V3 scale(const V3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
double dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
V3 cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double norm(const V3& a) { return std::sqrt(dot(a, a)); }

// Sum of squared distances to planes n.x = n.p (Garland & Heckbert's quadric), here the model's
// tangent planes at surface points.
struct Quadric {
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  double c = 0, weight = 0;
  void addPlane(const V3& n, const V3& p) {
    Eigen::Vector3d nn(n[0], n[1], n[2]);
    double d = -dot(n, p);
    A += nn * nn.transpose();
    b += d * nn;
    c += d * d;
    weight += 1;
  }
  // The 11 numbers SimplifyCarry::Vertex holds (A: xx xy xz yy yz zz, b, c, weight), and back.
  std::array<double, 11> packed() const {
    return {A(0, 0), A(0, 1), A(0, 2), A(1, 1), A(1, 2), A(2, 2), b[0], b[1], b[2], c, weight};
  }
  static Quadric unpacked(const std::array<double, 11>& d) {
    Quadric q;
    q.A << d[0], d[1], d[2], d[1], d[3], d[4], d[2], d[4], d[5];
    q.b = Eigen::Vector3d(d[6], d[7], d[8]);
    q.c = d[9];
    q.weight = d[10];
    return q;
  }
  Quadric& operator+=(const Quadric& o) {
    A += o.A, b += o.b, c += o.c, weight += o.weight;
    return *this;
  }
  double operator()(const V3& x) const {
    Eigen::Vector3d v(x[0], x[1], x[2]);
    return std::max(0.0, v.dot(A * v) + 2 * b.dot(v) + c);
  }
  // The least-squares point nearest to `ref`. Directions with less support than half a plane
  // (eigenvalue < 0.5; each unit-normal plane adds 1 to the trace) stay at ref: nearly parallel
  // planes do not define a crease. An absolute threshold, not one relative to the largest
  // eigenvalue: a vertex that has absorbed a whole face holds thousands of that face's planes
  // and still only a few dozen of the face across the crease.
  V3 minimiser(const V3& ref) const {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
    es.computeDirect(A);  // closed form for 3x3: several times faster than the iterative solver
    Eigen::Vector3d r(ref[0], ref[1], ref[2]), g = -(A * r + b), x = r;
    double top = es.eigenvalues().maxCoeff();
    for (int i = 0; i < 3; ++i) {
      double l = es.eigenvalues()[i];
      if (l > 0.5 && l > 1e-9 * top) {
        x += es.eigenvectors().col(i) * (es.eigenvectors().col(i).dot(g) / l);
      }
    }
    return {x[0], x[1], x[2]};
  }
};

// Closest distance from p to triangle abc (Ericson, Real-Time Collision Detection, 5.1.5).
double pointTriangleDistance(const V3& p, const V3& a, const V3& b, const V3& c) {
  V3 ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
  double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return norm(ap);
  V3 bp = sub(p, b);
  double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return norm(bp);
  double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return norm(sub(p, add(a, scale(ab, d1 / (d1 - d3)))));
  V3 cp = sub(p, c);
  double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return norm(cp);
  double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return norm(sub(p, add(a, scale(ac, d2 / (d2 - d6)))));
  double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return norm(sub(p, add(b, scale(sub(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6))))));
  double denom = 1 / (va + vb + vc);
  return norm(sub(p, add(a, add(scale(ab, vb * denom), scale(ac, vc * denom)))));
}

double quality(const V3& a, const V3& b, const V3& c) {
  double s = dot(sub(b, a), sub(b, a)) + dot(sub(c, b), sub(c, b)) + dot(sub(a, c), sub(a, c));
  return s > 0 ? 2 * std::sqrt(3.0) * norm(cross(sub(b, a), sub(c, a))) / s : 0;
}

constexpr int kMaxSamplesPerSide = 64;  // the error check's subdivision: m <= 64
constexpr size_t kProbes = 4;           // error samples tried first on every new triangle
constexpr int kGlobalStage = 4;         // SimplifyOptions::progress: the global pass
constexpr int kClusterLevels = 2;       // cell contractions: cells of 1, 2 and 4 voxels

}  // namespace

// The error check's samples of a triangle split m x m (withinLevel): the upright sub-triangles
// (i, j), i + j < m, each standing for its centroid a + (i + 1/3) u + (j + 1/3) v (u, v: the
// edges from a over m), probes first. Not the corners or edges: on a crease of the model the
// sign test along the normal is ill-posed. The centroids form a lattice of spacing longest/m
// (<= half a voxel); the upside-down sub-triangles' centroids would bring no point of the
// triangle nearer to a sample (its farthest points are at the corners and edges, next to
// upright ones; tested: ErrorSamplesCoverTheTriangleAsTheFullSubdivisionDoes) and are left out.
// Probes: the upright sub-triangles at (or, from an upside-down one, next to) the centroid and
// the midpoints between it and the corners, where a chord is deepest.
const std::vector<std::array<int32_t, 2>>& errorSampleCells(int m) {
  static const std::vector<std::vector<std::array<int32_t, 2>>> table = [] {
    std::vector<std::vector<std::array<int32_t, 2>>> t(kMaxSamplesPerSide + 1);
    for (int m = 1; m <= kMaxSamplesPerSide; ++m) {
      std::vector<std::array<int32_t, 2>>& cells = t[m];
      const double targets[kProbes][2] = {{m / 3.0, m / 3.0}, {m / 6.0, m / 6.0}, {2 * m / 3.0, m / 6.0}, {m / 6.0, 2 * m / 3.0}};
      for (const auto& tg : targets) {
        const int i = std::min(int(tg[0]), m - 1), j = std::min(int(tg[1]), m - 1 - i);
        if (std::find(cells.begin(), cells.end(), std::array<int32_t, 2>{i, j}) == cells.end()) cells.push_back({i, j});
      }
      const auto probes = std::ptrdiff_t(cells.size());
      for (int i = 0; i < m; ++i)
        for (int j = 0; i + j < m; ++j)
          if (std::find(cells.begin(), cells.begin() + probes, std::array<int32_t, 2>{i, j}) == cells.begin() + probes)
            cells.push_back({i, j});
    }
    return t;
  }();
  return table.at(size_t(m));
}

namespace {

constexpr double kQuantum = 65536;      // exact predicates: 2^16 steps per voxel
// The spatial hash's cell for the self-intersection check. Only the speed depends on it (every
// pair whose boxes meet is tested exactly either way): 8 voxels files a simplified triangle
// under one to eight cells without the separating-axis test, and took 30% less time in
// embedded() than 2 at 256^3.
constexpr double kBucketVoxels = 8;

// The state a simplification works on: the whole mesh, or one block of it (locked vertices and
// the triangles around the block held fixed, placements confined to the block).
struct Work {
  std::vector<V3> pos, normal;
  std::vector<EdgeKey> key;
  std::vector<Quadric> quad;
  std::vector<char> moved, locked;  // per vertex
  std::vector<Tri> tris;
  std::vector<int8_t> level;  // per triangle: error level (-1: not measured yet)
  std::vector<char> made;     // per triangle: made by a collapse
  bool confined = false;      // placements stay inside [regionLo, regionHi]
  V3 regionLo{}, regionHi{};
  // Per vertex, or empty (none): the tag of the block run that owned it and whose collapses ran
  // out, 0 for none. Every edge between two vertices of one tag was tried there, after the last
  // change to either end's star, and failed for reasons the next block's borders cannot change
  // (a placement cut off by the block's border unsettles its vertices): a later pass starts
  // from the other edges only, and a change to a settled vertex's star re-tries its edges.
  std::vector<uint32_t> settled;
};

// The state of a mesh (vertices in key order, triangles canonical) with what earlier passes
// carried: quadrics beyond a vertex's own tangent plane, error levels, made triangles.
// The mesh's vertex and triangle arrays move into the work (the caller replaces the mesh after).
Work workOf(Mesh&& mesh, int threads) {
  Work w;
  w.pos = std::move(mesh.positions);
  w.normal = std::move(mesh.normals);
  w.key = std::move(mesh.keys);
  const size_t nv = w.pos.size(), nt = mesh.triangles.size();
  for (const SimplifyCarry::Vertex& c : mesh.carry.vertices)
    if (c.index >= nv) throw std::invalid_argument("simplifyMesh: a carried vertex past the mesh's vertices");
  if (!mesh.carry.triangles.empty() && mesh.carry.triangles.size() != nt)
    throw std::invalid_argument("simplifyMesh: the carried triangle states do not match the triangles");
  // The master's serial stretch between the merge and the first block pass: in chunks, on all
  // its threads (each entry written once; the same arrays for any thread count).
  constexpr size_t kGrain = 1 << 14;
  w.quad.resize(nv);
  w.moved.resize(nv);
  w.locked.resize(nv);
  w.settled.resize(nv);
  parallelChunks(nv, kGrain, threads, [&](size_t b, size_t e) {
    for (size_t v = b; v < e; ++v) {
      w.quad[v] = Quadric();
      w.quad[v].addPlane(w.normal[v], w.pos[v]);
      w.moved[v] = 0, w.locked[v] = 0, w.settled[v] = 0;
    }
  });
  for (const SimplifyCarry::Vertex& c : mesh.carry.vertices) {  // in order: a repeated index, the last wins
    w.quad[c.index] = Quadric::unpacked(c.quadric);
    w.moved[c.index] = c.moved;
    w.settled[c.index] = c.settled;
  }
  w.tris = std::move(mesh.triangles);
  w.level.resize(nt);
  w.made.resize(nt);
  const std::vector<uint8_t>& states = mesh.carry.triangles;
  parallelChunks(nt, kGrain, threads, [&](size_t b, size_t e) {
    for (size_t t = b; t < e; ++t) {
      w.level[t] = states.empty() ? int8_t(-1) : int8_t((states[t] & 0x7f) - 1);
      w.made[t] = !states.empty() && (states[t] & 0x80) != 0;
    }
  });
  return w;
}

// The inverse of workOf for a region's piece: the carry lists what the next passes need.
void carryOf(const Work& w, SimplifyCarry& carry) {
  carry.vertices.clear();
  for (uint32_t v = 0; v < w.pos.size(); ++v) {
    const Quadric& q = w.quad[v];
    const uint32_t settled = w.settled.empty() ? 0 : w.settled[v];
    if (q.weight == 1 && !w.moved[v] && settled == 0) continue;  // as workOf rebuilds it
    carry.vertices.push_back({v, q.packed(), uint8_t(w.moved[v] ? 1 : 0), settled});
  }
  carry.triangles.resize(w.tris.size());
  for (size_t t = 0; t < w.tris.size(); ++t) carry.triangles[t] = uint8_t((w.level[t] + 1) | (w.made[t] ? 0x80 : 0));
}

// A 4-ary min-heap (by operator>): fewer levels, so fewer cache misses per pop than a binary
// heap of the same elements. Pops in the same order as std::priority_queue for a total order.
template <typename T>
class MinHeap {
 public:
  bool empty() const { return h_.empty(); }
  size_t size() const { return h_.size(); }
  const T& top() const { return h_.front(); }
  void push(const T& x) {
    size_t i = h_.size();
    h_.push_back(x);
    while (i > 0) {
      const size_t p = (i - 1) / 4;
      if (!(h_[p] > x)) break;
      h_[i] = h_[p];
      i = p;
    }
    h_[i] = x;
  }
  void pop() {
    const T x = h_.back();
    h_.pop_back();
    if (!h_.empty()) siftDown(0, x);
  }
  // Drops the elements `dead` accepts and rebuilds the heap (bottom-up, O(n)).
  template <typename Dead>
  void purge(Dead&& dead) {
    h_.erase(std::remove_if(h_.begin(), h_.end(), dead), h_.end());
    if (h_.size() < 2) return;
    for (size_t k = (h_.size() - 2) / 4 + 1; k-- > 0;) siftDown(k, h_[k]);
  }

 private:
  // Puts x at i or below, moving smaller children up.
  void siftDown(size_t i, const T x) {
    const size_t n = h_.size();
    for (;;) {
      const size_t c0 = 4 * i + 1;
      if (c0 >= n) break;
      size_t best = c0;
      for (size_t c = c0 + 1; c < std::min(c0 + 4, n); ++c)
        if (h_[best] > h_[c]) best = c;
      if (!(x > h_[best])) break;
      h_[i] = h_[best];
      i = best;
    }
    h_[i] = x;
  }

  std::vector<T> h_;
};

class Simplifier {
 public:
  // deferIntersections: no self-intersection check per collapse; embedded() checks the result
  // once at the end instead (simplifyChecked).
  Simplifier(Work&& work, const TapePtr& tape, const GridSpec& grid, const SimplifyOptions& opt, bool deferIntersections)
      : w_(std::move(work)), tape_(tape), grid_(grid), opt_(opt), tol_(opt.tolerance * grid.voxel),
        deferred_(deferIntersections) {
    // Error levels e_k = tol * 2^k up to two voxels (or the tolerance if larger): a replaced
    // triangle allows its new ones at most that much error, however far its own chord was (the
    // mesher's chords across a crease can be most of a voxel deep).
    while (std::ldexp(tol_, maxLevel_ + 1) <= std::max(tol_, grid_.voxel) * (1 + 1e-12)) ++maxLevel_;
    for (size_t k = 0; k < levelTol_.size(); ++k) levelTol_[k] = std::ldexp(tol_, int(k));
    if (tape_->numVars() > 3 && opt_.fixedCoords.size() < tape_->numVars() - 3)
      throw std::invalid_argument("simplifyMesh: the model has " + std::to_string(tape_->numVars()) +
                                  " coordinates; give values for x[4..] (fixedCoords)");
  }

  // Collapses until no candidate is left; then work(), vertexAlive() and triangleAlive() hold
  // the result.
  const SimplifyStats& run() {
    setUp();
    // Cells of 1, 2 and 4 voxels first (deferred mode only: the rerun of a block that failed the
    // intersection check goes edge by edge), then the greedy edge collapses.
    if (deferred_)
      for (int level = 0; level <= kClusterLevels; ++level) contractCells(level);
    pushAllCandidates();
    const bool report = opt_.progress && !w_.confined;  // the global pass only
    uint64_t examined = 0;
    // Most entries go stale (a collapse re-pushes its ring): when the heap has doubled since the
    // last purge, drop them, so pops sift through a shallower heap. Same pop order.
    size_t purgeAt = 2 * queue_.size() + 1024;
    while (!queue_.empty()) {
      if (queue_.size() >= purgeAt) {
        queue_.purge([&](const Candidate& c) { return !alive_[c.a] || !alive_[c.b] || version_[c.a] != c.va || version_[c.b] != c.vb; });
        purgeAt = 2 * queue_.size() + 1024;
      }
      if (report && (examined & 4095) == 0) opt_.progress(kGlobalStage, examined, examined + queue_.size());
      ++examined;
      Candidate c = queue_.top();
      queue_.pop();
      if (!alive_[c.a] || !alive_[c.b] || version_[c.a] != c.va || version_[c.b] != c.vb) continue;
      tryCollapse(c.a, c.b);
    }
    if (report) opt_.progress(kGlobalStage, examined, examined);
    int worst = -1;  // over the triangles that collapses made
    for (uint32_t t = 0; t < w_.tris.size(); ++t)
      if (tAlive_[t] && w_.made[t]) worst = std::max<int>(worst, w_.level[t]);
    stats_.errorBound = worst < 0 ? 0 : levelTol_[size_t(worst)];
    return stats_;
  }
  const Work& work() const { return w_; }

  // After a deferred run: does no triangle a collapse made meet a triangle near it improperly
  // (the same exact predicates as the per-collapse check, once per final triangle)?
  bool embedded() {
    // Every alive triangle's box and cells computed once; (cell, triangle) pairs in one array
    // grouped by cell (no hash map of lists to build).
    std::vector<Entry>& box = scratch_.boxes;
    std::vector<uint32_t>& cellsFrom = scratch_.cellsFrom;
    std::vector<uint64_t>& cellsOf = scratch_.cells;
    std::vector<std::pair<uint64_t, uint32_t>>& filed = scratch_.filed;
    box.resize(w_.tris.size());
    cellsFrom.assign(w_.tris.size() + 1, 0);
    cellsOf.clear();
    filed.clear();
    for (uint32_t t = 0; t < w_.tris.size(); ++t) {
      cellsFrom[t] = uint32_t(cellsOf.size());
      if (!tAlive_[t]) continue;
      const size_t first = cellsOf.size();
      fileTriangle(t, [&](uint64_t k, const Entry& e) { box[t] = e, cellsOf.push_back(k); });
      std::sort(cellsOf.begin() + std::ptrdiff_t(first), cellsOf.end());
      cellsOf.erase(std::unique(cellsOf.begin() + std::ptrdiff_t(first), cellsOf.end()), cellsOf.end());
      for (size_t i = first; i < cellsOf.size(); ++i) filed.push_back({cellsOf[i], t});
    }
    cellsFrom[w_.tris.size()] = uint32_t(cellsOf.size());
    // Grouped by a hash of the cell (a counting sort: linear, unlike sorting by cell); a
    // bucket's entries of other cells are skipped by their key.
    size_t buckets = 1;
    while (buckets < filed.size()) buckets <<= 1;
    const uint64_t mask = buckets - 1;
    auto bucketOf = [&](uint64_t key) { return (key * 0x9E3779B97F4A7C15ull >> 20) & mask; };
    std::vector<uint32_t>& bucketFrom = scratch_.bucketFrom;
    std::vector<std::pair<uint64_t, uint32_t>>& byBucket = scratch_.byBucket;
    bucketFrom.assign(buckets + 1, 0);
    for (const auto& f : filed) ++bucketFrom[bucketOf(f.first) + 1];
    for (size_t b = 0; b < buckets; ++b) bucketFrom[b + 1] += bucketFrom[b];
    byBucket.resize(filed.size());
    {
      std::vector<uint32_t>& at = scratch_.bucketFill;
      at.assign(bucketFrom.begin(), bucketFrom.end() - 1);
      for (const auto& f : filed) byBucket[at[bucketOf(f.first)]++] = f;
    }
    for (uint32_t t = 0; t < w_.tris.size(); ++t) {
      if (!tAlive_[t] || !madeNow_[t]) continue;
      const Tri& tr = w_.tris[t];
      const std::array<exact::P, 3> qt{qpos_[tr[0]], qpos_[tr[1]], qpos_[tr[2]]};
      V3 lo = w_.pos[tr[0]], hi = lo;
      for (uint32_t v : tr)
        for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], w_.pos[v][k]), hi[k] = std::max(hi[k], w_.pos[v][k]);
      float flo[3], fhi[3];
      roundOut(lo, hi, flo, fhi);
      ++probeNow_;
      probe_[t].seen = probeNow_;
      for (uint32_t c = cellsFrom[t]; c < cellsFrom[t + 1]; ++c) {
        const uint64_t key = cellsOf[c];
        const uint64_t b = bucketOf(key);
        for (uint32_t i = bucketFrom[b]; i < bucketFrom[b + 1]; ++i) {
          if (byBucket[i].first != key) continue;
          const uint32_t u = byBucket[i].second;
          const Entry& e = box[u];
          if (e.hi[0] < flo[0] || e.lo[0] > fhi[0] || e.hi[1] < flo[1] || e.lo[1] > fhi[1] || e.hi[2] < flo[2] ||
              e.lo[2] > fhi[2])
            continue;
          Probe& pr = probe_[u];
          if (pr.seen == probeNow_) continue;
          pr.seen = probeNow_;
          // Two triangles that meet share a point, so both are filed under its cell: a pair of
          // made triangles is tested from the first of them.
          if (madeNow_[u] && u < t) continue;
          const Tri& tu = w_.tris[u];
          if (improperPair(tr, qt, tu, {qpos_[tu[0]], qpos_[tu[1]], qpos_[tu[2]]})) return false;
        }
      }
    }
    return true;
  }
  bool vertexAlive(uint32_t v) const { return alive_[v] && !vtris_[v].empty(); }
  bool settles() const { return deferred_; }
  // A placement cut off by the block's border: v's edges may pass in another block.
  bool borderBound(uint32_t v) const { return borderBound_[v] != 0; }
  bool triangleAlive(uint32_t t) const { return tAlive_[t]; }

 private:
  struct Candidate {
    double cost, length2;
    uint32_t a, b, va, vb;
    bool operator>(const Candidate& o) const {
      if (cost != o.cost) return cost > o.cost;
      if (length2 != o.length2) return length2 > o.length2;
      return a != o.a ? a > o.a : b > o.b;
    }
  };

  void setUp() {
    const size_t nv = w_.pos.size();
    // Where the surface leaves the grid's box the mesh ends in an open rim on the box's faces:
    // its vertices stay where the mesher put them (moving one would cut a notch into the rim).
    for (size_t v = 0; v < nv; ++v)
      if (onBoxFace(w_.pos[v])) w_.locked[v] = 1;
    alive_.assign(nv, 1);
    version_.assign(nv, 0);
    if (w_.settled.size() != nv) w_.settled.assign(nv, 0);
    borderBound_.assign(nv, 0);
    markA_.assign(nv, 0);
    markB_.assign(nv, 0);
    vtris_.assign(nv, {});
    qpos_.resize(nv);
    for (size_t v = 0; v < nv; ++v) qpos_[v] = quantise(w_.pos[v]);
    tAlive_.assign(w_.tris.size(), 1);
    madeNow_.assign(w_.tris.size(), 0);
    probe_.resize(w_.tris.size());
    for (uint32_t t = 0; t < w_.tris.size(); ++t) {
      for (uint32_t v : w_.tris[t]) vtris_[v].push_back(t);
      if (!deferred_) insertBuckets(t);
    }
  }

  bool settledEdge(uint32_t a, uint32_t b) const { return w_.settled[a] != 0 && w_.settled[a] == w_.settled[b]; }
  // v's star changes: it is no longer settled, and the edges pushAllCandidates skipped for its
  // tag (those to vertices of the same tag; the others are queued already) are queued now, or
  // (push false: before the greedy phase) at its start.
  void unsettle(uint32_t v, bool push) {
    const uint32_t tag = w_.settled[v];
    if (tag == 0) return;
    w_.settled[v] = 0;
    if (!push) return;
    const uint32_t seen = nextMark();
    markA_[v] = seen;
    for (uint32_t t : vtris_[v])
      for (uint32_t x : w_.tris[t])
        if (markA_[x] != seen) {
          markA_[x] = seen;
          if (w_.settled[x] == tag) pushCandidate(v, x);
        }
  }

  // Every edge of the mesh as a collapse candidate.
  void pushAllCandidates() {
    for (uint32_t t = 0; t < w_.tris.size(); ++t) {
      if (!tAlive_[t]) continue;
      for (int c = 0; c < 3; ++c) {
        uint32_t a = w_.tris[t][c], b = w_.tris[t][(c + 1) % 3];
        // Each undirected edge once (in a closed mesh; a block's open rim is locked anyway).
        if (settledEdge(a, b)) continue;
        if (a < b || !std::count(vtris_[b].begin(), vtris_[b].end(), t)) pushCandidate(a, b);
      }
    }
  }

  // ---- positions ------------------------------------------------------------------------
  bool onBoxFace(const V3& p) const {
    const double eps = 1e-6 * grid_.voxel;
    for (int k = 0; k < 3; ++k) {
      const double lo = grid_.origin[k], hi = grid_.origin[k] + double(grid_.dims[k] - 1) * grid_.voxel;
      if (p[k] <= lo + eps || p[k] >= hi - eps) return true;
    }
    return false;
  }

  exact::P quantise(const V3& p) const {
    exact::P q;
    for (int k = 0; k < 3; ++k) q[k] = std::llround((p[k] - grid_.origin[k]) / grid_.voxel * kQuantum);
    return q;
  }

  V3 placement(uint32_t a, uint32_t b, double* cost, bool* clipped = nullptr) const {
    Quadric q = w_.quad[a];
    q += w_.quad[b];
    const V3 &pa = w_.pos[a], &pb = w_.pos[b];
    double ca = q(pa), cb = q(pb);
    V3 best = ca <= cb ? pa : pb;
    *cost = std::min(ca, cb);
    if (opt_.sharpFeatures) {
      V3 mid = scale(add(pa, pb), 0.5);
      V3 p = q.minimiser(mid);
      double reach = std::max(norm(sub(pa, pb)), grid_.voxel);
      double cp = q(p);
      bool inside = true;
      for (int k = 0; k < 3 && w_.confined; ++k) inside = inside && p[k] >= w_.regionLo[k] && p[k] <= w_.regionHi[k];
      if (norm(sub(p, mid)) <= reach && std::isfinite(cp) && cp <= *cost) {
        if (inside) {
          *cost = cp;
          best = p;
        } else if (clipped) {
          *clipped = true;
        }
      }
    }
    return best;
  }

  void pushCandidate(uint32_t a, uint32_t b) {
    if (w_.locked[a] || w_.locked[b]) return;
    if (a > b) std::swap(a, b);
    double cost;
    placement(a, b, &cost);
    // Mean squared distance to the tangent planes above tol^2: the merged vertex cannot sit on
    // all of them within the tolerance; not worth the model evaluations.
    if (cost > tol_ * tol_ * (w_.quad[a].weight + w_.quad[b].weight)) return;
    // Costs below 1e-6 tol^2 count as equal: then shorter edges first (even coarsening).
    double key = std::floor(cost / (1e-6 * tol_ * tol_));
    queue_.push({key, dot(sub(w_.pos[a], w_.pos[b]), sub(w_.pos[a], w_.pos[b])), a, b, version_[a], version_[b]});
  }

  // ---- spatial hash of triangles (for the self-intersection check) ------------------------
  std::array<int32_t, 6> cellRange(const V3& a, const V3& b, const V3& c) const {
    std::array<int32_t, 6> r;
    const double s = kBucketVoxels * grid_.voxel;
    for (int k = 0; k < 3; ++k) {
      double lo = std::min({a[k], b[k], c[k]}) - grid_.origin[k], hi = std::max({a[k], b[k], c[k]}) - grid_.origin[k];
      const double margin = 1e-3 * grid_.voxel;  // far above the quantisation step
      r[k] = int32_t(std::floor((lo - margin) / s));
      r[k + 3] = int32_t(std::floor((hi + margin) / s));
    }
    return r;
  }
  static uint64_t cellKey(int32_t x, int32_t y, int32_t z) {
    return (uint64_t(uint32_t(x + (1 << 20)) & 0x1fffff) << 42) | (uint64_t(uint32_t(y + (1 << 20)) & 0x1fffff) << 21) |
           uint64_t(uint32_t(z + (1 << 20)) & 0x1fffff);
  }
  // Calls f(key) for the cells of the range that the triangle abc may touch: all of them for a
  // small range, else those passing a conservative separating-axis test (the triangle's plane
  // and the nine edge x axis directions, the cell grown by a margin), so a large tilted
  // triangle is filed under the cells along its surface, not every cell of its box.
  template <typename F>
  void forTriangleCells(const V3& a, const V3& b, const V3& c, F&& f) const {
    const std::array<int32_t, 6> r = cellRange(a, b, c);
    const int64_t count = int64_t(r[3] - r[0] + 1) * (r[4] - r[1] + 1) * (r[5] - r[2] + 1);
    const double s = kBucketVoxels * grid_.voxel, h = 0.5 * s + 1e-3 * grid_.voxel;
    const V3 e[3] = {sub(b, a), sub(c, b), sub(a, c)};
    const V3 n = cross(e[0], e[2]);
    for (int32_t x = r[0]; x <= r[3]; ++x)
      for (int32_t y = r[1]; y <= r[4]; ++y)
        for (int32_t z = r[2]; z <= r[5]; ++z) {
          if (count > 8) {
            const V3 cc{grid_.origin[0] + (x + 0.5) * s, grid_.origin[1] + (y + 0.5) * s, grid_.origin[2] + (z + 0.5) * s};
            const V3 v[3] = {sub(a, cc), sub(b, cc), sub(c, cc)};
            auto separated = [&](const V3& axis) {
              double p0 = dot(axis, v[0]), p1 = dot(axis, v[1]), p2 = dot(axis, v[2]);
              double rad = h * (std::abs(axis[0]) + std::abs(axis[1]) + std::abs(axis[2]));
              return std::min({p0, p1, p2}) > rad * (1 + 1e-9) || std::max({p0, p1, p2}) < -rad * (1 + 1e-9);
            };
            bool apart = separated(n);
            for (int i = 0; i < 3 && !apart; ++i)
              apart = separated({0, -e[i][2], e[i][1]}) || separated({e[i][2], 0, -e[i][0]}) ||
                      separated({-e[i][1], e[i][0], 0});
            if (apart) continue;
          }
          f(cellKey(x, y, z));
        }
  }
  // Calls f(cell, entry) for the cells triangle t is filed under. The entry carries the
  // triangle's box (float, rounded outwards past a 1e-3 voxel margin), so a query scans its
  // cells' entries in order and touches a triangle only if the boxes meet.
  template <typename F>
  void fileTriangle(uint32_t t, F&& f) const {
    const Tri& tr = w_.tris[t];
    const V3 &a = w_.pos[tr[0]], &b = w_.pos[tr[1]], &c = w_.pos[tr[2]];
    Entry e{t, {}, {}};
    const double margin = 1e-3 * grid_.voxel;
    for (int k = 0; k < 3; ++k) {
      e.lo[k] = std::nextafter(float(std::min({a[k], b[k], c[k]}) - margin), -INFINITY);
      e.hi[k] = std::nextafter(float(std::max({a[k], b[k], c[k]}) + margin), INFINITY);
    }
    forTriangleCells(a, b, c, [&](uint64_t k) { f(k, e); });
  }
  void insertBuckets(uint32_t t) {
    fileTriangle(t, [&](uint64_t k, const Entry& e) { buckets_[k].push_back(e); });
  }
  // Before any corner of t moves (the same cells as its insertion).
  void eraseBuckets(uint32_t t) {
    const Tri& tr = w_.tris[t];
    forTriangleCells(w_.pos[tr[0]], w_.pos[tr[1]], w_.pos[tr[2]], [&](uint64_t k) {
      auto it = buckets_.find(k);
      auto& v = it->second;
      v.erase(std::find_if(v.begin(), v.end(), [t](const Entry& e) { return e.tri == t; }));
      if (v.empty()) buckets_.erase(it);
    });
  }

  // ---- error against the model --------------------------------------------------------------
  // A triangle's error level (levels): the first level k <= maxK at which every sample point p
  // of the triangle lies within e = tolerance * 2^k of the surface along the direction d, i.e.
  // the model changes sign along [p - 0.8 e d, p + 0.8 e d] (inside at the start, outside at the
  // end: the surface crosses it; 0.8 leaves a margin for the gaps between samples); maxK + 1
  // when there is none. d is the triangle's normal, or `primary` (for the mesher's slivers, whose
  // own normal is noise). Measuring along the normal (not towards the nearest surface point) also
  // keeps chords across a crease out: they are deeper along their normal than to the nearer face.
  struct LevelQuery {
    V3 a, b, c;
    V3 primary{0, 0, 0};  // zero: the triangle's own normal
    int level = 0;        // the answer
    // internal: unit direction, samples per side, whether the probes of `level` passed
    V3 d{};
    int m = 1, limit = 0;  // limit: the maxK of the last call
    const std::vector<std::array<int32_t, 2>>* cells = nullptr;  // errorSampleCells(m)
    bool probed = false, done = false;
  };

  // Answers every query. A level is checked in full only once its probes (kProbes points spread
  // over the triangle, where a chord is deepest) pass, and a failing level moves on to the next
  // one's probes: the answer is the same as checking every level in full, for far fewer
  // evaluations. All queries advance together, so each round is one batch of the evaluator
  // over every query's points. stopAbove: return false as soon as some query exceeds maxK.
  // resume: qs were answered by a call with a smaller maxK that failed; the queries that went
  // past it go on from where they stopped (the same answers as a fresh call, without checking
  // the lower levels again).
  bool levels(std::vector<LevelQuery>& qs, int maxK, bool stopAbove, bool resume = false) {
    if (resume) {
      for (LevelQuery& q : qs)
        if (q.d == V3{0, 0, 0})
          q.level = maxK + 1;  // as a fresh call answers
        else if (q.done && q.level == q.limit + 1)
          q.done = false;
    }
    for (LevelQuery& q : qs) q.limit = maxK;
    if (!resume)
      for (LevelQuery& q : qs) {  // a fresh call: every query from level 0
        auto unit = [](V3 d) {
          double l = norm(d);
          return l > 0 && std::isfinite(l) ? scale(d, 1 / l) : V3{0, 0, 0};
        };
        q.d = q.primary != V3{0, 0, 0} ? unit(q.primary) : unit(cross(sub(q.b, q.a), sub(q.c, q.a)));
        const double longest = std::max({norm(sub(q.b, q.a)), norm(sub(q.c, q.b)), norm(sub(q.a, q.c))});
        q.m = std::clamp(int(std::ceil(2 * longest / grid_.voxel)), 1, kMaxSamplesPerSide);  // <= half a voxel apart
        q.cells = &errorSampleCells(q.m);
        q.level = 0;
        q.probed = false;
        q.done = q.d == V3{0, 0, 0};  // no direction: no level passes
        if (q.done) q.level = maxK + 1;
      }
    const uint32_t nvars = tape_->numVars();
    batch_.reserve(*tape_);
    inputs_.resize(nvars);
    for (uint32_t k = 0; k < nvars; ++k) inputs_[k] = batch_.in(k);
    const uint32_t spatial = std::min(nvars, 3u);  // a 2D model (a prism) has no x[3]
    for (;;) {
      bool any = false;
      failed_.assign(qs.size(), 0);
      for (uint32_t i = 0; i < qs.size(); ++i) {
        LevelQuery& q = qs[i];
        if (q.done) continue;
        any = true;
        const std::vector<std::array<int32_t, 2>>& cells = *q.cells;
        const size_t from = q.probed ? kProbes : 0, to = q.probed ? cells.size() : std::min(kProbes, cells.size());
        const double e = 0.8 * levelTol_[size_t(q.level)];
        const V3 u = scale(sub(q.b, q.a), 1.0 / q.m), v = scale(sub(q.c, q.a), 1.0 / q.m), de = scale(q.d, e);
        // Straight into the evaluator's lanes, as many as fit before the batch is evaluated; a
        // query that already failed this round stops.
        for (size_t k = from; k < to && !failed_[i];) {
          const size_t n = std::min(to - k, kPairsPerCall - lanes_);
          double* const* in = inputs_.data();
          for (size_t j = 0; j < n; ++j, ++k) {
            const double s = cells[k][0] + 1.0 / 3, t = cells[k][1] + 1.0 / 3;
            const size_t lane = 2 * (lanes_ + j);
            for (uint32_t c = 0; c < spatial; ++c) {
              const double pc = q.a[c] + (u[c] * s + v[c] * t);  // a + s u + t v
              in[c][lane] = pc - de[c], in[c][lane + 1] = pc + de[c];
            }
            laneQuery_[lanes_ + j] = i;
          }
          lanes_ += n;
          if (lanes_ == kPairsPerCall && crossed() && stopAbove && endsAbove(qs, maxK)) return false;
        }
      }
      if (!any) return true;
      if (crossed() && stopAbove && endsAbove(qs, maxK)) return false;
      for (uint32_t i = 0; i < qs.size(); ++i) {
        LevelQuery& q = qs[i];
        if (q.done) continue;
        if (!failed_[i]) {
          // the probes passed: now the rest (none left: done); the rest passed: done
          if (q.probed || q.cells->size() <= kProbes)
            q.done = true;
          else
            q.probed = true;
        } else {
          q.probed = false;
          if (++q.level > maxK) {
            q.done = true;
            if (stopAbove) return false;
          }
        }
      }
    }
  }

  // With stopAbove: some query failed its last level maxK, so the call's answer (false) is known
  // without the rest of the round. That query is answered (above maxK); the others keep the
  // state they began the round with, and a resume redoes the round for them (the same answers).
  bool endsAbove(std::vector<LevelQuery>& qs, int maxK) {
    for (uint32_t i = 0; i < qs.size(); ++i)
      if (failed_[i] && !qs[i].done && qs[i].level == maxK) {
        qs[i].level = maxK + 1, qs[i].probed = false, qs[i].done = true;
        return true;
      }
    return false;
  }

  // Evaluates the pending lanes (pairs: f(p - e d) must be inside, f(p + e d) outside) and marks
  // failed_[query] where a pair is not. True if some pair failed.
  bool crossed() {
    if (lanes_ == 0) return false;
    const uint32_t nvars = tape_->numVars();
    for (uint32_t k = 3; k < nvars; ++k) std::fill_n(inputs_[k], 2 * lanes_, opt_.fixedCoords[k - 3]);
    const double* f = batch_.eval(*tape_, 2 * lanes_);
    stats_.modelEvals += 2 * lanes_;
    bool any = false;
    for (size_t i = 0; i < lanes_; ++i)
      if (!insideValue(f[2 * i]) || insideValue(f[2 * i + 1])) failed_[laneQuery_[i]] = 1, any = true;
    lanes_ = 0;
    return any;
  }

  int levelOf(uint32_t t) {
    if (w_.level[t] < 0) {
      const Tri& tr = w_.tris[t];
      std::vector<LevelQuery>& qs = scratch_.ownLevel;  // not queries: errorPasses holds those
      qs.assign(1, {});
      LevelQuery& q = qs[0];
      q.a = w_.pos[tr[0]], q.b = w_.pos[tr[1]], q.c = w_.pos[tr[2]];
      const V3 along = add(w_.normal[tr[0]], add(w_.normal[tr[1]], w_.normal[tr[2]]));
      if (quality(q.a, q.b, q.c) < opt_.minQuality && norm(along) > 0) q.primary = along;
      levels(qs, maxLevel_, false);
      w_.level[t] = int8_t(std::min(qs[0].level, maxLevel_));  // beyond the last level: no more allowance
    }
    return w_.level[t];
  }

  // The error check of a collapse or a contraction, whose new triangles are qs: the removed
  // vertices (gone) lie within e of the new triangles and every new triangle within e of the
  // surface (levels), e = tolerance * 2^allowed, allowed the worst level of the replaced
  // triangles (at least 0: the mesher's chords across a crease may be deeper than the
  // tolerance). That worst level is measured only when the tolerance alone does not pass: the
  // same outcome and the same levels, and most of the mesher's triangles never need theirs.
  bool errorPasses(std::vector<LevelQuery>& qs, const std::vector<V3>& gone, const std::vector<uint32_t>& replaced) {
    int allowed = 0;
    bool started = false;  // levels() ran: the second round resumes it
    for (bool measured = false;; measured = true) {
      const double e = levelTol_[size_t(allowed)];
      bool near = true;  // every removed vertex within e of some new triangle
      for (size_t i = 0; i < gone.size() && near; ++i) {
        near = false;
        for (size_t k = 0; k < qs.size() && !near; ++k) near = pointTriangleDistance(gone[i], qs[k].a, qs[k].b, qs[k].c) <= e;
      }
      if (near) {
        const bool pass = levels(qs, allowed, true, started);
        started = true;
        if (pass) return true;
      }
      if (measured) return false;
      int worst = 0;
      for (uint32_t t : replaced) worst = std::max(worst, levelOf(t));
      if (worst == allowed) return false;
      allowed = worst;
    }
  }

  // Shape of a changed triangle: tr (vertex ids, as it is) becoming c0, c1, c2 must keep facing
  // the same way — its own normal, or for a sliver (whose normal is noise: the mesher's
  // triangles where the surface grazes a grid point) the model's normals at its corners — within
  // ~78 degrees, and not degenerate. Tracks the worst quality before and after.
  // The worst quality of the triangles ts as they are (1 for none).
  double worstQuality(const std::vector<uint32_t>& ts) const {
    double worst = 1;
    for (uint32_t t : ts) worst = std::min(worst, quality(w_.pos[w_.tris[t][0]], w_.pos[w_.tris[t][1]], w_.pos[w_.tris[t][2]]));
    return worst;
  }
  // Below the quality bound the worst triangle may not get more than 10% worse (the mesher
  // leaves slivers where the surface grazes grid points; they go first).
  bool worstGotWorse(double before, double after) const { return after < opt_.minQuality && after < 0.9 * before; }

  bool keepsFacing(const Tri& tr, const V3& c0, const V3& c1, const V3& c2, double& worstBefore, double& worstAfter) const {
    const V3 &o0 = w_.pos[tr[0]], &o1 = w_.pos[tr[1]], &o2 = w_.pos[tr[2]];
    const double q0 = quality(o0, o1, o2);
    worstBefore = std::min(worstBefore, q0);
    const V3 n0 = q0 < opt_.minQuality ? add(w_.normal[tr[0]], add(w_.normal[tr[1]], w_.normal[tr[2]])) : cross(sub(o1, o0), sub(o2, o0));
    const V3 n1 = cross(sub(c1, c0), sub(c2, c0));
    const double l1 = norm(n1);
    worstAfter = std::min(worstAfter, quality(c0, c1, c2));
    return l1 > 1e-12 * grid_.voxel * grid_.voxel && dot(n0, n1) > 0.2 * norm(n0) * l1;
  }

  // ---- one collapse ---------------------------------------------------------------------------
  void tryCollapse(uint32_t a, uint32_t b) {
    // Link condition: exactly two triangles hold the edge, and a and b have no other common
    // neighbour; neither opposite vertex may drop below valence 3.
    // Scratch lists kept between calls (no allocation per attempt).
    std::vector<uint32_t>&opposite = scratch_.opposite, &changed = scratch_.changed, &removed = scratch_.removed,
                         &ring = scratch_.ring;
    for (auto* l : {&opposite, &changed, &removed, &ring}) l->clear();
    // a's neighbours marked; b's neighbours counted once each if marked (the common ones).
    const uint32_t mark = nextMark();
    for (uint32_t t : vtris_[a])
      for (uint32_t v : w_.tris[t]) markA_[v] = mark;
    size_t common = 0;
    for (uint32_t t : vtris_[b]) {
      bool hasA = false;
      for (uint32_t v : w_.tris[t]) hasA |= v == a;
      for (uint32_t v : w_.tris[t]) {
        if (v == a || v == b) continue;
        if (hasA) opposite.push_back(v);
        if (markA_[v] == mark && markB_[v] != mark) markB_[v] = mark, ++common;
      }
    }
    // The opposite vertices are common neighbours, so "no other common neighbour" is a count.
    if (opposite.size() != 2 || opposite[0] == opposite[1] || common != 2 || vtris_[opposite[0]].size() <= 3 ||
        vtris_[opposite[1]].size() <= 3) {
      ++stats_.rejectedTopology;
      return;
    }

    double cost;
    bool clipped = false;
    V3 p = placement(a, b, &cost, &clipped);
    if (clipped) borderBound_[a] = borderBound_[b] = 1;
    // changed: triangles kept with a new corner; removed: the two dropped
    for (uint32_t v : {a, b})
      for (uint32_t t : vtris_[v]) {
        const Tri& tr = w_.tris[t];
        bool both = (tr[0] == a || tr[1] == a || tr[2] == a) && (tr[0] == b || tr[1] == b || tr[2] == b);
        if (both) {
          if (v == a) removed.push_back(t);
        } else {
          changed.push_back(t);
        }
      }
    auto corner = [&](uint32_t v) { return v == a || v == b ? p : w_.pos[v]; };

    // Shape: no flip or fold, no sliver made worse (keepsFacing, worstGotWorse).
    double worstBefore = worstQuality(removed), worstAfter = 1;
    for (uint32_t t : changed) {
      const Tri& tr = w_.tris[t];
      if (!keepsFacing(tr, corner(tr[0]), corner(tr[1]), corner(tr[2]), worstBefore, worstAfter)) {
        ++stats_.rejectedShape;
        return;
      }
    }
    if (worstGotWorse(worstBefore, worstAfter)) {
      ++stats_.rejectedShape;
      return;
    }

    // Error: within the tolerance, or within the worst of the replaced triangles (errorPasses).
    std::vector<LevelQuery>& qs = scratch_.queries;
    qs.assign(changed.size(), {});
    for (size_t i = 0; i < changed.size(); ++i) {
      const Tri& tr = w_.tris[changed[i]];
      qs[i].a = corner(tr[0]), qs[i].b = corner(tr[1]), qs[i].c = corner(tr[2]);
    }
    std::vector<V3>& gonePoints = scratch_.gonePoints;
    gonePoints = {w_.pos[a], w_.pos[b]};
    std::vector<uint32_t>& replaced = scratch_.replaced;
    replaced = changed;
    replaced.insert(replaced.end(), removed.begin(), removed.end());
    if (!errorPasses(qs, gonePoints, replaced)) {
      ++stats_.rejectedError;
      return;
    }
    std::vector<int8_t>& newLevel = scratch_.newLevel;
    newLevel.resize(changed.size());
    for (size_t i = 0; i < changed.size(); ++i) newLevel[i] = int8_t(qs[i].level);

    // Self-intersection: the new triangles against each other, then against every other
    // triangle near them whose box meets theirs.
    const exact::P qp = quantise(p);
    if (!deferred_ && !noIntersection(a, b, p, qp, changed, removed)) {
      ++stats_.rejectedIntersection;
      return;
    }

    // Apply.
    for (uint32_t t : removed) {
      if (!deferred_) eraseBuckets(t);
      tAlive_[t] = 0;
      for (uint32_t v : w_.tris[t]) {
        auto& l = vtris_[v];
        l.erase(std::find(l.begin(), l.end(), t));
      }
    }
    if (!deferred_)
      for (uint32_t t : changed) eraseBuckets(t);
    for (uint32_t t : vtris_[b]) {
      for (uint32_t& v : w_.tris[t])
        if (v == b) v = a;
      vtris_[a].push_back(t);
    }
    vtris_[b].clear();
    alive_[b] = 0;
    if (p == w_.pos[b]) {  // stayed at b: a takes b's identity (its key and normal)
      w_.key[a] = w_.key[b];
      w_.normal[a] = w_.normal[b];
      w_.moved[a] = w_.moved[b];
    } else if (p != w_.pos[a]) {
      w_.moved[a] = 1;
    }
    w_.pos[a] = p;
    qpos_[a] = qp;
    w_.quad[a] += w_.quad[b];
    ++version_[a];
    for (size_t i = 0; i < changed.size(); ++i) {
      w_.level[changed[i]] = newLevel[i];
      w_.made[changed[i]] = 1;
      madeNow_[changed[i]] = 1;
      if (!deferred_) insertBuckets(changed[i]);
    }
    ++stats_.collapses;
    const uint32_t seen = nextMark();
    markA_[a] = seen;
    for (uint32_t t : vtris_[a])
      for (uint32_t v : w_.tris[t])
        if (markA_[v] != seen) markA_[v] = seen, ring.push_back(v);
    for (uint32_t v : ring) pushCandidate(a, v);  // the order of pushes does not matter: the
                                                   // candidates' order is total
    w_.settled[a] = 0;
    for (uint32_t v : ring) unsettle(v, true);
  }

  // ---- cell contractions --------------------------------------------------------------------
  // Before the greedy collapses, the vertices of one cell of 2^level voxels (by the grid edge
  // they came from) are merged into one in a single step where that is safe: dual contouring's
  // one vertex per cell (Ju et al.), reached from the marching tetrahedra's mesh, with the same
  // checks as an edge collapse. One contraction of k vertices does the work of k - 1 edge
  // collapses with one placement and one error check of its fan, instead of k - 1 of each and
  // the heap traffic of every ring they change. Cells go in key order, each connected group of
  // a cell's vertices once: the outcome is a function of the input (split-invariance).
  void contractCells(int level) {
    std::vector<std::pair<uint64_t, uint32_t>>& byCell = scratch_.byCell;
    byCell.clear();
    for (uint32_t v = 0; v < w_.pos.size(); ++v) {
      if (!alive_[v] || w_.locked[v] || vtris_[v].empty()) continue;
      const auto parts = edgeKeyParts(w_.key[v]);
      byCell.push_back({edgeKey(parts[0] >> level, parts[1] >> level, parts[2] >> level, 0), v});
    }
    std::sort(byCell.begin(), byCell.end());
    std::vector<uint32_t>& group = scratch_.group;
    std::vector<uint32_t>& component = scratch_.component;
    for (size_t i = 0; i < byCell.size();) {
      size_t j = i;
      while (j < byCell.size() && byCell[j].first == byCell[i].first) ++j;
      // tried in the block run that settled them all (the same tag)
      bool allSettled = w_.settled[byCell[i].second] != 0;
      for (size_t k = i; k < j && allSettled; ++k) allSettled = w_.settled[byCell[k].second] == w_.settled[byCell[i].second];
      if (j - i >= 2 && !allSettled) {
        group.clear();
        const uint32_t inGroup = nextMark();
        for (size_t k = i; k < j; ++k) group.push_back(byCell[k].second), markA_[byCell[k].second] = inGroup;
        // Connected pieces of the group (two sheets through one cell are two pieces).
        const uint32_t taken = nextMark();
        for (uint32_t seed : group) {
          if (markB_[seed] == taken) continue;
          component.assign(1, seed);
          markB_[seed] = taken;
          for (size_t q = 0; q < component.size(); ++q)
            for (uint32_t t : vtris_[component[q]])
              for (uint32_t u : w_.tris[t])
                if (markA_[u] == inGroup && markB_[u] != taken) markB_[u] = taken, component.push_back(u);
          if (component.size() >= 2) {
            std::sort(component.begin(), component.end());
            tryContract(component);
            // tryContract used the marks: restore the group's for its other pieces
            for (uint32_t u : group) markA_[u] = inGroup;
          }
        }
      }
      i = j;
    }
  }

  // Merges the connected vertices C into one if the surface stays a closed 2-manifold of the
  // same genus and the checks of an edge collapse pass (shape, error against the model).
  void tryContract(const std::vector<uint32_t>& C) {
    std::vector<uint32_t>& gone = scratch_.removed;  // the star's triangles with 2 or 3 corners in C
    gone.clear();
    std::vector<Fan>& fan = scratch_.fan;  // and those with one
    fan.clear();
    const uint32_t inC = nextMark();
    for (uint32_t c : C) markA_[c] = inC;
    ++stampNow_;
    for (uint32_t c : C)
      for (uint32_t t : vtris_[c]) {
        if (probe_[t].skip == stampNow_) continue;
        probe_[t].skip = stampNow_;
        const Tri& tr = w_.tris[t];
        int n = 0, at = 0;
        for (int k = 0; k < 3; ++k)
          if (markA_[tr[k]] == inC) ++n, at = k;
        if (n == 1)
          fan.push_back({t, tr[at], tr[(at + 1) % 3], tr[(at + 2) % 3]});
        else
          gone.push_back(t);
      }
    // Topology: the far edges u -> w of the fan form one simple cycle through every vertex next
    // to C, and the star of C is a disk (Euler: F = 2|C| + |fan| - 2, the edges other than the
    // cycle's being shared by two of its triangles), so C becomes one vertex inside that cycle.
    const size_t nc = C.size(), nf = fan.size();
    bool ok = nf >= 3 && gone.size() + nf == 2 * nc + nf - 2;
    const uint32_t onCycle = nextMark();
    std::vector<uint32_t>& next = scratch_.next;
    if (ok) {
      if (next.size() < w_.pos.size()) next.resize(w_.pos.size());
      for (const Fan& f : fan) {
        if (markB_[f.u] == onCycle) ok = false;
        markB_[f.u] = onCycle, next[f.u] = f.w;
      }
    }
    if (ok) {
      uint32_t u = fan[0].u;
      size_t steps = 0;
      do {
        if (markB_[u] != onCycle || steps > nf) { ok = false; break; }
        u = next[u], ++steps;
      } while (u != fan[0].u);
      ok = ok && steps == nf;
    }
    if (ok)  // every vertex of the star outside C is on the cycle
      for (uint32_t t : gone)
        for (uint32_t v : w_.tris[t]) ok = ok && (markA_[v] == inC || markB_[v] == onCycle);
    if (ok)  // the cycle's vertices keep at least three triangles
      for (const Fan& f : fan) {
        size_t inStar = 0;
        for (uint32_t t : vtris_[f.u]) inStar += probe_[t].skip == stampNow_;
        ok = ok && vtris_[f.u].size() - inStar + 2 >= 3;
      }
    if (ok && nf == 3)  // three cycle vertices that already bound a triangle: a closed tetrahedron
      for (uint32_t t : vtris_[fan[0].u]) {
        if (probe_[t].skip == stampNow_) continue;
        int n = 0;
        for (uint32_t v : w_.tris[t]) n += v == fan[1].u || v == fan[2].u;
        ok = ok && n < 2;
      }
    if (!ok) {
      ++stats_.rejectedTopology;
      return;
    }

    // Placement: the least-squares point of the merged quadric (on edges and corners of the
    // model), else the member where the quadric is least.
    Quadric q = w_.quad[C[0]];
    V3 mid = w_.pos[C[0]];
    double weight = w_.quad[C[0]].weight;
    for (size_t k = 1; k < nc; ++k) q += w_.quad[C[k]], mid = add(mid, w_.pos[C[k]]), weight += w_.quad[C[k]].weight;
    mid = scale(mid, 1.0 / double(nc));
    uint32_t survivor = C[0];
    double cost = q(w_.pos[C[0]]);
    for (size_t k = 1; k < nc; ++k) {
      const double ck = q(w_.pos[C[k]]);
      if (ck < cost) cost = ck, survivor = C[k];
    }
    V3 p = w_.pos[survivor];
    bool atMember = true;
    if (opt_.sharpFeatures) {
      const V3 x = q.minimiser(mid);
      double reach = grid_.voxel;
      for (uint32_t c : C) reach = std::max(reach, 2 * norm(sub(w_.pos[c], mid)));
      const double cx = q(x);
      bool inside = true;
      for (int k = 0; k < 3 && w_.confined; ++k) inside = inside && x[k] >= w_.regionLo[k] && x[k] <= w_.regionHi[k];
      if (norm(sub(x, mid)) <= reach && std::isfinite(cx) && cx <= cost) {
        if (inside)
          cost = cx, p = x, atMember = false;
        else
          for (uint32_t c : C) borderBound_[c] = 1;
      }
    }
    if (cost > tol_ * tol_ * weight) {
      ++stats_.rejectedError;
      return;
    }

    // Shape, as for an edge collapse: no fan triangle turns over or degenerates, and below the
    // quality bound the worst of the star does not get more than 10% worse.
    double worstBefore = worstQuality(gone), worstAfter = 1;
    for (const Fan& f : fan)
      if (!keepsFacing({f.c, f.u, f.w}, p, w_.pos[f.u], w_.pos[f.w], worstBefore, worstAfter)) {
        ++stats_.rejectedShape;
        return;
      }
    if (worstGotWorse(worstBefore, worstAfter)) {
      ++stats_.rejectedShape;
      return;
    }

    // Error: within the tolerance, or within the worst of the star's triangles (errorPasses).
    std::vector<LevelQuery>& qs = scratch_.queries;
    qs.assign(nf, {});
    for (size_t i = 0; i < nf; ++i) qs[i].a = p, qs[i].b = w_.pos[fan[i].u], qs[i].c = w_.pos[fan[i].w];
    std::vector<V3>& gonePoints = scratch_.gonePoints;
    gonePoints.clear();
    for (uint32_t c : C) gonePoints.push_back(w_.pos[c]);
    std::vector<uint32_t>& replaced = scratch_.replaced;
    replaced = gone;
    for (const Fan& f : fan) replaced.push_back(f.t);
    if (!errorPasses(qs, gonePoints, replaced)) {
      ++stats_.rejectedError;
      return;
    }

    // Apply: the survivor keeps its key (and normal) when the point is its own position.
    for (uint32_t t : gone) {
      tAlive_[t] = 0;
      for (uint32_t v : w_.tris[t]) {
        if (markA_[v] == inC) continue;
        auto& l = vtris_[v];
        l.erase(std::find(l.begin(), l.end(), t));
      }
    }
    auto& around = vtris_[survivor];
    around.clear();
    for (size_t i = 0; i < nf; ++i) {
      const Fan& f = fan[i];
      for (uint32_t& v : w_.tris[f.t])
        if (v == f.c) v = survivor;
      around.push_back(f.t);
      w_.level[f.t] = int8_t(qs[i].level);
      w_.made[f.t] = 1;
      madeNow_[f.t] = 1;
    }
    for (uint32_t c : C)
      if (c != survivor) alive_[c] = 0, vtris_[c].clear();
    if (!atMember) w_.moved[survivor] = 1;
    w_.pos[survivor] = p;
    qpos_[survivor] = quantise(p);
    w_.quad[survivor] = q;
    ++version_[survivor];
    stats_.collapses += nc - 1;
    w_.settled[survivor] = 0;
    for (const Fan& f : fan) unsettle(f.u, false);  // before the greedy phase: pushed at its start
  }

  // Self-intersection: the new triangles of collapsing a, b to p against each other, then
  // against every other triangle near them whose box meets theirs.
  bool noIntersection(uint32_t a, uint32_t b, const V3& p, const exact::P& qp, const std::vector<uint32_t>& changed,
                      const std::vector<uint32_t>& removed) {
    auto corner = [&](uint32_t v) { return v == a || v == b ? p : w_.pos[v]; };
    auto renamed = [&](const Tri& tr) {
      Tri r = tr;
      for (uint32_t& v : r)
        if (v == b) v = a;
      return r;
    };
    auto qcorner = [&](uint32_t v) { return v == a || v == b ? qp : qpos_[v]; };
    ++stampNow_;
    for (uint32_t t : changed) probe_[t].skip = stampNow_;
    for (uint32_t t : removed) probe_[t].skip = stampNow_;
    std::vector<NewTri>& fresh = freshTris_;
    fresh.clear();
    V3 ringLo{INFINITY, INFINITY, INFINITY}, ringHi{-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t t : changed) {
      const Tri& tr = w_.tris[t];
      NewTri n{renamed(tr), {qcorner(tr[0]), qcorner(tr[1]), qcorner(tr[2])}, corner(tr[0]), corner(tr[0]), {}, {}};
      for (int c = 1; c < 3; ++c)
        for (int k = 0; k < 3; ++k) n.lo[k] = std::min(n.lo[k], corner(tr[c])[k]), n.hi[k] = std::max(n.hi[k], corner(tr[c])[k]);
      for (int k = 0; k < 3; ++k) ringLo[k] = std::min(ringLo[k], n.lo[k]), ringHi[k] = std::max(ringHi[k], n.hi[k]);
      roundOut(n.lo, n.hi, n.flo, n.fhi);
      fresh.push_back(n);
    }
    for (size_t i = 0; i < fresh.size(); ++i)
      for (size_t j = i + 1; j < fresh.size(); ++j)
        if (improperPair(fresh[i].t, fresh[i].q, fresh[j].t, fresh[j].q)) return false;
    bool bad = false;
    ++probeNow_;
    // The cells the new triangles themselves may touch (as they would be filed): a triangle
    // meeting one of them improperly shares a point with it, so both are filed under that point's
    // cell. Fewer cells than the ring's box holds, when the ring is tilted or large.
    std::vector<uint64_t>& cellKeys = scratch_.cells;
    cellKeys.clear();
    for (uint32_t t : changed) {
      const Tri& tr = w_.tris[t];
      forTriangleCells(corner(tr[0]), corner(tr[1]), corner(tr[2]), [&](uint64_t k) { cellKeys.push_back(k); });
    }
    std::sort(cellKeys.begin(), cellKeys.end());
    cellKeys.erase(std::unique(cellKeys.begin(), cellKeys.end()), cellKeys.end());
    // Float comparisons against boxes rounded outwards: a superset of the pairs whose boxes
    // meet; the extra ones are apart by about the entries' margin, so the outcome is the same.
    float rlo[3], rhi[3];
    roundOut(ringLo, ringHi, rlo, rhi);
    for (size_t ci = 0; ci < cellKeys.size() && !bad; ++ci) {
      auto it = buckets_.find(cellKeys[ci]);
      if (it == buckets_.end()) continue;
      for (const Entry& e : it->second) {
        // Disjoint boxes: no contact, not even a shared vertex.
        if (e.hi[0] < rlo[0] || e.lo[0] > rhi[0] || e.hi[1] < rlo[1] || e.lo[1] > rhi[1] || e.hi[2] < rlo[2] ||
            e.lo[2] > rhi[2])
          continue;
        Probe& pr = probe_[e.tri];
        if (pr.skip == stampNow_ || pr.seen == probeNow_) continue;
        pr.seen = probeNow_;
        const Tri& tu = w_.tris[e.tri];
        std::array<exact::P, 3> qu;
        bool loaded = false;  // the corners only for a triangle whose box meets a new one's
        for (const NewTri& n : fresh) {
          if (e.hi[0] < n.flo[0] || e.lo[0] > n.fhi[0] || e.hi[1] < n.flo[1] || e.lo[1] > n.fhi[1] ||
              e.hi[2] < n.flo[2] || e.lo[2] > n.fhi[2])
            continue;
          if (!loaded) qu = {qpos_[tu[0]], qpos_[tu[1]], qpos_[tu[2]]}, loaded = true;
          if (improperPair(n.t, n.q, tu, qu)) {
            bad = true;
            break;
          }
        }
        if (bad) break;
      }
    }
    return !bad;
  }

  // ---- output -------------------------------------------------------------------------------
 public:
  // The mesh: vertices in the order of their keys (as the mesher orders them), triangles by
  // index triple rotated to start at the smallest.
  Mesh output(const MeshStats& stats) {
    const size_t nv = w_.pos.size();
    std::vector<uint32_t> order;
    for (uint32_t v = 0; v < nv; ++v)
      if (alive_[v] && !vtris_[v].empty()) order.push_back(v);
    std::sort(order.begin(), order.end(), [&](uint32_t x, uint32_t y) { return w_.key[x] != w_.key[y] ? w_.key[x] < w_.key[y] : x < y; });
    std::vector<uint32_t> index(nv, UINT32_MAX);
    Mesh out;
    out.stats = stats;
    GradientEvaluator grad;
    std::vector<double> x(std::max<uint32_t>(tape_->numVars(), 3)), g(x.size());
    for (uint32_t v : order) {
      index[v] = uint32_t(out.positions.size());
      out.positions.push_back(w_.pos[v]);
      out.keys.push_back(w_.key[v]);
      V3 n = w_.normal[v];
      V3 fan{0, 0, 0};  // area-weighted normal of the triangles around the vertex
      for (uint32_t t : vtris_[v]) {
        const Tri& tr = w_.tris[t];
        fan = add(fan, cross(sub(w_.pos[tr[1]], w_.pos[tr[0]]), sub(w_.pos[tr[2]], w_.pos[tr[0]])));
      }
      if (w_.moved[v] || dot(n, fan) <= 0) {
        // Outward = -grad f; at an edge or a corner of the model the gradient is one face's (or
        // undefined), and a kept vertex near a corner may now carry triangles of several faces:
        // then the fan's normal.
        for (uint32_t k = 0; k < x.size(); ++k) x[k] = k < 3 ? w_.pos[v][k] : opt_.fixedCoords[k - 3];
        grad.eval(*tape_, x.data(), g.data());
        V3 gn{-g[0], -g[1], -g[2]};
        double lg = norm(gn), lf = norm(fan);
        if (lg > 0 && std::isfinite(lg) && lf > 0 && dot(gn, fan) > 0.9 * lg * lf)
          n = scale(gn, 1 / lg);
        else if (lf > 0)
          n = scale(fan, 1 / lf);
      }
      out.normals.push_back(n);
    }
    for (uint32_t t = 0; t < w_.tris.size(); ++t) {
      if (!tAlive_[t]) continue;
      Tri r{index[w_.tris[t][0]], index[w_.tris[t][1]], index[w_.tris[t][2]]};
      canonicalRotate(r);
      out.triangles.push_back(r);
    }
    std::sort(out.triangles.begin(), out.triangles.end());
    return out;
  }

 private:

  Work w_;
  TapePtr tape_;
  GridSpec grid_;
  SimplifyOptions opt_;
  double tol_;
  SimplifyStats stats_;
  static constexpr size_t kPairsPerCall = BatchEvaluator<double>::kBatch / 2;
  size_t lanes_ = 0;                            // pairs written to the evaluator's inputs
  std::array<uint32_t, kPairsPerCall> laneQuery_{};  // whose each pair is
  std::vector<char> failed_;  // per query of levels()
  std::vector<double*> inputs_;  // the batch evaluator's input lanes, one array per coordinate
  struct Entry {
    uint32_t tri;
    float lo[3], hi[3];
  };
  struct Fan {  // a triangle of a contraction's star with one corner in the contracted set
    uint32_t t, c, u, w;  // triangle t = (c, u, w) in its winding, c in the set
  };
  struct Scratch {
    std::vector<uint32_t> opposite, changed, removed, ring;
    std::vector<int8_t> newLevel;
    std::vector<LevelQuery> queries, ownLevel;
    std::vector<uint64_t> cells;  // hash cells of the self-intersection check
    std::vector<std::pair<uint64_t, uint32_t>> filed;  // embedded(): (cell, triangle)
    std::vector<Entry> boxes;                          // embedded(): per triangle
    std::vector<uint32_t> cellsFrom;                   // embedded(): triangle t's cells in cells
    std::vector<uint32_t> bucketFrom, bucketFill;      // embedded(): hash buckets of filed
    std::vector<std::pair<uint64_t, uint32_t>> byBucket;
    std::vector<std::pair<uint64_t, uint32_t>> byCell;  // cell contractions
    std::vector<uint32_t> group, component, next, replaced;
    std::vector<V3> gonePoints;
    std::vector<Fan> fan;
  } scratch_;
  struct NewTri {  // a triangle as a collapse would leave it
    Tri t;
    std::array<exact::P, 3> q;  // quantised corners
    V3 lo, hi;                  // box
    float flo[3], fhi[3];       // the box rounded outwards to floats, like the entries' boxes
  };
  static void roundOut(const V3& lo, const V3& hi, float* flo, float* fhi) {
    for (int k = 0; k < 3; ++k)
      flo[k] = std::nextafter(float(lo[k]), -INFINITY), fhi[k] = std::nextafter(float(hi[k]), INFINITY);
  }
  std::vector<NewTri> freshTris_;
  std::vector<exact::P> qpos_;
  std::vector<char> alive_;
  std::vector<uint32_t> version_;
  std::vector<char> borderBound_;  // per vertex: an attempt's placement was cut off by the border
  // The triangles around each vertex: most have a dozen or fewer, held inline (no allocation
  // per vertex and per block).
  std::vector<boost::container::small_vector<uint32_t, 10>> vtris_;
  std::vector<char> tAlive_;
  // Per-triangle marks of the self-intersection queries.
  struct Probe {
    uint32_t skip = 0;  // == stampNow_: part of the collapse being checked
    uint32_t seen = 0;  // == probeNow_: already tested in this query
  };
  std::vector<Probe> probe_;
  uint32_t stampNow_ = 0, probeNow_ = 0;
  std::unordered_map<uint64_t, std::vector<Entry>> buckets_;
  // Per-vertex marks (link condition, ring): == the current mark means "in the set".
  std::vector<uint32_t> markA_, markB_;
  uint32_t mark_ = 0;
  uint32_t nextMark() { return ++mark_; }
  MinHeap<Candidate> queue_;
  BatchEvaluator<double> batch_;
  int maxLevel_ = 0;  // the last error level
  // e_k = tol * 2^k for every level a triangle can hold (int8_t): a level carried from a
  // worker's payload may exceed maxLevel_ (the decoder allows up to 15), and still counts.
  std::array<double, 128> levelTol_{};
  bool deferred_;
  std::vector<char> madeNow_;  // per triangle: made by a collapse of this run
};

// Simplifies w with the self-intersection check deferred to the end: collapses are made without
// it, then the result is checked once (Simplifier::embedded). A result that is not embedded is
// thrown away and w simplified again with the check at every collapse, so the outcome is still a
// function of w alone (split-invariance) and always embedded. The per-collapse check cost ~40%
// of the simplification and almost never rejects anything (docs/mesh.md).
// `input` makes w (called a second time for the rerun: no copy is kept for a rare event).
std::unique_ptr<Simplifier> simplifyChecked(const std::function<Work()>& input, const TapePtr& tape, const GridSpec& grid,
                                            const SimplifyOptions& opt, SimplifyStats& stats) {
  auto s = std::make_unique<Simplifier>(input(), tape, grid, opt, true);
  stats = s->run();
  if (s->embedded()) return s;
  const uint64_t spent = stats.modelEvals;
  s = std::make_unique<Simplifier>(input(), tape, grid, opt, false);
  stats = s->run();
  stats.modelEvals += spent;
  return s;
}

// The block passes' blocks (fixed in index space): edge and shift along each axis. The second
// pass's blocks are centred on the first's faces, where it left the rims. A third and a fourth
// pass, in the master only (simplifyMesh), of larger blocks: the third aligned with the first
// pass's (what the second leaves along its faces lies inside them), the fourth centred on the
// third's faces. Each pass (and the global one) skips the edges the run before it settled
// (Work::settled): the serial global pass mostly finishes along the fourth pass's faces.
constexpr int kBlockVoxels[4] = {32, 32, 64, 64};
constexpr int kBlockShift[4] = {0, 16, 0, 32};
constexpr int kWorkerPasses = 2;  // the passes simplifyRegion does in the bricks
// The shrunk block's margin: any gap between two blocks' boxes keeps their triangles apart (each
// block's stay inside its own box); a narrow one leaves narrow rims for the next pass (a quarter
// voxel: 44% fewer triangles reach the master's first pass than a whole voxel at 256^3).
constexpr double kBlockMarginVoxels = 0.25;
using BlockKey = std::array<int32_t, 3>;

// The cells of block b of pass `pass` along one axis, clipped to the grid's cells.
std::pair<int64_t, int64_t> blockCells(int32_t b, int pass, int64_t cells) {
  const int64_t lo = int64_t(b) * kBlockVoxels[pass] - kBlockShift[pass];
  return {std::max<int64_t>(0, lo), std::min(cells, lo + kBlockVoxels[pass])};
}

// Does the simplification of the region [lo, hi) of cells (simplifyRegion) do block b of
// `pass`? A first-pass block when its cells lie in the region; a second-pass block when, in
// addition, every first-pass block it meets does (so it sees the same mesh as it would after
// the whole first pass).
bool regionDoes(const BlockKey& b, int pass, const std::array<int64_t, 3>& lo, const std::array<int64_t, 3>& hi,
                const std::array<int64_t, 3>& cells) {
  for (int k = 0; k < 3; ++k) {
    auto [c0, c1] = blockCells(b[k], pass, cells[k]);
    if (c0 >= c1 || c0 < lo[k] || c1 > hi[k]) return false;
    if (pass == 1)
      for (int64_t cell : {c0, c1 - 1}) {
        auto [f0, f1] = blockCells(int32_t(cell / kBlockVoxels[0]), 0, cells[k]);
        if (f0 < lo[k] || f1 > hi[k]) return false;
      }
  }
  return true;
}

std::array<int64_t, 3> gridCells(const GridSpec& grid) {
  return {grid.dims[0] - 1, grid.dims[1] - 1, grid.dims[2] - 1};
}

// Did the farm's bricks of `brick` cells (simplifyRegion on each) do block b of `pass`? The
// brick holding the block's first cell decides.
bool bricksDid(const BlockKey& b, int pass, int brick, const std::array<int64_t, 3>& cells) {
  if (brick <= 0) return false;
  std::array<int64_t, 3> lo, hi;
  for (int k = 0; k < 3; ++k) {
    const int64_t c0 = blockCells(b[k], pass, cells[k]).first;
    lo[k] = c0 / brick * brick;
    hi[k] = std::min(cells[k], lo[k] + brick);
  }
  return regionDoes(b, pass, lo, hi, cells);
}

// A block pass, in parallel: the grid's index space, shifted by kBlockShift[pass], is cut into
// fixed blocks of kBlockVoxels[pass] (so the cut does not depend on the farm's bricks). A vertex
// belongs to its block if it and every neighbour lie inside the block shrunk by kBlockMarginVoxels; each
// block simplifies the triangles around its own vertices, with the other vertices locked,
// placements confined to the shrunk block, and every other triangle meeting it as a fixed
// obstacle. Those triangles are never changed by another block (each block's triangles stay
// inside its own shrunk box), so the blocks are independent: the result does not depend on the
// thread count or the order.
// Only the blocks `mine` accepts are done.
void blockPass(Work& g, const TapePtr& tape, const GridSpec& grid, const SimplifyOptions& opt, int pass,
               const std::function<bool(const BlockKey&)>& mine, SimplifyStats& stats) {
  const size_t nv = g.pos.size(), nt = g.tris.size();
  if (g.settled.size() != nv) g.settled.assign(nv, 0);
  const double side = kBlockVoxels[pass] * grid.voxel, margin = kBlockMarginVoxels * grid.voxel;
  V3 origin;
  for (int k = 0; k < 3; ++k) origin[k] = grid.origin[k] - kBlockShift[pass] * grid.voxel;
  auto blockOf = [&](const V3& p) {
    BlockKey b;
    for (int k = 0; k < 3; ++k) b[k] = int32_t(std::floor((p[k] - origin[k]) / side));
    return b;
  };
  auto shrunk = [&](const BlockKey& b, V3& lo, V3& hi) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = origin[k] + b[k] * side + margin;
      hi[k] = origin[k] + (b[k] + 1) * side - margin;
    }
  };
  auto inside = [](const V3& p, const V3& lo, const V3& hi) {
    return p[0] > lo[0] && p[0] < hi[0] && p[1] > lo[1] && p[1] < hi[1] && p[2] > lo[2] && p[2] < hi[2];
  };
  // The blocks this pass does (those `mine` accepts among the vertices' blocks): none, nothing
  // to set up (e.g. the master's first pass when the bricks did every block).
  std::vector<BlockKey> vblock(nv);
  std::vector<BlockKey> blocks;
  for (uint32_t v = 0; v < nv; ++v) {
    vblock[v] = blockOf(g.pos[v]);
    if (blocks.empty() || blocks.back() != vblock[v]) blocks.push_back(vblock[v]);  // runs: key order is local
  }
  std::sort(blocks.begin(), blocks.end());
  blocks.erase(std::unique(blocks.begin(), blocks.end()), blocks.end());
  blocks.erase(std::remove_if(blocks.begin(), blocks.end(), [&](const BlockKey& b) { return !mine(b); }), blocks.end());
  if (blocks.empty()) {
    if (opt.progress) opt.progress(pass, 0, 0);
    return;
  }
  auto blockIndex = [&](const BlockKey& b) -> int64_t {
    auto it = std::lower_bound(blocks.begin(), blocks.end(), b);
    return it != blocks.end() && *it == b ? it - blocks.begin() : -1;
  };
  // Triangles around each vertex, flat (offsets into one array).
  std::vector<uint32_t> vtStart(nv + 1, 0), vtList(3 * nt);
  for (const Tri& tr : g.tris)
    for (uint32_t v : tr) ++vtStart[v + 1];
  for (size_t v = 0; v < nv; ++v) vtStart[v + 1] += vtStart[v];
  {
    std::vector<uint32_t> fill(vtStart.begin(), vtStart.end() - 1);
    for (uint32_t t = 0; t < nt; ++t)
      for (uint32_t v : g.tris[t]) vtList[fill[v]++] = t;
  }
  // Owned vertices by block, in increasing order (the write-back order is fixed).
  std::vector<std::vector<uint32_t>> owned(blocks.size());
  BlockKey lastKey = vblock.empty() ? BlockKey{} : vblock[0];
  int64_t last = vblock.empty() ? -1 : blockIndex(lastKey);
  for (uint32_t v = 0; v < nv; ++v) {
    if (vtStart[v] == vtStart[v + 1]) continue;
    if (vblock[v] != lastKey) lastKey = vblock[v], last = blockIndex(lastKey);  // runs, as above
    const int64_t b = last;
    if (b < 0) continue;
    V3 lo, hi;
    shrunk(blocks[size_t(b)], lo, hi);
    bool ok = true;
    for (uint32_t i = vtStart[v]; i < vtStart[v + 1] && ok; ++i)
      for (uint32_t u : g.tris[vtList[i]]) ok = ok && inside(g.pos[u], lo, hi);
    if (ok) owned[size_t(b)].push_back(v);
  }
  // Obstacle candidates: every triangle under each block its box meets (increasing order).
  std::vector<std::vector<uint32_t>> near(blocks.size());
  for (uint32_t t = 0; t < nt; ++t) {
    V3 lo = g.pos[g.tris[t][0]], hi = lo;
    for (uint32_t v : g.tris[t])
      for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], g.pos[v][k]), hi[k] = std::max(hi[k], g.pos[v][k]);
    BlockKey a = blockOf(lo), b = blockOf(hi);
    for (int32_t x = a[0]; x <= b[0]; ++x)
      for (int32_t y = a[1]; y <= b[1]; ++y)
        for (int32_t z = a[2]; z <= b[2]; ++z) {
          const int64_t i = blockIndex({x, y, z});
          if (i >= 0) near[size_t(i)].push_back(t);
        }
  }

  // A block writes its own vertices' new state into g at once (no other block reads them) and
  // keeps its new triangles, appended afterwards in block order.
  struct Result {
    std::vector<Tri> tris;  // global vertex ids
    std::vector<int8_t> level;
    std::vector<char> made;
    SimplifyStats stats;
  };
  std::vector<Result> results(blocks.size());
  std::vector<char> vAlive(nv, 1), tAlive(nt, 1);
  // activeIn[t]: the block one of whose own vertices t has (a triangle with an owned vertex lies
  // in that block's shrunk box, so it is one block's only: each entry has one writer). Other
  // blocks read it to skip their own active triangles among the obstacles: the entry equals
  // their index exactly when they wrote it (relaxed atomics: a concurrent write by the entry's
  // one writer is another block's index either way).
  std::unique_ptr<std::atomic<uint32_t>[]> activeIn(new std::atomic<uint32_t>[nt]);
  for (size_t t = 0; t < nt; ++t) activeIn[t].store(UINT32_MAX, std::memory_order_relaxed);
  auto solve = [&](size_t i) {
    const BlockKey& b = blocks[i];
    // This block run's tag (Work::settled): neighbouring blocks' differ.
    const uint32_t tag = 1 + uint32_t(pass) + 4 * (uint32_t(b[0] & 511) | uint32_t(b[1] & 511) << 9 | uint32_t(b[2] & 511) << 18);
    Result& r = results[i];
    const std::vector<uint32_t>& own = owned[i];
    if (own.empty()) return;
    std::vector<uint32_t> active, globalOf;  // the block's triangles; local vertex -> global
    for (uint32_t v : own)
      for (uint32_t k = vtStart[v]; k < vtStart[v + 1]; ++k)
        if (activeIn[vtList[k]].load(std::memory_order_relaxed) != i)
          activeIn[vtList[k]].store(uint32_t(i), std::memory_order_relaxed), active.push_back(vtList[k]);
    std::sort(active.begin(), active.end());
    V3 lo, hi;
    shrunk(b, lo, hi);
    std::vector<uint32_t> obstacles;
    for (uint32_t t : near[i]) {
      if (activeIn[t].load(std::memory_order_relaxed) == i) continue;  // active here
      V3 tl = g.pos[g.tris[t][0]], th = tl;
      for (uint32_t v : g.tris[t])
        for (int k = 0; k < 3; ++k) tl[k] = std::min(tl[k], g.pos[v][k]), th[k] = std::max(th[k], g.pos[v][k]);
      if (th[0] >= lo[0] && tl[0] <= hi[0] && th[1] >= lo[1] && tl[1] <= hi[1] && th[2] >= lo[2] && tl[2] <= hi[2])
        obstacles.push_back(t);
    }
    // global -> local by a per-thread table (every entry back to "none" after the block); local
    // numbers in increasing global order
    thread_local std::vector<uint32_t> localOf;
    if (localOf.size() < nv) localOf.resize(nv, UINT32_MAX);
    for (const std::vector<uint32_t>* list : {&active, &obstacles})
      for (uint32_t t : *list)
        for (uint32_t v : g.tris[t])
          if (localOf[v] == UINT32_MAX) localOf[v] = 0, globalOf.push_back(v);
    std::sort(globalOf.begin(), globalOf.end());
    for (uint32_t i = 0; i < globalOf.size(); ++i) localOf[globalOf[i]] = i;
    auto local = [&](uint32_t v) { return localOf[v]; };
    auto input = [&] {
      Work w;
      const size_t n = globalOf.size(), m = active.size() + obstacles.size();
      w.pos.reserve(n), w.normal.reserve(n), w.key.reserve(n), w.quad.reserve(n), w.moved.reserve(n), w.locked.reserve(n);
      w.settled.reserve(n);
      w.tris.reserve(m), w.level.reserve(m), w.made.reserve(m);
      size_t at = 0;  // own is sorted: a merge walk marks the locked vertices
      for (uint32_t v : globalOf) {
        w.pos.push_back(g.pos[v]);
        w.normal.push_back(g.normal[v]);
        w.key.push_back(g.key[v]);
        w.quad.push_back(g.quad[v]);
        w.moved.push_back(g.moved[v]);
        w.settled.push_back(g.settled[v]);
        while (at < own.size() && own[at] < v) ++at;
        w.locked.push_back(!(at < own.size() && own[at] == v));
      }
      for (const std::vector<uint32_t>* list : {&active, &obstacles})
        for (uint32_t t : *list) {
          w.tris.push_back({local(g.tris[t][0]), local(g.tris[t][1]), local(g.tris[t][2])});
          w.level.push_back(g.level[t]);
          w.made.push_back(g.made[t]);
        }
      w.confined = true;
      w.regionLo = lo;
      w.regionHi = hi;
      return w;
    };
    std::unique_ptr<Simplifier> simplified = simplifyChecked(input, tape, grid, opt, r.stats);
    for (uint32_t v : globalOf) localOf[v] = UINT32_MAX;
    const Simplifier& s = *simplified;
    const Work& out = s.work();
    for (uint32_t i = 0; i < globalOf.size(); ++i) {
      if (out.locked[i]) continue;
      const uint32_t v = globalOf[i];
      vAlive[v] = s.vertexAlive(i);
      g.pos[v] = out.pos[i];
      g.normal[v] = out.normal[i];
      g.key[v] = out.key[i];
      g.quad[v] = out.quad[i];
      g.moved[v] = out.moved[i];
      // The block's collapses ran out around its own vertices (a rerun with the per-collapse
      // intersection check settles none: its rejections depend on more than the star).
      g.settled[v] = s.settles() && !s.borderBound(i) ? tag : 0;
    }
    for (uint32_t t : active) tAlive[t] = 0;
    for (uint32_t t = 0; t < active.size(); ++t) {  // the active triangles come first
      if (!s.triangleAlive(t)) continue;
      const Tri& tr = out.tris[t];
      r.tris.push_back({globalOf[tr[0]], globalOf[tr[1]], globalOf[tr[2]]});
      r.level.push_back(out.level[t]);
      r.made.push_back(out.made[t]);
    }
  };
  std::atomic<uint64_t> solved{0};
  if (opt.progress) opt.progress(pass, 0, blocks.size());
  parallelChunks(blocks.size(), 1, opt.threads, [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) {
      solve(i);
      if (opt.progress) opt.progress(pass, ++solved, blocks.size());
    }
  });

  for (Result& r : results) {
    g.tris.insert(g.tris.end(), r.tris.begin(), r.tris.end());
    g.level.insert(g.level.end(), r.level.begin(), r.level.end());
    g.made.insert(g.made.end(), r.made.begin(), r.made.end());
    tAlive.resize(g.tris.size(), 1);
    stats += r.stats;
    r = Result();
  }
  // Compact to the canonical form every pass starts from (vertices by key, triangles rotated
  // to their smallest index and sorted): a pass then sees the same numbering whether the passes
  // before it ran here or in the workers, region by region.
  std::vector<uint32_t> alive, index(nv, UINT32_MAX);
  for (uint32_t v = 0; v < nv; ++v)
    if (vAlive[v]) alive.push_back(v);
  parallelSort(alive.begin(), alive.end(), [&](uint32_t x, uint32_t y) { return g.key[x] != g.key[y] ? g.key[x] < g.key[y] : x < y; },
               opt.threads);  // a total order: the same for any thread count
  Work c;
  c.pos.reserve(alive.size()), c.normal.reserve(alive.size()), c.key.reserve(alive.size()), c.quad.reserve(alive.size());
  c.moved.reserve(alive.size()), c.locked.reserve(alive.size()), c.settled.reserve(alive.size());
  for (uint32_t v : alive) {
    index[v] = uint32_t(c.pos.size());
    c.pos.push_back(g.pos[v]);
    c.normal.push_back(g.normal[v]);
    c.key.push_back(g.key[v]);
    c.quad.push_back(g.quad[v]);
    c.moved.push_back(g.moved[v]);
    c.locked.push_back(0);
    c.settled.push_back(g.settled[v]);
  }
  std::vector<std::pair<Tri, uint32_t>> order;  // canonical triangle, old index
  order.reserve(g.tris.size());
  for (uint32_t t = 0; t < g.tris.size(); ++t) {
    if (!tAlive[t]) continue;
    Tri r{index[g.tris[t][0]], index[g.tris[t][1]], index[g.tris[t][2]]};
    canonicalRotate(r);
    order.push_back({r, t});
  }
  parallelSort(order.begin(), order.end(), std::less<>(), opt.threads);  // triangles are distinct: a total order
  c.tris.reserve(order.size()), c.level.reserve(order.size()), c.made.reserve(order.size());
  for (const auto& [r, t] : order) {
    c.tris.push_back(r);
    c.level.push_back(g.level[t]);
    c.made.push_back(g.made[t]);
  }
  g = std::move(c);
}

}  // namespace

SimplifyStats simplifyMesh(Mesh& mesh, const TapePtr& tape, const GridSpec& grid, const SimplifyOptions& options) {
  SimplifyStats stats;
  stats.trianglesBefore = stats.trianglesAfter = mesh.triangles.size() + 2 * mesh.carry.counters.collapses;
  if (!(options.tolerance > 0) || mesh.triangles.empty()) return stats;
  Work w = workOf(std::move(mesh), options.threads);
  stats += mesh.carry.counters;  // the regions' share (simplifyRegion in the workers)
  mesh.carry = SimplifyCarry();
  // Four block passes (kBlockVoxels), each centred on what the one before left along its block
  // faces; the global pass finishes the rest. Blocks the bricks' own simplification did are
  // skipped (the result is the same).
  const std::array<int64_t, 3> cells = gridCells(grid);
  for (int pass = 0; pass < kWorkerPasses; ++pass) {
    // Bricks of whole first-pass blocks did every first-pass block: nothing to look for.
    const int brick = options.bricksSimplified;
    if (pass == 0 && kBlockShift[0] == 0 && brick > 0 && brick % kBlockVoxels[0] == 0) {
      if (options.progress) options.progress(pass, 0, 0);
      continue;
    }
    blockPass(w, tape, grid, options, pass, [&](const BlockKey& b) { return !bricksDid(b, pass, brick, cells); }, stats);
  }
  for (int pass = kWorkerPasses; pass < 4; ++pass) blockPass(w, tape, grid, options, pass, [](const BlockKey&) { return true; }, stats);
  SimplifyStats s2;
  std::unique_ptr<Simplifier> second = simplifyChecked([&w] { return w; }, tape, grid, options, s2);
  stats += s2;
  stats.errorBound = s2.errorBound;  // over every triangle a collapse made, in either pass
  mesh = second->output(mesh.stats);
  stats.trianglesAfter = mesh.triangles.size();
  return stats;
}

void simplifyRegion(MeshPiece& piece, const TapePtr& tape, const GridSpec& grid, const SimplifyOptions& options,
                    const std::array<int32_t, 3>& lo, const std::array<int32_t, 3>& hi) {
  if (!(options.tolerance > 0) || piece.triangles.empty()) return;
  Mesh m;  // the piece as a mesh: its vertices are in key order, its triangles canonical
  m.positions.reserve(piece.vertices.size()), m.normals.reserve(piece.vertices.size()), m.keys.reserve(piece.vertices.size());
  for (const MeshVertex& v : piece.vertices) {
    m.positions.push_back(v.position);
    m.normals.push_back(v.normal);
    m.keys.push_back(v.key);
  }
  m.triangles = std::move(piece.triangles);
  m.carry = std::move(piece.carry);
  Work w = workOf(std::move(m), options.threads);
  SimplifyStats stats;
  const std::array<int64_t, 3> cells = gridCells(grid), rlo{lo[0], lo[1], lo[2]}, rhi{hi[0], hi[1], hi[2]};
  for (int pass = 0; pass < kWorkerPasses; ++pass)
    blockPass(w, tape, grid, options, pass, [&](const BlockKey& b) { return regionDoes(b, pass, rlo, rhi, cells); }, stats);
  piece.vertices.clear();
  for (size_t v = 0; v < w.pos.size(); ++v) piece.vertices.push_back({w.key[v], w.pos[v], w.normal[v]});
  SimplifyCarry& c = piece.carry;
  carryOf(w, c);
  piece.triangles = std::move(w.tris);
  c.counters += stats;
}

}  // namespace frep
