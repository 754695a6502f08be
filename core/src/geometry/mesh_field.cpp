// Signed distance to a triangle mesh (Choporov-Hybrid eq. 8-9: dist = min over the triangles of
// the distance to each, f = sign * dist as eq. 1-3): exact closest point on triangles through a
// BVH instead of the paper's scan of every triangle; sign from the closest feature's
// angle-weighted pseudonormal on closed meshes and from the generalised winding number on open
// ones, instead of the ray parity of eq. 7 (distance_fields.h).
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <utility>
#include <vector>

#include "frep/geometry/distance_fields.h"
#include "geometry/mesh_topology.h"

namespace frep {

namespace {
inline void sub(const double* a, const double* b, double* r) { r[0] = a[0] - b[0], r[1] = a[1] - b[1], r[2] = a[2] - b[2]; }
inline double dot(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline void cross(const double* a, const double* b, double* r) {
  r[0] = a[1] * b[2] - a[2] * b[1];
  r[1] = a[2] * b[0] - a[0] * b[2];
  r[2] = a[0] * b[1] - a[1] * b[0];
}

// Closest point on triangle abc to p (the Voronoi-region walk of real-time collision
// detection texts). region: 0 face, 1..3 vertex a/b/c, 4..6 edge ab/bc/ca.
double triangleDist2(const double* p, const double* a, const double* b, const double* c, double* q, int& region) {
  double ab[3], ac[3], ap[3], bp[3], cp[3];
  sub(b, a, ab), sub(c, a, ac), sub(p, a, ap);
  auto set = [&](const double* base, double s, const double* dir, int reg) {
    for (int k = 0; k < 3; ++k) q[k] = base[k] + s * (dir ? dir[k] : 0.0);
    region = reg;
  };
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) set(a, 0, nullptr, 1);
  else {
    sub(p, b, bp);
    const double d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) set(b, 0, nullptr, 2);
    else {
      const double vc = d1 * d4 - d3 * d2;
      if (vc <= 0 && d1 >= 0 && d3 <= 0) set(a, d1 / (d1 - d3), ab, 4);
      else {
        sub(p, c, cp);
        const double d5 = dot(ab, cp), d6 = dot(ac, cp);
        if (d6 >= 0 && d5 <= d6) set(c, 0, nullptr, 3);
        else {
          const double vb = d5 * d2 - d1 * d6;
          if (vb <= 0 && d2 >= 0 && d6 <= 0) set(a, d2 / (d2 - d6), ac, 6);
          else {
            const double va = d3 * d6 - d5 * d4;
            if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
              double bc[3];
              sub(c, b, bc);
              set(b, (d4 - d3) / ((d4 - d3) + (d5 - d6)), bc, 5);
            } else {
              const double den = 1.0 / (va + vb + vc);
              const double v = vb * den, w = vc * den;
              for (int k = 0; k < 3; ++k) q[k] = a[k] + ab[k] * v + ac[k] * w;
              region = 0;
            }
          }
        }
      }
    }
  }
  double d[3];
  sub(p, q, d);
  return dot(d, d);
}

// A cell's candidate list (cellCandidates): per candidate its slot, its key and its linear
// lower bound's unit direction and base, as floats.
constexpr uint32_t kCandidateWords = 6;
uint32_t candidateSlot(const uint32_t* list, uint32_t i) { return list[kCandidateWords * i]; }
double candidateKey(const uint32_t* list, uint32_t i) { return double(floatOfBits(list[kCandidateWords * i + 1])); }
// A lower bound of |p - T| for candidate i, pc = p - c and fromCentre >= |pc|: T lies in the
// half-space n . (x - q) <= 0 (q: T's nearest point to c, n: the unit vector from q to c), so
// |p - T| >= n . (p - q) = |c - q| + n . pc, tight where p moves along the cell's surface rather
// than towards it (the key's |c - T| - |pc| is not). The base carries the slack for q's and n's
// rounding; 1e-7 |pc| covers n rounded to float.
double linearGap(const uint32_t* list, uint32_t i, const double* pc, double fromCentre) {
  const uint32_t* e = &list[kCandidateWords * i];
  const double n0 = floatOfBits(e[2]), n1 = floatOfBits(e[3]), n2 = floatOfBits(e[4]), base = floatOfBits(e[5]);
  return base + (n0 * pc[0] + n1 * pc[1] + n2 * pc[2]) - 1e-7 * fromCentre;
}

