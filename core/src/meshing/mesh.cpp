// Marching tetrahedra on the Kuhn decomposition, keyed by global grid edges (see mesh.h).
//
// meshRegion: (1) the sparse sampler (band 1 voxel) gives the sign of every grid point near the
// surface (leaves) and of whole 8^3 blocks elsewhere (tiles); (2) every cell of every leaf is
// classified by its 8 corner signs, and each crossed cell's six tetrahedra add oriented
// triangles and quads whose corners are global edge keys; (3) each distinct crossed edge gets
// its vertex by root finding on the model and its normal from the gradient; (4) quads are
// split along their shorter diagonal. Every step depends on the edge or the cell only, never on
// the region, so adjacent pieces agree on shared vertices and the merged mesh is split-free.
#include "frep/meshing/mesh.h"
#include "frep/extremum/extremum.h"

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "frep/evaluators/eval.h"
#include "meshing/kuhn_tables.h"
#include "meshing/mesh_extremum_roots.h"
#include "meshing/radix_sort.h"
#include "sampling/parallel_chunks.h"

namespace frep {

namespace {

// ---- Tables: the oriented polygons of each cell's Kuhn tetrahedra (kuhn_tables.h) -----------

std::array<int, 3> cornerPos(uint8_t m) { return {m & 1, (m >> 1) & 1, (m >> 2) & 1}; }
// Twice the midpoint of the edge between corners a and b (exact integers).
std::array<int, 3> mid2(uint8_t a, uint8_t b) {
  auto p = cornerPos(a), q = cornerPos(b);
  return {p[0] + q[0], p[1] + q[1], p[2] + q[2]};
}

// The polygon of tetrahedron v (corner masks) for an inside pattern (bit i: corner v[i] inside).
KuhnPolygon tetPolygon(const uint8_t v[4], int pattern) {
  KuhnPolygon poly{};
  std::vector<int> in, out;
  for (int i = 0; i < 4; ++i) ((pattern >> i) & 1 ? in : out).push_back(i);
  if (in.empty() || out.empty()) return poly;
  std::vector<std::pair<uint8_t, uint8_t>> cycle;  // (corner a, corner b) per polygon vertex
  std::array<int, 3> dir;                          // from inside towards outside
  if (in.size() == 1 || out.size() == 1) {
    bool oneIn = in.size() == 1;
    int apex = oneIn ? in[0] : out[0];
    const std::vector<int>& rest = oneIn ? out : in;
    for (int r : rest) cycle.push_back({v[apex], v[r]});
    auto pa = cornerPos(v[apex]), pr = cornerPos(v[rest[0]]);
    for (int a = 0; a < 3; ++a) dir[a] = oneIn ? pr[a] - pa[a] : pa[a] - pr[a];
  } else {
    int a = in[0], b = in[1], cc = out[0], d = out[1];
    cycle = {{v[a], v[cc]}, {v[a], v[d]}, {v[b], v[d]}, {v[b], v[cc]}};
    auto pa = cornerPos(v[a]), pb = cornerPos(v[b]), pc = cornerPos(v[cc]), pd = cornerPos(v[d]);
    for (int k = 0; k < 3; ++k) dir[k] = pc[k] + pd[k] - pa[k] - pb[k];
  }
  std::array<int, 3> m0 = mid2(cycle[0].first, cycle[0].second), m1 = mid2(cycle[1].first, cycle[1].second),
                     m2 = mid2(cycle[2].first, cycle[2].second);
  int u[3] = {m1[0] - m0[0], m1[1] - m0[1], m1[2] - m0[2]};
  int w[3] = {m2[0] - m0[0], m2[1] - m0[1], m2[2] - m0[2]};
  int n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
  int dot = n[0] * dir[0] + n[1] * dir[1] + n[2] * dir[2];
  if (dot == 0) throw std::logic_error("mesh tables: degenerate tetrahedron case");
  if (dot < 0) std::reverse(cycle.begin() + 1, cycle.end());
  poly.count = uint8_t(cycle.size());
  for (size_t i = 0; i < cycle.size(); ++i) {
    poly.lo[i] = uint8_t(cycle[i].first & cycle[i].second);
    poly.dir[i] = uint8_t(cycle[i].first ^ cycle[i].second);
  }
  return poly;
}

struct KuhnCellTable {
  KuhnCell cells[256];

