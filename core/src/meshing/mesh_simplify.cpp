// Adaptive, feature-preserving edge collapses checked against the model (mesh_simplify.h): the
// state of a mesh as the simplifier takes it, the block passes and the public entry points; the
// simplifier itself is simplifier.h.
#include "frep/meshing/mesh_simplify.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <memory>
#include <stdexcept>

#include "meshing/simplifier.h"
#include "sampling/parallel_chunks.h"

namespace frep {

namespace {

using namespace simplify_detail;

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

// See kMinSimplifyTolerance: a tolerance whose error levels are not normal numbers is refused
// (a master's job or a caller could otherwise make the simplifier spin without end).
void checkTolerance(double tolerance, const GridSpec& grid) {
  const double tol = tolerance * grid.voxel;
  if (!(tolerance >= kMinSimplifyTolerance && tolerance <= kMaxSimplifyTolerance) || !(tol > 1e-140 && tol < 1e140))
    throw std::invalid_argument("simplifyMesh: tolerance " + std::to_string(tolerance) +
                                " voxels: expected 0 or 1e-30 to 1e30 voxels (and at most 1e140 in length)");
}

}  // namespace

SimplifyStats simplifyMesh(Mesh& mesh, const TapePtr& tape, const GridSpec& grid, const SimplifyOptions& options) {
  SimplifyStats stats;
  stats.trianglesBefore = stats.trianglesAfter = mesh.triangles.size() + 2 * mesh.carry.counters.collapses;
  if (!(options.tolerance > 0) || mesh.triangles.empty()) return stats;
  checkTolerance(options.tolerance, grid);
  InterruptScope scope(InterruptScope::choose(options.interrupt));
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
  checkTolerance(options.tolerance, grid);
  InterruptScope scope(InterruptScope::choose(options.interrupt));
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