void normalise(double* v) {
  const double l = std::sqrt(dot(v, v));
  if (l > 0) v[0] /= l, v[1] /= l, v[2] /= l;
}
}  // namespace

MeshField::MeshField(std::vector<double> xyz, std::vector<uint32_t> tris, std::string name) : name_(std::move(name)) {
  if (tris.empty() || tris.size() % 3 != 0) throw std::invalid_argument("the mesh has no triangles");
  const size_t nv = xyz.size() / 3;
  for (uint32_t i : tris)
    if (i >= nv) throw std::invalid_argument("a triangle refers to vertex " + std::to_string(i + 1) + " of " + std::to_string(nv));
  // Weld equal coordinates (STL stores each triangle's corners separately).
  const std::vector<uint32_t> remapV = mesh_topology::weldVertices(xyz, xyz_);
  for (size_t t = 0; t < tris.size(); t += 3) {
    const uint32_t a = remapV[tris[t]], b = remapV[tris[t + 1]], c = remapV[tris[t + 2]];
    if (a == b || b == c || c == a) {
      ++check_.degenerateTriangles;
      continue;
    }
    tris_.insert(tris_.end(), {a, b, c});
  }
  if (tris_.empty()) throw std::invalid_argument("every triangle of the mesh is degenerate");
  const mesh_topology::EdgeUses edges = mesh_topology::edgeUsesOf(tris_);
  orientConsistently(edges);
  // An inside-out mesh (clockwise seen from outside) would make every sign wrong: orient it so
  // that the enclosed volume is positive.
  if (volume() < 0.0)
    for (size_t t = 0; t < tris_.size(); t += 3) std::swap(tris_[t + 1], tris_[t + 2]);
  const size_t nt = tris_.size() / 3;
  faceN_.assign(3 * nt, 0.0);
  vertN_.assign(xyz_.size(), 0.0);
  triEdge_.resize(3 * nt);
  std::vector<Bvh::Box> boxes(nt);
  for (size_t t = 0; t < nt; ++t) {
    const double* v[3] = {&xyz_[3 * tris_[3 * t]], &xyz_[3 * tris_[3 * t + 1]], &xyz_[3 * tris_[3 * t + 2]]};
    double e1[3], e2[3], n[3];
    sub(v[1], v[0], e1), sub(v[2], v[0], e2), cross(e1, e2, n);
    normalise(n);
    for (int k = 0; k < 3; ++k) faceN_[3 * t + k] = n[k];
    for (int c = 0; c < 3; ++c) {
      // Angle-weighted vertex pseudonormal.
      double u[3], w[3];
      sub(v[(c + 1) % 3], v[c], u), sub(v[(c + 2) % 3], v[c], w);
      normalise(u), normalise(w);
      const double ang = std::acos(std::max(-1.0, std::min(1.0, dot(u, w))));
      for (int k = 0; k < 3; ++k) vertN_[3 * tris_[3 * t + c] + k] += ang * n[k];
    }
    for (int k = 0; k < 3; ++k) {
      boxes[t].lo[k] = std::min({v[0][k], v[1][k], v[2][k]});
      boxes[t].hi[k] = std::max({v[0][k], v[1][k], v[2][k]});
    }
  }
  // One edge per key, numbered in key order; its pseudonormal sums its triangles' normals in
  // triangle order. A flip may have moved a use's corner: the triangle's corner that runs along
  // the key is the one.
  edges.forEachEdge([&](size_t first, size_t last) {
    const uint64_t key = edges.key[first];
    const size_t e = edgeN_.size() / 3;
    edgeN_.insert(edgeN_.end(), {0.0, 0.0, 0.0});
    for (size_t j = first; j < last; ++j) {
      const size_t t = edges.use[j] / 3;
      for (size_t c = 0; c < 3; ++c)
        if (mesh_topology::edgeKey(tris_[3 * t + c], tris_[3 * t + (c + 1) % 3]) == key) triEdge_[3 * t + c] = uint32_t(e);
      for (int k = 0; k < 3; ++k) edgeN_[3 * e + k] += faceN_[3 * t + k];
    }
    if (last - first == 1) {
      ++check_.openEdges;
      if (check_.firstOpen.size() < 5) check_.firstOpen.push_back({uint32_t(key >> 32), uint32_t(key)});
    } else if (last - first > 2) {
      ++check_.nonManifoldEdges;
    }
  });
  bvh_.build(boxes);
  // Each triangle's corners in one block, in the hierarchy's leaf order: a query reads the
  // triangles of a leaf from consecutive memory.
  corners_.resize(9 * nt);
  slotPlanes_.resize(4 * nt);
  for (size_t slot = 0; slot < nt; ++slot) {
    const size_t t = bvh_.order()[slot];
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k) corners_[9 * slot + 3 * c + k] = xyz_[3 * tris_[3 * t + c] + k];
    double* pl = &slotPlanes_[4 * slot];
    for (int k = 0; k < 3; ++k) pl[k] = faceN_[3 * t + k];  // zero for a degenerate triangle
    pl[3] = dot(pl, &corners_[9 * slot]);
  }
  // The candidate lattice: 64 cells along the mesh's longest extent, and a margin of 16 cells
  // (queries come from around the mesh too). Finer cells have shorter lists but more of them
  // to build: bunny (+) ball meshed at 16^3 / 32^3 / 64^3 / 128^3 took 0.43 / 0.67 / 0.82 /
  // 1.57 s with 128 cells, 0.28 / 0.42 / 0.75 / 1.68 s with 64 (32: 0.23 / 0.54 / 0.87 / 2.48).
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i < xyz_.size(); ++i) lo[i % 3] = std::min(lo[i % 3], xyz_[i]), hi[i % 3] = std::max(hi[i % 3], xyz_[i]);
  lattice_ = CellLattice::over(lo, hi, 64, 16);
  scale_ = std::max({std::abs(lo[0]), std::abs(lo[1]), std::abs(lo[2]), std::abs(hi[0]), std::abs(hi[1]), std::abs(hi[2]),
                     hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  uint64_t h = 0xcbf29ce484222325ULL;
  for (double d : xyz_) {
    uint64_t b;
    std::memcpy(&b, &d, sizeof b);
    h = (h ^ b) * 0x100000001b3ULL;
  }
  for (uint32_t i : tris_) h = (h ^ i) * 0x100000001b3ULL;
  hash_ = h;
}

void MeshField::orientConsistently(const mesh_topology::EdgeUses& edges) {
  // Breadth-first over triangles joined by manifold edges: a neighbour that runs a shared edge in
  // the same direction is flipped (patches or STL files with mixed windings).
  const size_t nt = tris_.size() / 3;
  // across[3 t + c]: the other triangle of the edge from corner c to c + 1 of t as given, when
  // that edge has two uses (a manifold edge).
  std::vector<uint32_t> across(3 * nt, UINT32_MAX);
  edges.forEachEdge([&](size_t first, size_t last) {
    if (last - first != 2) return;
    across[edges.use[first]] = edges.use[first + 1] / 3;
    across[edges.use[first + 1]] = edges.use[first] / 3;
  });
  auto runs = [&](uint32_t t, uint32_t a, uint32_t b) {  // does t have the directed edge a->b?
    for (int c = 0; c < 3; ++c)
      if (tris_[3 * t + c] == a && tris_[3 * t + (c + 1) % 3] == b) return true;
    return false;
  };
  std::vector<char> seen(nt, 0), flipped(nt, 0);
  std::vector<uint32_t> queue;
  for (uint32_t start = 0; start < nt; ++start) {
    if (seen[start]) continue;
    seen[start] = 1;
    queue.assign(1, start);
    for (size_t q = 0; q < queue.size(); ++q) {
      const uint32_t t = queue[q];
      for (int c = 0; c < 3; ++c) {
        const uint32_t a = tris_[3 * t + c], b = tris_[3 * t + (c + 1) % 3];
        // Corner c of a flipped (a, c', b') is the edge given from corner 2 - c of (a, b', c').
        const uint32_t u = across[3 * size_t(t) + size_t(flipped[t] ? 2 - c : c)];
        if (u == UINT32_MAX || seen[u]) continue;
        seen[u] = 1;
        if (runs(u, a, b)) std::swap(tris_[3 * u + 1], tris_[3 * u + 2]), flipped[u] = 1;
        queue.push_back(u);
      }
    }
  }
}

// Nearest-triangle queries. The answer is canonical: the least squared distance as computed by
// triangleDist2, and among triangles at exactly that distance the one of the lowest slot. So
// every way of finding it below (a warm start, the plane test, a cell's candidates, the whole
// hierarchy) gives the same triangle, whatever the order of queries or the thread.
namespace {
// This thread's previous nearest triangle on a mesh (queries come in nearby runs: a brick's
// points, a triangle's error samples), keyed by the field's id (an address may be reused).
struct WarmTriangle {
  uint64_t field = 0;
  uint32_t slot = 0;
};
thread_local WarmTriangle tWarm;
std::atomic<bool> gCandidateCells{true};
constexpr uint32_t kMaxCandidates = 48;
}  // namespace

// The best so far, by the canonical order; `found` false: only triangles below best2 count.
struct MeshField::Nearest {
  double best2;
  uint32_t slot = UINT32_MAX;
  int region = 0;
  double q[3] = {0, 0, 0};
  bool found = false;
};

void MeshField::useCandidateCells(bool on) { gCandidateCells = on; }

// A lower bound of p's distance to triangle `slot`: its distance to the triangle's plane, less
// a slack for the plane's rounding (so every triangle that could tie stays in).
inline double MeshField::planeGap(const double* p, uint32_t slot) const {
  const double* pl = &slotPlanes_[4 * size_t(slot)];
  const double slack = 1e-13 * (std::abs(p[0]) + std::abs(p[1]) + std::abs(p[2]) + std::abs(pl[3]));
  return std::abs(dot(pl, p) - pl[3]) - slack;
}

// Offers triangle `slot` to n: skipped when its plane is farther than the best, else measured.
inline void MeshField::offer(const double* p, uint32_t slot, Nearest& n) const {
  const double h = planeGap(p, slot);
  if (h > 0 && h * h > n.best2 * (1 + 1e-9)) return;
  double qq[3];
  int region;
  const double* c = &corners_[9 * size_t(slot)];
  const double d2 = triangleDist2(p, c, c + 3, c + 6, qq, region);
  const bool better = n.found ? d2 < n.best2 || (d2 == n.best2 && slot < n.slot)
                              : d2 < n.best2 || n.best2 == std::numeric_limits<double>::infinity();
  if (!better) return;
  n.best2 = d2, n.slot = slot, n.region = region, n.found = true;
  n.q[0] = qq[0], n.q[1] = qq[1], n.q[2] = qq[2];
}

// The whole hierarchy: every leaf within the best distance so far (inclusive: ties are seen).
void MeshField::searchAll(const double* p, Nearest& n) const {
  bvh_.nearAll(p, [&](uint32_t slot, uint32_t) { offer(p, slot, n); }, n.best2);
}

// The candidates of the lattice cell holding p: every triangle that can be nearest to some
// point of the cell. With c the cell's centre and T_c its nearest triangle, any point of the
// cell is within U = |c - T_c| + half the cell's diagonal of T_c, so a triangle farther than U
// from the whole cell (by its box, its plane or its distance from c less half the diagonal) is
// never nearest there, nor tied. Nothing when p is outside the lattice or the cell has too
// many candidates. The list holds per candidate (kCandidateWords) its slot, key |c - T| as
// float bits rounded down and linearGap's bound, sorted by key: a query at p stops at the first
// key with key - |p - c| beyond its best distance (nearestTriangle), as |p - T| >= |c - T| -
// |p - c|, and skips those whose linear bound is beyond it. count: the candidates; fromCentre:
// |p - c| rounded up, with margins for its rounding and for p placed in the cell from a few
// ulps outside; centreValue: f(c) with its magnitude rounded down (0 on an open mesh: no
// sign), kept in a header pair before the list (offsetClass: a point nearer c than |f(c)| has
// c's class). pc: p - c (linearGap).
const uint32_t* MeshField::cellCandidates(const double* p, uint32_t& count, double& fromCentre, double& centreValue,
                                          double* pc) const {
  uint64_t key;
  int64_t ijk[3];
  if (!lattice_.cellOf(p, key, ijk)) return nullptr;
  Bvh::Box box;
  lattice_.cellBox(ijk, box.lo, box.hi);
  double centre[3];
  for (int k = 0; k < 3; ++k) centre[k] = 0.5 * (box.lo[k] + box.hi[k]);
  sub(p, centre, pc);
  fromCentre = std::sqrt(dot(pc, pc)) * (1 + 1e-9) + 1e-12 * scale_;
  const uint32_t* list = CellLists::get(id_, key, count, [&](std::vector<uint32_t>& out) {
    const double cellSize = lattice_.size;
    Nearest c{std::numeric_limits<double>::infinity()};
    // Seeded by this thread's last nearest triangle (a query nearby), a little above its
    // distance so that the nearest and its ties still count: only best2 is read, the same
    // whatever the seed.
    if (tWarm.field == id_) {
      double qq[3];
      int region;
      const double* v = &corners_[9 * size_t(tWarm.slot)];
      c.best2 = triangleDist2(centre, v, v + 3, v + 6, qq, region) * (1 + 2e-9) + 1e-300;
    }
    searchAll(centre, c);
    // A cell far from the mesh (its reach a sphere over many triangles) is left to the
    // hierarchy: only cells within a few of their sizes of the surface are worth a list.
    if (c.best2 > 16 * cellSize * cellSize) return false;
    const bool hasClass = check_.closed() && c.found;
    out.push_back(hasClass && insideAt(centre, bvh_.order()[c.slot], c.region, c.q) ? 1u : 0u);
    out.push_back(bitsOfFloat(floatBelow(hasClass ? std::sqrt(c.best2) * (1 - 1e-9) : 0.0)));
    const double halfDiag = 0.5 * std::sqrt(3.0) * cellSize;
    const double slack = 1e-12 * scale_;  // a point placed in the cell from a few ulps outside
    const double reach = (std::sqrt(c.best2) + halfDiag) * (1 + 1e-9) + slack;
    struct Found {
      float key;
      uint32_t slot;
      float n[3], base;
      bool operator<(const Found& o) const { return key != o.key ? key < o.key : slot < o.slot; }
    };
    thread_local std::vector<Found> found;
    found.clear();
    bool fits = true;
    bvh_.nearBox(box, reach, [&](uint32_t slot, uint32_t) {
      const double* v = &corners_[9 * size_t(slot)];
      double gap2 = 0;
      for (int k = 0; k < 3; ++k) {
        const double lo = std::min({v[k], v[3 + k], v[6 + k]}), hi = std::max({v[k], v[3 + k], v[6 + k]});
        const double d = std::max({0.0, lo - box.hi[k], box.lo[k] - hi});
        gap2 += d * d;
      }
      if (gap2 > reach * reach) return true;
      const double* pl = &slotPlanes_[4 * size_t(slot)];
      const double spread = 0.5 * cellSize * (std::abs(pl[0]) + std::abs(pl[1]) + std::abs(pl[2]));
      const double planeGap = std::abs(dot(pl, centre) - pl[3]) - spread;
      if (planeGap > reach) return true;
      // The tightest: every point x of the cell has |x - T| >= |c - T| - |x - c| (dc: |c - T|
      // rounded down).
      double qq[3];
      int region;
      const double dExact = std::sqrt(triangleDist2(centre, v, v + 3, v + 6, qq, region));
      const double dc = dExact * (1 - 1e-9);
      if (dc - halfDiag * (1 + 1e-9) - slack > reach) return true;
      Found f{floatBelow(dc), slot, {0, 0, 0}, -INFINITY};  // the key, rounded down again
      // linearGap's direction and base, where c is clear of T (else n is ill-conditioned):
      // q within delta of the true nearest point turns n by at most 2 delta / d, which moves
      // n . (x - q) for x in T by at most delta (1 + 2 diam(T) / d).
      if (dExact > 1e-6 * cellSize) {
        const double delta = 1e-12 * scale_;
        double diam2 = 0;
        for (int a = 0; a < 3; ++a)
          for (int b = a + 1; b < 3; ++b) {
            double e[3];
            sub(v + 3 * b, v + 3 * a, e);
            diam2 = std::max(diam2, dot(e, e));
          }
        double n[3];
        sub(centre, qq, n);
        normalise(n);
        for (int k = 0; k < 3; ++k) f.n[k] = float(n[k]);
        f.base = floatBelow(dExact * (1 - 1e-9) - delta * (1 + 2 * std::sqrt(diam2) / dExact));
      }
      found.push_back(f);
      fits = found.size() <= kMaxCandidates;
      return fits;  // too many: the hierarchy answers here
    });
    if (!fits) return false;
    std::sort(found.begin(), found.end());
    for (const Found& f : found)
      out.insert(out.end(), {f.slot, bitsOfFloat(f.key), bitsOfFloat(f.n[0]), bitsOfFloat(f.n[1]), bitsOfFloat(f.n[2]),
                             bitsOfFloat(f.base)});
    return true;
  });
  if (!list) return nullptr;
  float fc;
  std::memcpy(&fc, &list[1], sizeof fc);
  centreValue = list[0] ? double(fc) : -double(fc);
  count = (count - 2) / kCandidateWords;
  return list + 2;
}

int64_t MeshField::nearestTriangle(const double* p, double* q, int& bestRegion, double& best2, double start2) const {
  Nearest n{start2};
  const size_t nt = tris_.size() / 3;
  uint32_t count = 0;
  const uint32_t* cands = nullptr;
  double fromCentre, centreValue, pc[3];  // of the cell of the candidates
  if (nt <= 16) {  // a few triangles: all of them, no hierarchy
    // This thread's last nearest first: its distance lets the plane test skip most of the
    // others (a convex polytope's facets). The answer is canonical, so the order is free.
    const uint32_t warm = tWarm.field == id_ && tWarm.slot < nt ? tWarm.slot : 0;
    offer(p, warm, n);
    for (uint32_t slot = 0; slot < nt; ++slot)
      if (slot != warm) offer(p, slot, n);
    if (n.found) tWarm = {id_, n.slot};
  } else if (gCandidateCells.load(std::memory_order_relaxed) &&
             (cands = cellCandidates(p, count, fromCentre, centreValue, pc))) {
    // Near-first: once a candidate's lower bound key - |p - c| exceeds the best distance, so do
    // all the later ones' (a tie needs a distance equal to the best); one whose linear bound
    // does is skipped.
    for (uint32_t i = 0; i < count; ++i) {
      const double gap = candidateKey(cands, i) - fromCentre;
      if (gap > 0 && gap * gap > n.best2 * (1 + 1e-9)) break;
      const double linear = linearGap(cands, i, pc, fromCentre);
      if (linear > 0 && linear * linear > n.best2 * (1 + 1e-9)) continue;
      offer(p, candidateSlot(cands, i), n);
    }
    if (n.found) tWarm = {id_, n.slot};
  } else {
    // Warm start: the previous nearest triangle's distance, a little above so that it and its
    // ties still count, bounds the search.
    if (tWarm.field == id_) {
      double qq[3];
      int region;
      const double* c = &corners_[9 * size_t(tWarm.slot)];
      n.best2 = std::min(n.best2, triangleDist2(p, c, c + 3, c + 6, qq, region) * (1 + 2e-9) + 1e-300);
    }
    searchAll(p, n);
    if (n.found) tWarm = {id_, n.slot};
  }
  best2 = n.best2;
  bestRegion = n.region;
  if (q) q[0] = n.q[0], q[1] = n.q[1], q[2] = n.q[2];
  return n.found ? int64_t(bvh_.order()[n.slot]) : -1;
}

double MeshField::signedDistance(const double* p, double* q) const {
  double best2, bq[3];
  int bestRegion;
  const int64_t t = nearestTriangle(p, bq, bestRegion, best2);
  if (q) q[0] = bq[0], q[1] = bq[1], q[2] = bq[2];
  const double d = std::sqrt(best2);
  if (d == 0.0) return 0.0;
  const bool inside = check_.closed() ? insideAt(p, uint32_t(t), bestRegion, bq) : windingNumber(p) > 0.5;
  return inside ? d : -d;
}

// Closed meshes: inside iff p - q points against the pseudonormal of the nearest feature
// (region of triangle t) at q.
bool MeshField::insideAt(const double* p, uint32_t t, int region, const double* q) const {
  const double* n;
  if (region == 0) n = &faceN_[3 * size_t(t)];
  else if (region <= 3) n = &vertN_[3 * size_t(tris_[3 * size_t(t) + size_t(region) - 1])];
  else n = &edgeN_[3 * size_t(triEdge_[3 * size_t(t) + size_t(region) - 4])];
  double dp[3];
  sub(p, q, dp);
  return dot(dp, n) < 0.0;
}

// The class of value(p) + level (level != 0) on a closed mesh. With d the distance to the
// triangles: for level = r > 0, value + r >= 0 iff p is inside or fl(d) <= r; for level = -r,
// iff p is inside and not fl(d) < r. As fl(sqrt) is monotone, "fl(d) <= r" holds iff some
// triangle's computed distance is <= r: near the offset surface the last nearest triangle
// (this thread's warm one) or the first few of the cell's list settle it, where the value
// needs the nearest triangle. When no triangle is that near, d > 0 and p has the mesh's class:
// that of the cell's centre c if |p - c| < |f(c)| (no surface between them), else value's.
double MeshField::offsetClass(const double* p, double level) const {
  const size_t nt = tris_.size() / 3;
  if (!check_.closed() || level == 0 || !std::isfinite(level) || nt <= 16 ||
      !gCandidateCells.load(std::memory_order_relaxed))
    return value(p) + level;
  const double r = std::abs(level), rSlack = r * (1 + 1e-9);
  const double near = level > 0 ? 1.0 : -1.0;  // the class when some triangle is within r
  const double r2 = r * r;
  auto within = [&](uint32_t slot) {
    double qq[3];
    int region;
    const double* v = &corners_[9 * size_t(slot)];
    const double d2 = triangleDist2(p, v, v + 3, v + 6, qq, region);
    // d2 clear of r^2 (1e-12 covers r * r's rounding) decides fl(sqrt(d2)) against r without
    // the square root (fl(sqrt) is monotone and correctly rounded)
    if (d2 < r2 * (1 - 1e-12)) return true;
    if (d2 > r2 * (1 + 1e-12)) return false;
    const double d = std::sqrt(d2);
    return level > 0 ? d <= r : d < r;
  };
  if (tWarm.field == id_ && tWarm.slot < nt && planeGap(p, tWarm.slot) <= rSlack && within(tWarm.slot)) return near;
  uint32_t count = 0;
  double fromCentre, centreValue, pc[3];
  const uint32_t* cands = cellCandidates(p, count, fromCentre, centreValue, pc);
  if (!cands) return value(p) + level;
  for (uint32_t i = 0; i < count; ++i) {
    if (candidateKey(cands, i) - fromCentre > rSlack) break;  // this one and the rest: farther than r
    if (linearGap(cands, i, pc, fromCentre) > rSlack) continue;  // this one is farther than r
    const uint32_t slot = candidateSlot(cands, i);
    if (planeGap(p, slot) > rSlack) continue;  // its plane is farther than r
    if (within(slot)) {
      tWarm = {id_, slot};
      return near;
    }
  }
  if (fromCentre < std::abs(centreValue)) return centreValue > 0 ? 1.0 : -1.0;
  return value(p) + level;
}

double MeshField::value(const double* p) const { return signedDistance(p, nullptr); }

double MeshField::classValue(const double* p) const {
  if (!check_.closed()) return value(p);
  uint32_t count = 0;
  const uint32_t* cls = CellLists::at(classId_, lattice_, p, count, [&](const double* lo, const double* hi, std::vector<uint32_t>& out) {
    Bvh::Box box;
    for (int k = 0; k < 3; ++k) box.lo[k] = lo[k], box.hi[k] = hi[k];
    // (a margin: a point may be placed in the cell from a few ulps outside)
    if (!(bvh_.boxGap(box) > 1e-9 * lattice_.size)) return false;  // a triangle may cross the cell
    // No triangle meets the (closed) cell: f has one sign in it, that of its centre.
    const double c[3] = {0.5 * (box.lo[0] + box.hi[0]), 0.5 * (box.lo[1] + box.hi[1]), 0.5 * (box.lo[2] + box.hi[2])};
    out.push_back(value(c) > 0 ? 1u : 0u);
    return true;
  });
  if (!cls) return value(p);
  return cls[0] ? lattice_.size : -lattice_.size;
}

Interval MeshField::bound(const Interval box[3]) const {
  const Interval lip = DistanceField::bound(box);
  if (!check_.closed() || lip.lo > 0.0 || lip.hi < 0.0 || !std::isfinite(lip.lo) || !std::isfinite(lip.hi)) return lip;
  Bvh::Box q;
  for (int k = 0; k < 3; ++k) q.lo[k] = box[k].lo, q.hi[k] = box[k].hi;
  const double gap = bvh_.boxGap(q);
  if (!(gap > 0.0)) return lip;
  // The box meets no triangle: f keeps the sign of its value at the centre (the midpoint of
  // lip) and |f| >= gap throughout.
  const double mid = 0.5 * (lip.lo + lip.hi);
  if (mid > 0.0) return {std::max(lip.lo, gap), lip.hi};
  if (mid < 0.0) return {lip.lo, std::min(lip.hi, -gap)};
  return lip;
}

double MeshField::distance(const double* p, double* q) const {
  double best2;
  int region;
  nearestTriangle(p, q, region, best2);  // no sign: an open mesh's would cost a winding number
  return std::sqrt(best2);
}

double MeshField::distance(const double* p, double* q, double atMost) const {
  double best2;
  int region;
  const double start = atMost * (1 + 1e-9) + 1e-300;  // rounding: the true distance must be inside
  if (std::isfinite(start) && nearestTriangle(p, q, region, best2, start * start) >= 0) return std::sqrt(best2);
  return distance(p, q);
}

double MeshField::gradient(const double* p, double* g) const {
  double q[3];
  return gradientFromNearest(signedDistance(p, q), p, q, g);
}

double MeshField::windingNumber(const double* p) const {
  // Solid angle of each triangle seen from p (the tangent half-angle formula of Van Oosterom
  // and Strackee), summed: 1 inside a closed outward-oriented mesh, 0 outside.
  double sum = 0.0;
  for (size_t t = 0; t < tris_.size(); t += 3) {
    double a[3], b[3], c[3], bc[3];
    sub(&xyz_[3 * tris_[t]], p, a), sub(&xyz_[3 * tris_[t + 1]], p, b), sub(&xyz_[3 * tris_[t + 2]], p, c);
    const double la = std::sqrt(dot(a, a)), lb = std::sqrt(dot(b, b)), lc = std::sqrt(dot(c, c));
    cross(b, c, bc);
    const double num = dot(a, bc);
    const double den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
    sum += 2.0 * std::atan2(num, den);
  }
  return sum / (4.0 * M_PI);
}

double MeshField::volume() const {
  double v = 0.0;
  for (size_t t = 0; t < tris_.size(); t += 3) {
    double bc[3];
    cross(&xyz_[3 * tris_[t + 1]], &xyz_[3 * tris_[t + 2]], bc);
    v += dot(&xyz_[3 * tris_[t]], bc) / 6.0;
  }
  return v;
}

}  // namespace frep