  KuhnCellTable() {
    const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    uint8_t corners[6][4];
    for (int t = 0; t < 6; ++t) {
      uint8_t c1 = uint8_t(1 << perms[t][0]);
      uint8_t c2 = uint8_t(c1 | (1 << perms[t][1]));
      const uint8_t v[4] = {0, c1, c2, 7};
      for (int i = 0; i < 4; ++i) corners[t][i] = v[i];
    }
    for (unsigned mask = 0; mask < 256; ++mask) {
      KuhnCell& cell = cells[mask];
      cell = KuhnCell{};
      for (int t = 0; t < 6; ++t) {
        int pattern = 0;
        for (int v = 0; v < 4; ++v) pattern |= int((mask >> corners[t][v]) & 1) << v;
        KuhnPolygon poly = tetPolygon(corners[t], pattern);
        if (poly.count != 0) cell.polygons[cell.count++] = poly;
      }
    }
  }
};

}  // namespace

const KuhnCell& kuhnCell(unsigned insideMask) {
  static const KuhnCellTable table;
  return table.cells[insideMask & 255];
}

namespace {




// Edge key -> index, open addressing (keys are never ~0: the top bits of a key are unused).
class KeyIndex {
 public:
  explicit KeyIndex(const std::vector<MeshVertex>& verts) {
    size_t cap = 16;
    while (cap < 2 * verts.size()) cap *= 2;
    mask_ = cap - 1;
    keys_.assign(cap, ~uint64_t(0));
    vals_.resize(cap);
    for (size_t i = 0; i < verts.size(); ++i) {
      size_t h = slot(verts[i].key);
      while (keys_[h] != ~uint64_t(0)) h = (h + 1) & mask_;
      keys_[h] = verts[i].key;
      vals_[h] = uint32_t(i);
    }
  }
  uint32_t at(EdgeKey k) const {
    for (size_t h = slot(k);; h = (h + 1) & mask_) {
      if (keys_[h] == k) return vals_[h];
      if (keys_[h] == ~uint64_t(0)) throw std::logic_error("mesh: a triangle's vertex is missing");
    }
  }

 private:
  size_t slot(uint64_t k) const { return size_t((k * 0x9E3779B97F4A7C15ull) >> 20) & mask_; }
  size_t mask_ = 0;
  std::vector<uint64_t> keys_;
  std::vector<uint32_t> vals_;
};

struct CrossEdge {
  EdgeKey key;
  bool inAtBase;  // the edge's base point is inside
  bool operator<(const CrossEdge& o) const { return key < o.key; }
};

struct CellOutput {
  std::vector<CrossEdge> edges;
  std::vector<std::array<EdgeKey, 3>> tris;
  std::vector<std::array<EdgeKey, 4>> quads;
  uint64_t cellsVisited = 0, cellsCrossed = 0, directEvals = 0;
  PointEvaluator point;
  BatchEvaluator<double> signs;  // one lane, the sampler's class of a field result
};

struct RootWorker {
  IntervalEvaluator interval;
  std::vector<Interval> box;
  BatchEvaluator<double> batch;
  PointEvaluator point;
  BatchGradientEvaluator grad;
  std::vector<double> x;
  uint64_t rootEvals = 0, gradientEvals = 0, fallbacks = 0;
};

class RegionMesher {
 public:
  RegionMesher(const TapePtr& tape, const GridSpec& grid, const std::array<int32_t, 3>& lo,
               const std::array<int32_t, 3>& hi, const MeshOptions& opt)
      : tape_(tape), grid_(grid), opt_(opt), nvars_(tape->numVars()) {
    if (nvars_ > 3 && opt.fixedCoords.size() < nvars_ - 3)
      throw std::invalid_argument("mesh: model has " + std::to_string(nvars_) +
                                  " coordinates; give values for x[4..] (fixedCoords)");
    if (!(opt.endGuard >= 0 && opt.endGuard < 0.5)) throw std::invalid_argument("mesh: endGuard must be in [0, 0.5)");
    if (opt.rootIterations < 0 || opt.rootIterations > 200)
      throw std::invalid_argument("mesh: rootIterations must be in [0, 200]");
    for (int a = 0; a < 3; ++a) {
      if (grid.dims[a] < 2) throw std::invalid_argument("mesh: the grid needs at least 2 points per axis");
      if (grid.dims[a] >= kMaxMeshGridPoints) throw std::invalid_argument("mesh: grid too large (2^19 points per axis)");
      if (lo[a] < 0 || lo[a] % kLeafDim != 0) throw std::invalid_argument("mesh: region must start on a multiple of 8");
      lo_[a] = lo[a];
      cellHi_[a] = std::min<int64_t>(hi[a], grid.dims[a] - 1);
    }
  }

