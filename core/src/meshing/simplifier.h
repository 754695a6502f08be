// The simplifier of one mesh or one block of it (mesh_simplify.h): the state it works on and
// the class that collapses edges and contracts cells, checked against the model. Its members
// are defined by concern: simplifier.cpp (the run, candidates, placements, the spatial hash,
// the output), simplifier_error.cpp (error against the model), simplifier_changes.cpp (edge
// collapses and cell contractions, their checks). Internal to frep_core.
#pragma once

#include <boost/container/small_vector.hpp>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

#include "frep/evaluators/eval.h"
#include "frep/evaluators/float_error.h"
#include "frep/meshing/mesh_predicates.h"
#include "frep/meshing/mesh_simplify.h"
#include "meshing/simplify_geometry.h"

namespace frep::simplify_detail {

constexpr int kMaxSamplesPerSide = 64;  // the error check's subdivision: m <= 64
constexpr size_t kProbes = 4;           // error samples tried first on every new triangle
constexpr int kGlobalStage = 4;         // SimplifyOptions::progress: the global pass
constexpr int kClusterLevels = 2;       // cell contractions: cells of 1, 2 and 4 voxels

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
  Simplifier(Work&& work, const TapePtr& tape, const GridSpec& grid, const SimplifyOptions& opt, bool deferIntersections);
  const SimplifyStats& run();
  const Work& work() const { return w_; }

  bool embedded();
  bool vertexAlive(uint32_t v) const { return alive_[v] && !vtris_[v].empty(); }
  bool settles() const { return deferred_; }
  // A placement cut off by the block's border: v's edges may pass in another block.
  bool borderBound(uint32_t v) const { return borderBound_[v] != 0; }
  bool triangleAlive(uint32_t t) const { return tAlive_[t]; }
  Mesh output(const MeshStats& stats);

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

  void setUp();
  bool settledEdge(uint32_t a, uint32_t b) const { return w_.settled[a] != 0 && w_.settled[a] == w_.settled[b]; }
  void unsettle(uint32_t v, bool push);
  void pushAllCandidates();

  // ---- positions ------------------------------------------------------------------------
  bool onBoxFace(const V3& p) const;
  exact::P quantise(const V3& p) const;
  V3 placement(uint32_t a, uint32_t b, double* cost, bool* clipped = nullptr) const;
  void pushCandidate(uint32_t a, uint32_t b);

  // ---- spatial hash of triangles (for the self-intersection check) ------------------------
  std::array<int32_t, 6> cellRange(const V3& a, const V3& b, const V3& c) const;
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
  void eraseBuckets(uint32_t t);

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

  bool levels(std::vector<LevelQuery>& qs, int maxK, bool stopAbove, bool resume = false);
  bool endsAbove(std::vector<LevelQuery>& qs, int maxK);
  bool crossed();
  // inside_[i] = insideValue(f) at the first n lanes of the inputs: in float where the certified
  // bound (float_error.h) decides the sign, in double for the rest (the same classes as double
  // throughout; the inputs' lanes are reused for the double ones).
  void classify(size_t n);
  // Does every sample of q's level (de: its offset along q.d) pass, by interval bounds of f over
  // the boxes of the triangle moved by -de and by +de? False: not decided (sample them).
  bool offsetsDecided(const LevelQuery& q, const V3& de);
  int levelOf(uint32_t t);
  bool errorPasses(std::vector<LevelQuery>& qs, const std::vector<V3>& gone, const std::vector<uint32_t>& replaced);

  // ---- shape of a change (simplifier_changes.cpp) ---------------------------------------------
  double worstQuality(const std::vector<uint32_t>& ts) const;
  // Below the quality bound the worst triangle may not get more than 10% worse (the mesher
  // leaves slivers where the surface grazes grid points; they go first).
  bool worstGotWorse(double before, double after) const { return after < opt_.minQuality && after < 0.9 * before; }
  bool keepsFacing(const Tri& tr, const V3& c0, const V3& c1, const V3& c2, double& worstBefore, double& worstAfter) const;
  bool acceptsChange(std::vector<LevelQuery>& qs, const std::vector<Tri>& before, const std::vector<uint32_t>& dropped,
                     const std::vector<V3>& gone, const std::vector<uint32_t>& replaced);

  // ---- one collapse ---------------------------------------------------------------------------
  void tryCollapse(uint32_t a, uint32_t b);

  // ---- cell contractions --------------------------------------------------------------------
  void contractCells(int level);
  void tryContract(const std::vector<uint32_t>& C);
  bool noIntersection(uint32_t a, uint32_t b, const V3& p, const exact::P& qp, const std::vector<uint32_t>& changed,
                      const std::vector<uint32_t>& removed);

  // ---- state --------------------------------------------------------------------------------
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
    std::vector<Tri> before;  // acceptsChange: the changed triangles as they are
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
  // Sign checks in float first where the tape's ops are covered by the bound (3.4x cheaper per
  // point on examples/chair.hf; the model evaluations are ~80% of the simplifier's time).
  bool floatSigns_ = false;
  BatchEvaluator<float> fbatch_;
  FloatErrorBound fbound_;
  std::vector<float*> finputs_;      // its input lanes, written with inputs_ (levels)
  std::array<double, 3> laneLo_{}, laneHi_{};  // a box holding the lanes written (spatial coordinates)
  std::vector<Interval> box_;        // the box bound_ holds for
  double bound_ = -1;                // < 0: none yet
  std::vector<uint32_t> redo_;
  std::array<char, 2 * kPairsPerCall> inside_{};
  // A level of at least kIntervalSamples samples is first tried by two interval evaluations
  // (offsetsDecided): where the triangle lies in a flat face of the model (most of a CSG of
  // blocks), both boxes are thin and decide it at the cost of a few point evaluations. Only
  // for tapes whose interval extension holds every double evaluation in its box (interval.h):
  // no extremum (its bound is a search's) and no field (its own bounds).
  // Tried while it pays: a level of n samples when n times the share of tries that decided
  // (counted since this run began, from an even start) is at least kIntervalSamples. A curved
  // surface's levels are rarely decided (sphere ∩ gyroid) and then cost more than they spare.
  static constexpr size_t kIntervalSamples = 32;
  bool worthIntervals(size_t n) const { return n * (intervalPasses_ + 1) >= kIntervalSamples * (intervalTries_ + 2); }
  uint64_t intervalTries_ = 0, intervalPasses_ = 0;
  bool intervalLevels_ = false;
  IntervalEvaluator ieval_;
  std::vector<Interval> ibox_;
  int maxLevel_ = 0;  // the last error level
  // e_k = tol * 2^k for every level a triangle can hold (int8_t): a level carried from a
  // worker's payload may exceed maxLevel_ (the decoder allows up to 15), and still counts.
  std::array<double, 128> levelTol_{};
  bool deferred_;
  std::vector<char> madeNow_;  // per triangle: made by a collapse of this run
};

}  // namespace frep::simplify_detail
