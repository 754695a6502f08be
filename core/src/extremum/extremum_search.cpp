// The extremum solver's branch-and-bound searches (extremum.h): on the body's min-of-terms
// form, on natural interval bounds with pruned tapes, and the sound enclosure over X boxes.
#include "extremum/extremum_solver.h"

#include <string>

namespace frep {

// Branch-and-bound on the body's min-of-terms form (extremum_terms.h): the incumbent is
// polished by local ascent, and every box is contracted by constraint propagation against the
// cut best + tolerance before it is bounded (boxes that cannot reach the cut are dropped
// whole; the parts cut off a box are bounded by the cut).
//
// signOnly (cold searches only, warmT null): return as soon as the sign of the value the
// full search would return is known: the centre (its first incumbent) is above 0, no point of
// the domain reaches 0 (the root box contracted away against the cut 0), or a point above the
// tolerance is found by an ascent started from the best face centre (the full search then
// ends above max - tolerance > 0: certified searches). The value returned is the incumbent,
// with that sign, certified false and lo = hi = value. Otherwise the full search runs.
ExtremumResult ExtremumSolver::Impl::branchAndBoundTerms(const double* X, const double* warmT, bool signOnly) {
  tBest.assign(p, 0.0);
  tC.assign(p, 0.0);
  Search S(*this, X, tBest);
  // The start of the ascent: the warm start (else the centre). Only a sign search evaluates it
  // first (its value may decide the sign); the ascent's end, evaluated below, is not worse.
  if (signOnly) S.seed(warmT, tC);
  else S.start(warmT, tC);
  const double tol = s.tolerance;
  auto signKnown = [&]() {
    S.r.value = sign * S.bestV;
    S.r.lo = S.r.hi = S.r.value;
    S.r.certified = false;
    S.r.signDecided = true;
    finish(S.r, S.bestT);
    return std::move(S.r);
  };
  if (signOnly && S.bestV > 0) return signKnown();
  tf.setX(X);
  if (signOnly) {
    tLo.assign(plo.begin(), plo.end());
    tHi.assign(phi.begin(), phi.end());
    double ub = kInf, ub0 = kInf;
    uint32_t passes = 0;
    const bool alive = tf.contract(tLo.data(), tHi.data(), 0.0, ub, ub0, passes);
    S.r.intervalEvals += passes;
    if (!alive) return signKnown();  // every computed value is below 0: so is the incumbent's
  }
  {
    // Polish the warm start (else the domain centre): pruning then starts from a
    // nearly optimal value. A gradient evaluation is counted as 1 + p body evaluations.
    std::vector<double>& at = tAsc;
    at = tBest;
    if (signOnly) {
      // Start from the best of the centre and the centres of the domain's 2p faces (a
      // Minkowski body often peaks on the boundary of B's box), by the terms' values: fewer
      // steps to a value above 0. (Not for full searches: their values came out slightly less
      // accurate, e.g. the mesher's normals.)
      double bestF = tf.pointMin(at.data());
      tFace.resize(p);
      for (uint32_t k = 0; k < p; ++k)
        for (int side = 0; side < 2; ++side) {
          centre(plo.data(), phi.data(), tFace.data());
          tFace[k] = side ? phi[k] : plo[k];
          const double f = tf.pointMin(tFace.data());
          if (f > bestF) {
            bestF = f;
            at = tFace;
          }
        }
      S.r.pointEvals += 1 + 2 * p;
    }
    // signOnly: stop once above the tolerance (this ascent is not the full search's, whose
    // value can stay up to the tolerance below the maximum: only a point above it decides).
    const uint32_t calls = tf.ascend(at.data(), plo.data(), phi.data(), tol, signOnly ? tol : kInf);
    S.r.pointEvals += uint64_t(calls) * (1 + p);
    S.tryPoint(at.data());
  }
  if (signOnly && S.bestV > tol) return signKnown();
  if (signOnly) {  // undecided: the full search, counting the evaluations spent so far too
    ExtremumResult r = branchAndBoundTerms(X, warmT, false);
    r.pointEvals += S.r.pointEvals;
    r.intervalEvals += S.r.intervalEvals;
    extremumCounters().pointEvals.fetch_add(S.r.pointEvals, std::memory_order_relaxed);
    extremumCounters().intervalEvals.fetch_add(S.r.intervalEvals, std::memory_order_relaxed);
    return r;
  }
  pool.clear();
  heap.clear();
  std::vector<double>& clo = tLo;
  std::vector<double>& chi = tHi;
  // Contract, bound, and keep or drop one box.
  auto consider = [&](const double* lo, const double* hi) {
    clo.assign(lo, lo + p);
    chi.assign(hi, hi + p);
    const double cut = S.bestV + tol;
    double ub = kInf, ub0 = kInf;
    uint32_t passes = 0;
    const bool alive = tf.contract(clo.data(), chi.data(), cut, ub, ub0, passes);
    S.r.intervalEvals += passes;
    if (!alive) {  // nothing in the box reaches the cut
      S.prunedHi = std::max(S.prunedHi, std::min(ub0, cut));
      return;
    }
    bool shrunk = false;
    for (uint32_t k = 0; k < p; ++k) shrunk = shrunk || clo[k] != lo[k] || chi[k] != hi[k];
    if (shrunk) S.prunedHi = std::max(S.prunedHi, cut);  // the parts cut off stay below the cut
    if (ub > cut && boxFraction(clo.data(), chi.data()) <= kCentredFraction) {
      // Centred bound (about 2 + p evaluations): only on small boxes, where it is tighter.
      ub = std::min(ub, tf.upper(clo.data(), chi.data()));
      S.r.intervalEvals += 2 + p;
    }
    if (!S.drop(ub)) pushBox(clo.data(), chi.data(), ub);
  };
  consider(plo.data(), phi.data());
  std::vector<double>& lo = tLo2;
  std::vector<double>& hi = tHi2;
  std::vector<double>& half = tHalf;
  lo.resize(p);
  hi.resize(p);
  half.resize(p);
  auto atTop = [&](const HeapEntry& top) {
    centre(lo.data(), hi.data(), tC.data());
    S.tryPoint(tC.data());
    return !S.drop(top.first);
  };
  auto split = [&](uint32_t d, double mid) {
    std::copy(hi.begin(), hi.end(), half.begin());
    half[d] = mid;
    consider(lo.data(), half.data());
    std::copy(lo.begin(), lo.end(), half.begin());
    half[d] = mid;
    consider(half.data(), hi.data());
  };
  bestFirst(S, lo, hi, atTop, split);
  return std::move(S.r);
}

// Interval branch-and-bound over the parameter box (best-first on the upper bound), for
// bodies without a term form (nested extrema): natural interval bounds and pruned tapes.
ExtremumResult ExtremumSolver::Impl::branchAndBound(const double* X, const double* warmT) {
  if (useTerms) return branchAndBoundTerms(X, warmT);
  std::vector<Interval> Xi(n);
  for (uint32_t k = 0; k < n; ++k) Xi[k] = Interval(X[k]);
  std::vector<double> bestT(p), c(p);
  Search S(*this, X, bestT);
  const bool centreTried = S.seed(warmT, c);
  pool.clear();
  heap.clear();
  tapes.clear();
  auto push = [&](const double* lo, const double* hi, double ub, TapePtr tape) {
    tapes.push_back(std::move(tape));
    pushBox(lo, hi, ub);
  };
  // Each box carries the body pruned by its own interval evaluation (min/max/select decided
  // over the box), so deeper boxes walk shorter tapes; values are bit-identical inside.
  const bool prune = body->numChoices() > 0;
  {
    Interval root = evalBox(Xi.data(), plo.data(), phi.data());
    ++S.r.intervalEvals;
    if (!S.drop(root.hi)) push(plo.data(), phi.data(), root.hi, prune ? ie.pruned(body) : body);
  }
  std::vector<double> lo(p), hi(p), clo(p), chi(p);
  TapePtr boxTape;
  auto atTop = [&](const HeapEntry& top) {
    // The incumbent improves at the centres of the most promising boxes, evaluated when the
    // box comes off the heap (once per split rather than once per child).
    boxTape = tapes[top.second];
    if (top.second == 0 && centreTried) return true;
    centre(lo.data(), hi.data(), c.data());
    S.tryPoint(c.data(), boxTape.get());
    return !S.drop(top.first);
  };
  auto split = [&](uint32_t d, double mid) {
    for (int half = 0; half < 2; ++half) {
      clo = lo;
      chi = hi;
      if (half == 0) chi[d] = mid;
      else clo[d] = mid;
      Interval iv = evalBox(Xi.data(), clo.data(), chi.data(), boxTape.get());
      ++S.r.intervalEvals;
      if (S.drop(iv.hi)) continue;
      push(clo.data(), chi.data(), iv.hi, prune && boxTape->numChoices() > 0 ? ie.pruned(boxTape) : boxTape);
    }
  };
  bestFirst(S, lo, hi, atTop, split);
  return std::move(S.r);
}

// Sound enclosure over an X box: the upper side is the largest interval upper bound over a
// cover of the domain (refined best-first), the lower side the best interval lower bound of g
// at fixed u (sound: max_u g(X, u) >= g(X, u0) for every X). Stops as soon as the sign is
// decided, the enclosure is tighter than the tolerance, or the budget is spent.
Interval ExtremumSolver::Impl::bound(const Interval* X, bool signOnly, bool budgetOnly) {
  uint64_t evals = 0;
  std::vector<double> lo(p), hi(p), clo(p), chi(p), c(p);
  pool.clear();
  heap.clear();
  double L = -kInf;
  double wx = kInf;  // width due to the X box alone (at fixed u): what D refinement cannot remove
  auto witness = [&](const double* l, const double* h) {
    centre(l, h, c.data());
    Interval v = evalBox(X, c.data(), c.data());
    ++evals;
    L = std::max(L, v.lo);
    wx = std::min(wx, v.hi - v.lo);
  };
  Interval root = evalBox(X, plo.data(), phi.data());
  ++evals;
  pushBox(plo.data(), phi.data(), root.hi);
  witness(plo.data(), phi.data());
  // Soft budget: intervalBudget evaluations, then continue (up to 8x) only while the
  // enclosure is much wider than what the X box alone explains (tiny X boxes, e.g. inside an
  // outer search, get tight bounds; large sampler boxes stop early).
  const uint32_t soft = std::max<uint32_t>(s.intervalBudget, 3);
  const uint32_t hard = 8 * soft;
  while (!heap.empty() && evals + 3 <= hard) {
    const double U = std::max(L, heap.front().first);
    if ((signOnly && (L > 0 || U < 0)) || U - L <= s.tolerance) break;
    if (evals + 3 > soft && (budgetOnly || U - L <= 4.0 * wx)) break;
    const HeapEntry top = popBox(lo, hi);
    const uint32_t d = widestDim(lo.data(), hi.data());
    const double mid = 0.5 * (lo[d] + hi[d]);
    if (!(mid > lo[d] && mid < hi[d])) {
      pushBox(lo.data(), hi.data(), top.first);
      break;
    }
    for (int half = 0; half < 2; ++half) {
      clo = lo;
      chi = hi;
      if (half == 0) chi[d] = mid;
      else clo[d] = mid;
      Interval iv = evalBox(X, clo.data(), chi.data());
      ++evals;
      if (iv.hi <= L) continue;  // cannot raise the upper bound above L
      pushBox(clo.data(), chi.data(), iv.hi);
    }
    if (!heap.empty()) {
      const double* t = &pool[size_t(heap.front().second) * 2 * p];
      witness(t, t + p);
    }
  }
  const double U = heap.empty() ? L : std::max(L, heap.front().first);
  auto& cn = extremumCounters();
  cn.boundCalls.fetch_add(1, std::memory_order_relaxed);
  cn.boundIntervalEvals.fetch_add(evals, std::memory_order_relaxed);
  return sign > 0 ? Interval(L, U) : Interval(-U, -L);
}

}  // namespace frep