  MeshPiece run() {
    InterruptScope scope(InterruptScope::choose(opt_.interrupt));  // the sampler below takes it too
    MeshPiece piece;
    piece.regionLo = {int32_t(lo_[0]), int32_t(lo_[1]), int32_t(lo_[2])};
    if (lo_[0] >= cellHi_[0] || lo_[1] >= cellHi_[1] || lo_[2] >= cellHi_[2]) return piece;

    SampleOptions so;
    // Only signs are read from the sample; extremum models, whose point values are searches,
    // take a band of 0 (half the evaluated points; the vertices get their own values).
    const bool extremumPath = tape_->hasExtrema() && opt_.extremumVertices;
    so.bandVoxels = extremumPath ? 0 : 1;
    so.pointwiseSearches = extremumPath;  // signs that do not depend on the region
    so.extremumSignsOnly = extremumPath;  // ... and only signs: searches stop once theirs is known
    so.fieldSignsOnly = true;             // a field result's class, not its distance
    so.tilesCoverCells = true;            // every crossed cell starts in a leaf, whatever the band
    so.fixedCoords = opt_.fixedCoords;
    so.threads = opt_.threads;
    for (int a = 0; a < 3; ++a) {
      so.regionLo[a] = int32_t(lo_[a]);
      so.regionHi[a] = int32_t(cellHi_[a] + 1);  // the cells' far corners
    }
    sampled_ = sample(tape_, grid_, so);
    piece.stats.samplePointEvals = sampled_.stats.pointEvals;
    piece.stats.sampleIntervalEvals = sampled_.stats.intervalEvals;
    piece.stats.nanValues = sampled_.stats.nanValues;
    piece.stats.domainErrors = sampled_.stats.domainErrors;
    for (size_t i = 0; i < sampled_.leaves.size(); ++i) leafIndex_[blockKey(sampled_.leaves[i].origin)] = i;
    for (const Tile& t : sampled_.tiles) tileSign_[tileKey(t.origin, t.size)] = t.inside;
    maxTile_ = 8;
    for (const Tile& t : sampled_.tiles) maxTile_ = std::max<int64_t>(maxTile_, t.size);

    // Cells -> oriented polygons over edge keys.
    tbb::enumerable_thread_specific<CellOutput> outs;
    parallelChunks(sampled_.leaves.size(), 1, opt_.threads, [&](size_t b, size_t e) {
      CellOutput& out = outs.local();
      for (size_t i = b; i < e; ++i) {
        size_t first = out.edges.size();
        leafCells(out, sampled_.leaves[i]);
        // Most repeats of an edge come from the same leaf: drop them while they are few.
        std::sort(out.edges.begin() + long(first), out.edges.end());
        out.edges.erase(std::unique(out.edges.begin() + long(first), out.edges.end(),
                                    [](const CrossEdge& x, const CrossEdge& y) { return x.key == y.key; }),
                        out.edges.end());
      }
    });
    std::vector<CrossEdge> edges;
    std::vector<std::array<EdgeKey, 3>> keyTris;
    std::vector<std::array<EdgeKey, 4>> quads;
    for (CellOutput& o : outs) {
      piece.stats.cellsVisited += o.cellsVisited;
      piece.stats.cellsCrossed += o.cellsCrossed;
      piece.stats.samplePointEvals += o.directEvals;
      edges.insert(edges.end(), o.edges.begin(), o.edges.end());
      keyTris.insert(keyTris.end(), o.tris.begin(), o.tris.end());
      quads.insert(quads.end(), o.quads.begin(), o.quads.end());
    }
    radixSortByKey(edges, [](const CrossEdge& e) { return e.key; });  // equal keys are one edge's records
    edges.erase(std::unique(edges.begin(), edges.end(),
                            [](const CrossEdge& a, const CrossEdge& b) { return a.key == b.key; }),
                edges.end());

    if (extremumPath) {
      std::vector<ExtremumEdge> xedges(edges.size());
      for (size_t i = 0; i < edges.size(); ++i) xedges[i] = {edges[i].key, edges[i].inAtBase};
      extremumEdgeVertices(tape_, grid_, opt_, xedges, piece.vertices, piece.stats);
      return finish(piece, keyTris, quads);
    }

    // Vertices: roots along the edges, normals from the gradient. Each edge is solved with the
    // tape pruned over the 8^3 block of its base point (a box that depends on the edge only,
    // never on the region), in groups of edges sharing that block.
    piece.vertices.resize(edges.size());
    std::vector<std::pair<uint64_t, uint32_t>> order(edges.size());  // (block of base, edge index)
    for (size_t i = 0; i < edges.size(); ++i) {
      auto e = edgeKeyParts(edges[i].key);
      order[i] = {edgeKey(e[0] & ~7, e[1] & ~7, e[2] & ~7, 0), uint32_t(i)};
    }
    radixSortByKey(order, [](const std::pair<uint64_t, uint32_t>& o) { return o.first; });  // then by edge: stable
    std::vector<size_t> groupStart;
    for (size_t i = 0; i < order.size(); ++i)
      if (i == 0 || order[i].first != order[i - 1].first) groupStart.push_back(i);
    groupStart.push_back(order.size());
    tbb::enumerable_thread_specific<RootWorker> workers;
    constexpr size_t B = BatchEvaluator<double>::kBatch;
    static_assert(B <= BatchGradientEvaluator::kBatch, "a batch of roots gets its normals in one gradient batch");
    std::atomic<uint64_t> groupsDone{0};
    parallelChunks(groupStart.size() - 1, 1, opt_.threads, [&](size_t gb, size_t ge) {
      RootWorker& w = workers.local();
      for (size_t g = gb; g < ge; ++g) {
        reportProgress("mesh", ++groupsDone, groupStart.size() - 1);
        TapePtr tape = blockTape(w, order[groupStart[g]].first);
        for (size_t start = groupStart[g]; start < groupStart[g + 1]; start += B) {
          size_t count = std::min(B, groupStart[g + 1] - start);
          const CrossEdge* ep[B];
          MeshVertex* vp[B];
          for (size_t l = 0; l < count; ++l) {
            ep[l] = &edges[order[start + l].second];
            vp[l] = &piece.vertices[order[start + l].second];
          }
          solveRoots(w, *tape, ep, vp, count);
        }
      }
    });
    for (RootWorker& w : workers) {
      piece.stats.rootEvals += w.rootEvals;
      piece.stats.gradientEvals += w.gradientEvals;
      piece.stats.fallbackEdges += w.fallbacks;
    }
    return finish(piece, keyTris, quads);
  }

