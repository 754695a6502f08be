// The simplifier's changes to the mesh: edge collapses and cell contractions, with their
// topology, shape, error and self-intersection checks (simplifier.h).
#include "meshing/simplifier.h"

namespace frep {

namespace simplify_detail {

// Shape of a changed triangle: tr (vertex ids, as it is) becoming c0, c1, c2 must keep facing
// the same way — its own normal, or for a sliver (whose normal is noise: the mesher's
// triangles where the surface grazes a grid point) the model's normals at its corners — within
// ~78 degrees, and not degenerate. Tracks the worst quality before and after.
// The worst quality of the triangles ts as they are (1 for none).
double Simplifier::worstQuality(const std::vector<uint32_t>& ts) const {
  double worst = 1;
  for (uint32_t t : ts) worst = std::min(worst, quality(w_.pos[w_.tris[t][0]], w_.pos[w_.tris[t][1]], w_.pos[w_.tris[t][2]]));
  return worst;
}

bool Simplifier::keepsFacing(const Tri& tr, const V3& c0, const V3& c1, const V3& c2, double& worstBefore, double& worstAfter) const {
  const V3 &o0 = w_.pos[tr[0]], &o1 = w_.pos[tr[1]], &o2 = w_.pos[tr[2]];
  const double q0 = quality(o0, o1, o2);
  worstBefore = std::min(worstBefore, q0);
  const V3 n0 = q0 < opt_.minQuality ? add(w_.normal[tr[0]], add(w_.normal[tr[1]], w_.normal[tr[2]])) : cross(sub(o1, o0), sub(o2, o0));
  const V3 n1 = cross(sub(c1, c0), sub(c2, c0));
  const double l1 = norm(n1);
  worstAfter = std::min(worstAfter, quality(c0, c1, c2));
  return l1 > 1e-12 * grid_.voxel * grid_.voxel && dot(n0, n1) > 0.2 * norm(n0) * l1;
}

// The checks an edge collapse and a cell contraction share once their topology passed. The
// new triangles qs (corners a, b, c) are what the triangles before[i] (vertex ids, as they are)
// become; `dropped` go, the points `gone` leave the mesh, `replaced` are all the triangles the
// new ones replace. Shape: no new triangle turns over or degenerates (keepsFacing), and below
// the quality bound the worst of before and dropped does not get more than 10% worse
// (worstGotWorse). Error: within the tolerance, or within the worst level of the replaced
// triangles (errorPasses); qs[i].level is then the new triangle's level. Counts a rejection.
bool Simplifier::acceptsChange(std::vector<LevelQuery>& qs, const std::vector<Tri>& before,
                               const std::vector<uint32_t>& dropped, const std::vector<V3>& gone,
                               const std::vector<uint32_t>& replaced) {
  double worstBefore = worstQuality(dropped), worstAfter = 1;
  for (size_t i = 0; i < qs.size(); ++i)
    if (!keepsFacing(before[i], qs[i].a, qs[i].b, qs[i].c, worstBefore, worstAfter)) {
      ++stats_.rejectedShape;
      return false;
    }
  if (worstGotWorse(worstBefore, worstAfter)) {
    ++stats_.rejectedShape;
    return false;
  }
  if (!errorPasses(qs, gone, replaced)) {
    ++stats_.rejectedError;
    return false;
  }
  return true;
}

void Simplifier::tryCollapse(uint32_t a, uint32_t b) {
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

  // Shape and error (acceptsChange): the changed triangles with a and b at p; the two removed.
  std::vector<LevelQuery>& qs = scratch_.queries;
  std::vector<Tri>& before = scratch_.before;
  qs.assign(changed.size(), {});
  before.resize(changed.size());
  for (size_t i = 0; i < changed.size(); ++i) {
    const Tri& tr = w_.tris[changed[i]];
    before[i] = tr;
    qs[i].a = corner(tr[0]), qs[i].b = corner(tr[1]), qs[i].c = corner(tr[2]);
  }
  std::vector<V3>& gonePoints = scratch_.gonePoints;
  gonePoints = {w_.pos[a], w_.pos[b]};
  std::vector<uint32_t>& replaced = scratch_.replaced;
  replaced = changed;
  replaced.insert(replaced.end(), removed.begin(), removed.end());
  if (!acceptsChange(qs, before, removed, gonePoints, replaced)) return;
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

// Before the greedy collapses, the vertices of one cell of 2^level voxels (by the grid edge
// they came from) are merged into one in a single step where that is safe: dual contouring's
// one vertex per cell (Ju et al.), reached from the marching tetrahedra's mesh, with the same
// checks as an edge collapse. One contraction of k vertices does the work of k - 1 edge
// collapses with one placement and one error check of its fan, instead of k - 1 of each and
// the heap traffic of every ring they change. Cells go in key order, each connected group of
// a cell's vertices once: the outcome is a function of the input (split-invariance).
void Simplifier::contractCells(int level) {
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
void Simplifier::tryContract(const std::vector<uint32_t>& C) {
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

  // Shape and error, as for an edge collapse (acceptsChange): the fan's triangles with C at p
  // (each as it is, from its corner in C); the star's others dropped.
  std::vector<LevelQuery>& qs = scratch_.queries;
  std::vector<Tri>& before = scratch_.before;
  qs.assign(nf, {});
  before.resize(nf);
  for (size_t i = 0; i < nf; ++i) {
    before[i] = {fan[i].c, fan[i].u, fan[i].w};
    qs[i].a = p, qs[i].b = w_.pos[fan[i].u], qs[i].c = w_.pos[fan[i].w];
  }
  std::vector<V3>& gonePoints = scratch_.gonePoints;
  gonePoints.clear();
  for (uint32_t c : C) gonePoints.push_back(w_.pos[c]);
  std::vector<uint32_t>& replaced = scratch_.replaced;
  replaced = gone;
  for (const Fan& f : fan) replaced.push_back(f.t);
  if (!acceptsChange(qs, before, gone, gonePoints, replaced)) return;

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
bool Simplifier::noIntersection(uint32_t a, uint32_t b, const V3& p, const exact::P& qp, const std::vector<uint32_t>& changed,
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

}  // namespace simplify_detail
}  // namespace frep
