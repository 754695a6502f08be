// The simplifier's error against the model: sample points of a triangle, error levels, and the
// error check of a collapse or a contraction (simplifier.h).
#include "meshing/simplifier.h"

#include <limits>

namespace frep {

using simplify_detail::kMaxSamplesPerSide;
using simplify_detail::kProbes;

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

namespace simplify_detail {

namespace {
// double -> float without the undefined conversion of values beyond float's range (those lanes
// never pass the bound: it is infinite for such boxes).
inline float narrow(double x) { return std::fabs(x) <= 3.0e38 ? float(x) : float(std::copysign(INFINITY, x)); }
}  // namespace

// Answers every query. A level is checked in full only once its probes (kProbes points spread
// over the triangle, where a chord is deepest) pass, and a failing level moves on to the next
// one's probes: the answer is the same as checking every level in full, for far fewer
// evaluations. All queries advance together, so each round is one batch of the evaluator
// over every query's points. stopAbove: return false as soon as some query exceeds maxK.
// resume: qs were answered by a call with a smaller maxK that failed; the queries that went
// past it go on from where they stopped (the same answers as a fresh call, without checking
// the lower levels again).
bool Simplifier::levels(std::vector<LevelQuery>& qs, int maxK, bool stopAbove, bool resume) {
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
  if (floatSigns_) {
    fbatch_.reserve(*tape_);
    finputs_.resize(nvars);
    for (uint32_t k = 0; k < nvars; ++k) finputs_[k] = fbatch_.in(k);
  }
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
      // A large level decided by intervals before its probes: the whole of it passes.
      if (intervalLevels_ && !q.probed && worthIntervals(cells.size()) && offsetsDecided(q, de)) {
        q.probed = true;  // with no failure this round, done
        continue;
      }
      // Straight into the evaluator's lanes, as many as fit before the batch is evaluated; a
      // query that already failed this round stops.
      for (size_t k = from; k < to && !failed_[i];) {
        const size_t n = std::min(to - k, kPairsPerCall - lanes_);
        if (floatSigns_ && lanes_ == 0) laneLo_ = {INFINITY, INFINITY, INFINITY}, laneHi_ = {-INFINITY, -INFINITY, -INFINITY};
        const size_t lane0 = 2 * lanes_;
        for (uint32_t c = 0; c < spatial; ++c) {  // coordinate by coordinate: the box in registers
          double* const out = inputs_[c] + lane0;
          const double ac = q.a[c], uc = u[c], vc = v[c], dc = de[c];
          double lo = INFINITY, hi = -INFINITY;
          for (size_t j = 0; j < n; ++j) {
            const double s = cells[k + j][0] + 1.0 / 3, t = cells[k + j][1] + 1.0 / 3;
            const double pc = ac + (uc * s + vc * t);  // a + s u + t v
            out[2 * j] = pc - dc, out[2 * j + 1] = pc + dc;
            lo = pc < lo ? pc : lo, hi = pc > hi ? pc : hi;
          }
          if (floatSigns_) {  // the float lanes and their box (classify); rounding is monotone, so
            // fl(lo - |dc|) and fl(hi + |dc|) hold every fl(pc -+ dc)
            float* const fout = finputs_[c] + lane0;
            if (lo - std::fabs(dc) >= -3.0e38 && hi + std::fabs(dc) <= 3.0e38)
              for (size_t j = 0; j < 2 * n; ++j) fout[j] = float(out[j]);  // in range: vectorised
            else
              for (size_t j = 0; j < 2 * n; ++j) fout[j] = narrow(out[j]);
            laneLo_[c] = std::min(laneLo_[c], lo - std::fabs(dc)), laneHi_[c] = std::max(laneHi_[c], hi + std::fabs(dc));
          }
        }
        for (size_t j = 0; j < n; ++j) laneQuery_[lanes_ + j] = i;
        k += n;
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

// Every sample of the level is a + s u + t v -+ de (u, v: the edges from a over m) with s, t >=
// 1/3 and s + t <= m - 1/3, a point of the triangle moved by -+de, computed with a few
// roundings: the boxes of the two moved triangles, widened by far more than those roundings,
// hold them all. f's interval over the inner box at or above 0 and over the outer one below 0
// (no NaN: a NaN-prone op widens to everything) puts the double value of every sample on the
// side the check asks (interval.h: outward rounding holds the double evaluation as well), so
// the level passes, as its samples would. Measured and dropped: the parts of an undecided
// triangle by midpoint subdivision (chair 256^3: half the samples, 1.4x the time; an interval
// evaluation costs far more than the float batch's points it spares).
bool Simplifier::offsetsDecided(const LevelQuery& q, const V3& de) {
  const uint32_t nvars = tape_->numVars(), spatial = std::min(nvars, 3u);
  ibox_.resize(nvars);
  for (uint32_t k = spatial; k < nvars; ++k) ibox_[k] = Interval(opt_.fixedCoords[k - 3]);
  V3 lo{}, hi{};
  double reach = 0;
  for (uint32_t k = 0; k < spatial; ++k) {
    lo[k] = std::min({q.a[k], q.b[k], q.c[k]}), hi[k] = std::max({q.a[k], q.b[k], q.c[k]});
    reach = std::max(reach, std::fabs(q.a[k]) + std::fabs(q.b[k]) + std::fabs(q.c[k]) + std::fabs(de[k]));
  }
  const double pad = 1e-9 * reach + 1e-300;
  if (!(pad < INFINITY)) return false;  // no box: coordinates beyond double's range
  ++intervalTries_;
  for (const double side : {-1.0, 1.0}) {
    for (uint32_t k = 0; k < spatial; ++k) ibox_[k] = Interval(lo[k] + side * de[k] - pad, hi[k] + side * de[k] + pad);
    const Interval f = ieval_.eval(*tape_, ibox_.data());
    // insideValue: f >= 0. Clear of 0 by a margin as well: the batch evaluator's formulas may
    // round differently from the interval ops' in the last bits where a bound grazes 0.
    const double margin = 1e-12 * (std::fabs(f.lo) + std::fabs(f.hi));
    if (!(side < 0 ? f.lo > margin : f.hi < -margin)) return false;
  }
  ++intervalPasses_;
  return true;
}

// With stopAbove: some query failed its last level maxK, so the call's answer (false) is known
// without the rest of the round. That query is answered (above maxK); the others keep the
// state they began the round with, and a resume redoes the round for them (the same answers).
bool Simplifier::endsAbove(std::vector<LevelQuery>& qs, int maxK) {
  for (uint32_t i = 0; i < qs.size(); ++i)
    if (failed_[i] && !qs[i].done && qs[i].level == maxK) {
      qs[i].level = maxK + 1, qs[i].probed = false, qs[i].done = true;
      return true;
    }
  return false;
}

// Evaluates the pending lanes (pairs: f(p - e d) must be inside, f(p + e d) outside) and marks
// failed_[query] where a pair is not. True if some pair failed.
bool Simplifier::crossed() {
  if (lanes_ == 0) return false;
  const uint32_t nvars = tape_->numVars();
  for (uint32_t k = 3; k < nvars; ++k) std::fill_n(inputs_[k], 2 * lanes_, opt_.fixedCoords[k - 3]);
  classify(2 * lanes_);
  stats_.modelEvals += 2 * lanes_;
  bool any = false;
  for (size_t i = 0; i < lanes_; ++i)
    if (!inside_[2 * i] || inside_[2 * i + 1]) failed_[laneQuery_[i]] = 1, any = true;
  lanes_ = 0;
  return any;
}

// Where |f_float| exceeds the bound B over the lanes' box, f_double is nonzero with f_float's
// sign (float_error.h), so insideValue (f >= 0) agrees; NaN and the lanes within B go to double.
// Each lane's value depends on its point alone (no extremum or field in a covered tape), so the
// double lanes give the same bits packed to the front.
void Simplifier::classify(size_t n) {
  const uint32_t nvars = tape_->numVars(), spatial = std::min(nvars, 3u);
  if (floatSigns_) {
    // The bound of a box holding the lanes (laneLo_, laneHi_ and the fixed coordinates): the
    // last one computed when it holds them (the rounds of one check sample the same triangles),
    // else one for the lanes' box 3 voxels wider. A tight box keeps the bound tight (the
    // R-functions' slopes are taken over it); the hull of all lanes so far left 80% of them to
    // double on examples/chair.hf; chair 128^3, one thread: pad 0.5 / 1.5 / 4 / 8 voxels
    // 1.21 / 1.16 / 1.13 / 1.35 CPU-s.
    bool held = bound_ >= 0;
    box_.resize(nvars);
    for (uint32_t k = 0; k < nvars; ++k) {
      const double lo = k < spatial ? laneLo_[k] : opt_.fixedCoords[k - 3], hi = k < spatial ? laneHi_[k] : lo;
      held = held && lo >= box_[k].lo && hi <= box_[k].hi;
    }
    if (!held) {
      for (uint32_t k = 0; k < nvars; ++k) {
        const double pad = k < spatial ? 3 * grid_.voxel : 0.0;
        box_[k] = k < spatial ? Interval{laneLo_[k] - pad, laneHi_[k] + pad} : Interval{opt_.fixedCoords[k - 3]};
      }
      bound_ = fbound_.bound(*tape_, box_.data());
    }
    if (bound_ < std::numeric_limits<double>::infinity()) {
      for (uint32_t k = spatial; k < nvars; ++k) std::fill_n(finputs_[k], n, narrow(opt_.fixedCoords[k - 3]));
      const float* f = fbatch_.eval(*tape_, n);
      const float bound = narrow(bound_) * (1 + 0x1p-20f);  // rounded up: |f| > it exceeds bound_
      redo_.clear();
      for (size_t i = 0; i < n; ++i) {
        if (std::fabs(f[i]) > bound) inside_[i] = f[i] >= 0;
        else redo_.push_back(uint32_t(i));
      }
      if (redo_.empty()) return;
      for (uint32_t k = 0; k < nvars; ++k)  // redo_[j] >= j: packing forward reads no written lane
        for (size_t j = 0; j < redo_.size(); ++j) inputs_[k][j] = inputs_[k][redo_[j]];
      const double* fd = batch_.eval(*tape_, redo_.size());
      for (size_t j = 0; j < redo_.size(); ++j) inside_[redo_[j]] = insideValue(fd[j]);
      return;
    }
  }
  const double* f = batch_.eval(*tape_, n);
  for (size_t i = 0; i < n; ++i) inside_[i] = insideValue(f[i]);
}

int Simplifier::levelOf(uint32_t t) {
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
bool Simplifier::errorPasses(std::vector<LevelQuery>& qs, const std::vector<V3>& gone, const std::vector<uint32_t>& replaced) {
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

}  // namespace simplify_detail
}  // namespace frep