 private:
  // Triangles as local indices of the piece's vertices.
  MeshPiece finish(MeshPiece& piece, const std::vector<std::array<EdgeKey, 3>>& keyTris,
                   const std::vector<std::array<EdgeKey, 4>>& quads) {
    // Triangles as local indices (vertices are sorted by key, so index order is key order).
    // Quads: split along the shorter diagonal (ties: 0-2), a choice made from the quad alone.
    KeyIndex index(piece.vertices);
    std::vector<std::array<uint32_t, 3>> tris;
    tris.reserve(keyTris.size() + 2 * quads.size());
    for (const auto& t : keyTris) tris.push_back({index.at(t[0]), index.at(t[1]), index.at(t[2])});
    for (const auto& q : quads) {
      const std::array<uint32_t, 4> v{index.at(q[0]), index.at(q[1]), index.at(q[2]), index.at(q[3])};
      const std::array<double, 3>* p[4];
      for (int c = 0; c < 4; ++c) p[c] = &piece.vertices[v[c]].position;
      splitKuhnQuad(v, p, tris);
    }
    for (auto& t : tris) canonicalRotate(t);
    std::sort(tris.begin(), tris.end());
    piece.triangles = std::move(tris);
    return std::move(piece);
  }

  static uint64_t blockKey(const std::array<int32_t, 3>& o) { return edgeKey(o[0], o[1], o[2], 0); }
  static uint64_t tileKey(const std::array<int32_t, 3>& o, int32_t size) {
    int lg = 0;
    while ((int64_t(1) << lg) < size) ++lg;
    // Origins are multiples of 8, so the key's low 6 bits (direction, low bits of z) are free.
    return edgeKey(o[0], o[1], o[2], 0) | uint64_t(lg);
  }

