// The simplifier's run: candidates, placements, the spatial hash of the self-intersection
// check, the deferred check of the result, and the output (simplifier.h).
#include "meshing/simplifier.h"

#include <stdexcept>
#include <string>

namespace frep {

namespace simplify_detail {

// deferIntersections: no self-intersection check per collapse; embedded() checks the result
// once at the end instead (simplifyChecked).
Simplifier::Simplifier(Work&& work, const TapePtr& tape, const GridSpec& grid, const SimplifyOptions& opt, bool deferIntersections)
    : w_(std::move(work)), tape_(tape), grid_(grid), opt_(opt), tol_(opt.tolerance * grid.voxel),
      deferred_(deferIntersections) {
  // Error levels e_k = tol * 2^k up to two voxels (or the tolerance if larger): a replaced
  // triangle allows its new ones at most that much error, however far its own chord was (the
  // mesher's chords across a crease can be most of a voxel deep).
  // (At most the last level levelTol_ holds: simplifyMesh refuses tolerances that would go further.)
  while (maxLevel_ + 1 < int(levelTol_.size()) && std::ldexp(tol_, maxLevel_ + 1) <= std::max(tol_, grid_.voxel) * (1 + 1e-12))
    ++maxLevel_;
  for (size_t k = 0; k < levelTol_.size(); ++k) levelTol_[k] = std::ldexp(tol_, int(k));
  if (tape_->numVars() > 3 && opt_.fixedCoords.size() < tape_->numVars() - 3)
    throw std::invalid_argument("simplifyMesh: the model has " + std::to_string(tape_->numVars()) +
                                " coordinates; give values for x[4..] (fixedCoords)");
  batch_.setFieldSignsOnly(true);  // crossed() reads the class of each value alone
  floatSigns_ = opt_.floatSigns && FloatErrorBound::supports(*tape_);
  intervalLevels_ = opt_.intervalLevels && !tape_->hasExtrema() && tape_->fields().empty();
}

// Collapses until no candidate is left; then work(), vertexAlive() and triangleAlive() hold
// the result.
const SimplifyStats& Simplifier::run() {
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
    if ((examined & 1023) == 0) {  // each collapse checks its error at up to 64^2 points
      if (w_.confined) checkInterrupt();
      else reportProgress("simplify", examined, examined + queue_.size());
    }
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

// After a deferred run: does no triangle a collapse made meet a triangle near it improperly
// (the same exact predicates as the per-collapse check, once per final triangle)?
bool Simplifier::embedded() {
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

void Simplifier::setUp() {
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

// v's star changes: it is no longer settled, and the edges pushAllCandidates skipped for its
// tag (those to vertices of the same tag; the others are queued already) are queued now, or
// (push false: before the greedy phase) at its start.
void Simplifier::unsettle(uint32_t v, bool push) {
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
void Simplifier::pushAllCandidates() {
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

bool Simplifier::onBoxFace(const V3& p) const {
  const double eps = 1e-6 * grid_.voxel;
  for (int k = 0; k < 3; ++k) {
    const double lo = grid_.origin[k], hi = grid_.origin[k] + double(grid_.dims[k] - 1) * grid_.voxel;
    if (p[k] <= lo + eps || p[k] >= hi - eps) return true;
  }
  return false;
}

exact::P Simplifier::quantise(const V3& p) const {
  exact::P q;
  for (int k = 0; k < 3; ++k) q[k] = std::llround((p[k] - grid_.origin[k]) / grid_.voxel * kQuantum);
  return q;
}

V3 Simplifier::placement(uint32_t a, uint32_t b, double* cost, bool* clipped) const {
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

void Simplifier::pushCandidate(uint32_t a, uint32_t b) {
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

std::array<int32_t, 6> Simplifier::cellRange(const V3& a, const V3& b, const V3& c) const {
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

// Before any corner of t moves (the same cells as its insertion).
void Simplifier::eraseBuckets(uint32_t t) {
  const Tri& tr = w_.tris[t];
  forTriangleCells(w_.pos[tr[0]], w_.pos[tr[1]], w_.pos[tr[2]], [&](uint64_t k) {
    auto it = buckets_.find(k);
    auto& v = it->second;
    v.erase(std::find_if(v.begin(), v.end(), [t](const Entry& e) { return e.tri == t; }));
    if (v.empty()) buckets_.erase(it);
  });
}

// The mesh: vertices in the order of their keys (as the mesher orders them), triangles by
// index triple rotated to start at the smallest.
Mesh Simplifier::output(const MeshStats& stats) {
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

}  // namespace simplify_detail
}  // namespace frep