  // Source of the signs of the 8^3 block at origin o: a leaf, a tile's sign, or neither.
  struct BlockSource {
    const LeafBlock* leaf = nullptr;
    int tile = 0;  // +1 inside tile, -1 outside tile, 0 unknown (evaluate points directly)
  };
  BlockSource blockSource(const std::array<int64_t, 3>& o) const {
    BlockSource s;
    auto it = leafIndex_.find(blockKey({int32_t(o[0]), int32_t(o[1]), int32_t(o[2])}));
    if (it != leafIndex_.end()) {
      s.leaf = &sampled_.leaves[it->second];
      return s;
    }
    for (int64_t size = 8; size <= maxTile_; size *= 2) {
      std::array<int32_t, 3> to;
      for (int a = 0; a < 3; ++a) to[a] = int32_t(lo_[a] + ((o[a] - lo_[a]) / size) * size);
      auto t = tileSign_.find(tileKey(to, int32_t(size)));
      if (t != tileSign_.end()) {
        s.tile = t->second ? 1 : -1;
        return s;
      }
    }
    return s;
  }

  bool evalInside(CellOutput& out, int64_t i, int64_t j, int64_t k) {
    double x[16];
    std::vector<double> xv;
    double* px = x;
    if (nvars_ > 16) {
      xv.resize(nvars_);
      px = xv.data();
    }
    auto w = grid_.world(i, j, k);
    for (uint32_t v = 0; v < nvars_; ++v) px[v] = v < 3 ? w[v] : opt_.fixedCoords[v - 3];
    ++out.directEvals;
    // The class the sampler gives the point (fieldSignsOnly), whichever region holds it; a
    // tape with extrema keeps the point evaluator (its cold search, as pointwiseSearches).
    if (tape_->hasExtrema() || tape_->fields().empty()) return insideValue(out.point.eval(*tape_, px));
    out.signs.reserve(*tape_);
    out.signs.setFieldSignsOnly(true);
    for (uint32_t v = 0; v < nvars_; ++v) out.signs.in(v)[0] = px[v];
    return insideValue(out.signs.eval(*tape_, 1)[0]);
  }

  void leafCells(CellOutput& out, const LeafBlock& leaf) {
    const std::array<int64_t, 3> o{leaf.origin[0], leaf.origin[1], leaf.origin[2]};
    int64_t end[3];
    for (int a = 0; a < 3; ++a) end[a] = std::min<int64_t>(o[a] + kLeafDim, cellHi_[a]);  // cells [o, end)
    if (end[0] <= o[0] || end[1] <= o[1] || end[2] <= o[2]) return;
    BlockSource src[8];
    for (int n = 0; n < 8; ++n) {
      if (n == 0) {
        src[n].leaf = &leaf;
        continue;
      }
      std::array<int64_t, 3> bo{o[0] + (n & 1) * 8, o[1] + ((n >> 1) & 1) * 8, o[2] + ((n >> 2) & 1) * 8};
      bool needed = true;
      for (int a = 0; a < 3; ++a)
        if (((n >> a) & 1) && end[a] < o[a] + kLeafDim) needed = false;  // no cell reaches it
      if (needed) src[n] = blockSource(bo);
    }
    // Signs of points [o, end] per axis (at most 9^3).
    uint8_t in[9][9][9];
    for (int64_t x = o[0]; x <= end[0]; ++x)
      for (int64_t y = o[1]; y <= end[1]; ++y)
        for (int64_t z = o[2]; z <= end[2]; ++z) {
          int lx = int(x - o[0]), ly = int(y - o[1]), lz = int(z - o[2]);
          int n = (lx >> 3) | ((ly >> 3) << 1) | ((lz >> 3) << 2);
          const BlockSource& s = src[n];
          bool inside;
          if (s.leaf) inside = insideValue(s.leaf->values[leafOffset(lx & 7, ly & 7, lz & 7)]);
          else if (s.tile) inside = s.tile > 0;
          else inside = evalInside(out, x, y, z);
          in[lx][ly][lz] = inside;
        }
    for (int64_t x = o[0]; x < end[0]; ++x)
      for (int64_t y = o[1]; y < end[1]; ++y)
        for (int64_t z = o[2]; z < end[2]; ++z) {
          ++out.cellsVisited;
          int lx = int(x - o[0]), ly = int(y - o[1]), lz = int(z - o[2]);
          unsigned mask = 0;
          for (int c = 0; c < 8; ++c) mask |= unsigned(in[lx + (c & 1)][ly + ((c >> 1) & 1)][lz + ((c >> 2) & 1)]) << c;
          if (mask == 0 || mask == 255) continue;
          ++out.cellsCrossed;
          forCellPolygons(
              mask, x, y, z, edgeKey, [&](EdgeKey k, bool loInside) { out.edges.push_back({k, loInside}); },
              [&](const EdgeKey* k, int n) {
                if (n == 3) out.tris.push_back({k[0], k[1], k[2]});
                else out.quads.push_back({k[0], k[1], k[2], k[3]});
              });
        }
  }

  // Illinois false position on t in [0, 1] from the inside end (t = 0) to the outside end,
  // bisection when the end values contradict their signs. The same steps for every edge, so a
  // vertex depends on its edge only.
  // The root tape pruned by interval evaluation over the block [o, o + 8]^3 (world box).
  TapePtr blockTape(RootWorker& w, uint64_t blockKey) {
    if (tape_->numChoices() == 0) return tape_;
    auto o = edgeKeyParts(blockKey);
    w.box.resize(std::max<uint32_t>(nvars_, 1));
    for (uint32_t v = 0; v < nvars_; ++v) {
      if (v < 3) {
        double lo = grid_.origin[v] + double(o[v]) * grid_.voxel;
        double hi = grid_.origin[v] + double(o[v] + kLeafDim) * grid_.voxel;
        w.box[v] = Interval(lo, hi);
      } else {
        w.box[v] = Interval(opt_.fixedCoords[v - 3]);
      }
    }
    w.interval.eval(*tape_, w.box.data());
    return w.interval.pruned(tape_);
  }

  void solveRoots(RootWorker& w, const Tape& tape, const CrossEdge* const* edgePtrs, MeshVertex* const* vertPtrs,
                  size_t count) {
    constexpr size_t B = BatchEvaluator<double>::kBatch;
    double pin[B][3], dp[B][3];
    double a[B], b[B], fa[B], fb[B], ra[B], rb[B];
    int8_t last[B];
    bool illinois[B], done[B];
    double prevT[B];
    for (size_t l = 0; l < count; ++l) {
      const CrossEdge& edge = *edgePtrs[l];
      auto parts = edgeKeyParts(edge.key);
      auto p0 = grid_.world(parts[0], parts[1], parts[2]);
      int d = int(parts[3]);
      auto p1 = grid_.world(parts[0] + (d & 1), parts[1] + ((d >> 1) & 1), parts[2] + ((d >> 2) & 1));
      const auto& pi = edge.inAtBase ? p0 : p1;
      const auto& po = edge.inAtBase ? p1 : p0;
      for (int c = 0; c < 3; ++c) {
        pin[l][c] = pi[c];
        dp[l][c] = po[c] - pi[c];
      }
      done[l] = false;
      a[l] = 0;
      b[l] = 1;
      last[l] = 0;
    }
    const bool useBatch = !tape.hasExtrema();  // batch extremum lanes warm-start each other
    // An extremum's value is certified only within its search's tolerance (and is usually far
    // better: the incumbent is polished by local ascent), and every step costs a search per
    // lane: a lane stops once |f| is below MeshOptions::rootStopValue (a test of the lane
    // alone, so every vertex stays a function of its edge).
    double noise = opt_.rootStopValue;
    if (noise < 0) {
      noise = 0.0;
      if (tape.hasExtrema()) {
        noise = INFINITY;
        for (const ExtremumEntry& e : tape.extrema())
          noise = std::min(noise, e.spec->method == ExtremumMethod::BranchAndBound ? 0.01 * e.spec->tolerance : 0.0);
      }
    }
    std::vector<double> tv(count), fv(count);
    // Evaluates f at tv for the lanes not done, packed together (a lane's value never depends on
    // the other lanes: batches of extremum tapes are avoided, their lanes warm-start each other).
    auto evalAt = [&]() {
      size_t idx[B], k = 0;
      for (size_t l = 0; l < count; ++l)
        if (!done[l]) idx[k++] = l;
      w.rootEvals += k;
      if (useBatch) {
        w.batch.reserve(tape);
        for (size_t j = 0; j < k; ++j) {
          size_t l = idx[j];
          for (uint32_t v = 0; v < nvars_; ++v)
            w.batch.in(v)[j] = v < 3 ? pin[l][v] + tv[l] * dp[l][v] : opt_.fixedCoords[v - 3];
        }
        const double* f = w.batch.eval(tape, k);
        for (size_t j = 0; j < k; ++j) fv[idx[j]] = f[j];
      } else {
        w.x.resize(std::max<uint32_t>(nvars_, 3));
        for (size_t j = 0; j < k; ++j) {
          size_t l = idx[j];
          for (uint32_t v = 0; v < nvars_; ++v)
            w.x[v] = v < 3 ? pin[l][v] + tv[l] * dp[l][v] : opt_.fixedCoords[v - 3];
          fv[l] = w.point.eval(tape, w.x.data());
        }
      }
    };
    std::fill(tv.begin(), tv.end(), 0.0);
    evalAt();
    for (size_t l = 0; l < count; ++l) fa[l] = ra[l] = fv[l];
    std::fill(tv.begin(), tv.end(), 1.0);
    evalAt();
    for (size_t l = 0; l < count; ++l) {
      fb[l] = rb[l] = fv[l];
      illinois[l] = std::isfinite(fa[l]) && std::isfinite(fb[l]) && fa[l] >= 0 && fb[l] < 0;
      if (!illinois[l]) ++w.fallbacks;
    }
    for (int it = 0; it < opt_.rootIterations; ++it) {
      // A lane is done when its step moved t by less than 1e-10 of the edge: it depends on the
      // lane alone, so stopping early keeps every vertex a function of its edge.
      size_t active = 0;
      for (size_t l = 0; l < count; ++l) active += !done[l];
      if (active == 0) break;
      for (size_t l = 0; l < count; ++l) {
        double t = 0.5 * (a[l] + b[l]);
        if (illinois[l] && fa[l] != fb[l]) {
          double s = a[l] + (b[l] - a[l]) * fa[l] / (fa[l] - fb[l]);
          if (s > a[l] && s < b[l]) t = s;
        }
        tv[l] = t;
      }
      evalAt();
      for (size_t l = 0; l < count; ++l) {
        double t = tv[l], f = fv[l];
        if (done[l]) continue;
        if (!(t > a[l] && t < b[l])) {  // converged to a point
          done[l] = true;
          continue;
        }
        if (it > 0 && std::abs(t - prevT[l]) < 1e-10) done[l] = true;
        if (noise > 0 && std::abs(f) <= noise) done[l] = true;
        // A root hit exactly (an exact distance's first false-position step on a flat piece
        // often is): it becomes the inside end with fa = 0, where false position stalls, and
        // the steps left would bisect towards it from outside; the vertex is that root.
        if (f == 0) done[l] = true;
        prevT[l] = t;
        if (std::isnan(f)) illinois[l] = false;
        if (insideValue(f)) {
          a[l] = t;
          fa[l] = ra[l] = f;
          if (last[l] == 1) fb[l] *= 0.5;
          last[l] = 1;
        } else {
          b[l] = t;
          fb[l] = rb[l] = f;
          if (last[l] == -1) fa[l] *= 0.5;
          last[l] = -1;
        }
      }
    }
    const double guard = opt_.endGuard;
    w.grad.reserve(tape);
    for (size_t l = 0; l < count; ++l) {
      double t = 0.5 * (a[l] + b[l]);
      if (illinois[l] && std::isfinite(ra[l]) && std::isfinite(rb[l]) && ra[l] >= 0 && rb[l] < 0)
        t = a[l] + (b[l] - a[l]) * ra[l] / (ra[l] - rb[l]);
      t = std::min(std::max(t, guard), 1.0 - guard);
      MeshVertex& v = *vertPtrs[l];
      v.key = edgePtrs[l]->key;
      for (int c = 0; c < 3; ++c) v.position[c] = pin[l][c] + t * dp[l][c];
      for (uint32_t c = 0; c < nvars_; ++c) w.grad.in(c)[l] = c < 3 ? v.position[c] : opt_.fixedCoords[c - 3];
    }
    // Normals: -grad f, or the edge direction where the gradient is unusable.
    w.grad.eval(tape, count);
    w.gradientEvals += count;
    for (size_t l = 0; l < count; ++l) {
      MeshVertex& v = *vertPtrs[l];
      double n[3] = {-w.grad.partial(0)[l], -w.grad.partial(1)[l], -w.grad.partial(2)[l]};
      double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      if (!(len > 0) || !std::isfinite(len)) {
        for (int c = 0; c < 3; ++c) n[c] = dp[l][c];
        len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      }
      for (int c = 0; c < 3; ++c) v.normal[c] = n[c] / len;
    }
  }

  TapePtr tape_;
  GridSpec grid_;
  MeshOptions opt_;
  uint32_t nvars_;
  int64_t lo_[3], cellHi_[3];
  SampleResult sampled_;
  std::unordered_map<uint64_t, size_t> leafIndex_;
  std::unordered_map<uint64_t, bool> tileSign_;
  int64_t maxTile_ = 8;
};

}  // namespace

MeshPiece meshRegion(const TapePtr& tape, const GridSpec& grid, const std::array<int32_t, 3>& lo,
                     const std::array<int32_t, 3>& hi, const MeshOptions& options) {
  return RegionMesher(tape, grid, lo, hi, options).run();
}

Mesh meshGrid(const TapePtr& tape, const GridSpec& grid, const MeshOptions& options, int brick) {
  if (brick < 0 || brick % kLeafDim != 0) throw std::invalid_argument("mesh: brick must be a multiple of 8 (0: one region)");
  std::vector<MeshPiece> pieces;
  if (brick == 0) {
    pieces.push_back(meshRegion(tape, grid, {0, 0, 0}, grid.dims, options));
  } else {
    for (int32_t x = 0; x < grid.dims[0] - 1; x += brick)
      for (int32_t y = 0; y < grid.dims[1] - 1; y += brick)
        for (int32_t z = 0; z < grid.dims[2] - 1; z += brick)
          pieces.push_back(meshRegion(tape, grid, {x, y, z}, {x + brick, y + brick, z + brick}, options));
  }
  return mergePieces(pieces);
}

}  // namespace frep
