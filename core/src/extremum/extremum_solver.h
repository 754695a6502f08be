// Internal to the extremum solver: the state of ExtremumSolver (extremum.h) and its search
// building blocks. Its members are defined in extremum.cpp (set-up, the eps-grid) and
// extremum_search.cpp (branch-and-bound, sound bounds over X boxes).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "extremum/extremum_terms.h"
#include "frep/evaluators/eval.h"
#include "frep/extremum/extremum.h"
#include "frep/interrupt/interrupter.h"

namespace frep {

struct ExtremumSolver::Impl {
  const ExtremumSpec& s;
  TapePtr body;
  uint32_t n, m, p;
  double sign;                     // search max of sign * g
  std::vector<double> plo, phi;    // parameter box
  std::vector<double> scale;       // parameter unit -> length (angles: radius)
  PointEvaluator pe;
  IntervalEvaluator ie;
  BatchEvaluator<double> be;
  GradientEvaluator ge;
  std::vector<double> x;           // n + m body coordinates
  std::vector<Interval> xi;        // n + m body intervals
  std::vector<Interval> ti;        // p parameter intervals
  std::vector<double> tt;          // p parameters
  // branch-and-bound storage: boxes as 2p doubles in a pool, heap of (upper, index)
  std::vector<double> pool;
  std::vector<std::pair<double, uint32_t>> heap;
  std::vector<TapePtr> tapes;  // B&B: the body pruned to each box (interval choices of its parent)
  std::vector<double> gv;          // grid values
  detail::TermForm tf;             // B&B: the objective as a min of terms (extremum_terms.h)
  bool useTerms = false;
  static constexpr double kInf = std::numeric_limits<double>::infinity();

  Impl(const ExtremumSpec& spec, TapePtr b);

  // Parameters -> hidden variables u (written to x[n..n+m)).
  void toU(const double* t, double* u) const {
    if (s.domain == DomainKind::Box) {
      for (uint32_t k = 0; k < m; ++k) u[k] = t[k];
      return;
    }
    double r = s.domain == DomainKind::Ball ? t[0] : s.radius;
    const double* ang = s.domain == DomainKind::Ball ? t + 1 : t;
    for (uint32_t k = 0; k + 1 < m; ++k) {
      u[k] = r * std::cos(ang[k]);
      r *= std::sin(ang[k]);
    }
    u[m - 1] = r;
  }
  void toU(const Interval* t, Interval* u) const {
    if (s.domain == DomainKind::Box) {
      for (uint32_t k = 0; k < m; ++k) u[k] = t[k];
      return;
    }
    Interval r = s.domain == DomainKind::Ball ? t[0] : Interval(s.radius);
    const Interval* ang = s.domain == DomainKind::Ball ? t + 1 : t;
    for (uint32_t k = 0; k + 1 < m; ++k) {
      u[k] = applyOp(Op::Mul, r, applyOp(Op::Cos, ang[k]));
      r = applyOp(Op::Mul, r, applyOp(Op::Sin, ang[k]));
    }
    u[m - 1] = r;
  }

  double evalPoint(const double* X, const double* t, const Tape* tape = nullptr) {
    for (uint32_t k = 0; k < n; ++k) x[k] = X[k];
    toU(t, x.data() + n);
    return sign * pe.eval(tape ? *tape : *body, x.data());
  }
  // Interval of sign * g over (X box) x u(t box).
  Interval evalBox(const Interval* X, const double* tlo, const double* thi, const Tape* tape = nullptr) {
    for (uint32_t k = 0; k < n; ++k) xi[k] = X[k];
    for (uint32_t k = 0; k < p; ++k) ti[k] = Interval(tlo[k], thi[k]);
    toU(ti.data(), xi.data() + n);
    Interval v = ie.eval(tape ? *tape : *body, xi.data());
    if (std::isnan(v.lo) || std::isnan(v.hi)) return Interval::everything();
    return sign > 0 ? v : Interval(-v.hi, -v.lo);
  }

  // Largest side of a parameter box relative to the domain's.
  double boxFraction(const double* lo, const double* hi) const {
    double f = 0.0;
    for (uint32_t k = 0; k < p; ++k)
      if (phi[k] > plo[k]) f = std::max(f, (hi[k] - lo[k]) / (phi[k] - plo[k]));
    return f;
  }
  // B&B boxes get the centred bound once their sides are at most this fraction of the domain's
  // (measured: on larger boxes it rarely beats the natural bound after contraction).
  static constexpr double kCentredFraction = 1.0 / 16.0;

  uint32_t widestDim(const double* lo, const double* hi) const {
    uint32_t best = 0;
    double w = -1;
    for (uint32_t k = 0; k < p; ++k) {
      double wk = (hi[k] - lo[k]) * scale[k];
      if (wk > w) {
        w = wk;
        best = k;
      }
    }
    return best;
  }

  void finish(ExtremumResult& r, const std::vector<double>& bestT);

  ExtremumResult grid(const double* X);

  // ---- branch-and-bound building blocks (both searches and bound) ----

  // Boxes are 2p doubles (lo, hi) in the pool; the heap holds (upper bound, box index), the
  // largest upper bound on top. A box's index is also its index in tapes.
  using HeapEntry = std::pair<double, uint32_t>;
  struct HeapLess {
    bool operator()(const HeapEntry& a, const HeapEntry& b) const { return a.first < b.first; }
  };
  void pushBox(const double* lo, const double* hi, double ub) {
    const uint32_t id = static_cast<uint32_t>(pool.size() / (2 * p));
    pool.insert(pool.end(), lo, lo + p);
    pool.insert(pool.end(), hi, hi + p);
    heap.emplace_back(ub, id);
    std::push_heap(heap.begin(), heap.end(), HeapLess());
  }
  // Takes the box with the largest upper bound off the heap, into lo and hi.
  HeapEntry popBox(std::vector<double>& lo, std::vector<double>& hi) {
    std::pop_heap(heap.begin(), heap.end(), HeapLess());
    const HeapEntry top = heap.back();
    heap.pop_back();
    const double* b = &pool[size_t(top.second) * 2 * p];
    std::copy(b, b + p, lo.begin());
    std::copy(b + p, b + 2 * p, hi.begin());
    return top;
  }
  void centre(const double* lo, const double* hi, double* c) const {
    for (uint32_t k = 0; k < p; ++k) c[k] = 0.5 * (lo[k] + hi[k]);
  }

  // One branch-and-bound search at X: the incumbent (best value and its parameters), the
  // largest upper bound of the boxes dropped on the way, and the result being filled in.
  struct Search {
    Search(Impl& impl, const double* x, std::vector<double>& best) : I(impl), X(x), bestT(best) {}
    Impl& I;
    const double* X;
    std::vector<double>& bestT;
    ExtremumResult r;
    double bestV = -kInf;
    double prunedHi = -kInf;

    // The objective at t (on tape; default: the body), kept when it beats the incumbent.
    void tryPoint(const double* t, const Tape* tape = nullptr) {
      const double v = I.evalPoint(X, t, tape);
      ++r.pointEvals;
      if (v > bestV) {
        bestV = v;
        std::copy(t, t + I.p, bestT.begin());
      }
    }
    // (The centre of the root box is tried anyway when the search splits it.)
    // The warm start when it lies in the domain, else the domain's centre (written to c), as
    // bestT, not evaluated. Returns whether it is the centre.
    bool start(const double* warmT, std::vector<double>& c) {
      I.centre(I.plo.data(), I.phi.data(), c.data());
      bool inside = warmT;
      for (uint32_t k = 0; inside && k < I.p; ++k) inside = warmT[k] >= I.plo[k] && warmT[k] <= I.phi[k];
      if (inside) std::copy(warmT, warmT + I.p, bestT.begin());
      else std::copy(c.begin(), c.end(), bestT.begin());
      return !inside;
    }
    // start, and the point evaluated. Returns whether it is the centre.
    bool seed(const double* warmT, std::vector<double>& c) {
      const bool atCentre = start(warmT, c);
      tryPoint(atCentre ? c.data() : warmT);
      return atCentre;
    }
    // Whether a box with upper bound ub is dropped: it cannot beat the incumbent by more than
    // the tolerance (its bound is kept in prunedHi).
    bool drop(double ub) {
      if (!(ub <= bestV + I.s.tolerance)) return false;
      prunedHi = std::max(prunedHi, ub);
      return true;
    }
  };

  // The best-first loop of both searches, over the boxes in the heap: stops when the largest
  // upper bound cannot beat the incumbent by more than the tolerance (certified), after maxBoxes
  // splits (not certified) or at a box too small to split (certified if its bound is within the
  // tolerance). atTop(top) may try the box's centre and returns false when the box is dropped;
  // split(d, mid) bounds and keeps the halves of [lo, hi] cut at mid along d. Then fills in the
  // result: the incumbent's value, and the gap up to the largest bound left or dropped.
  template <class AtTop, class Split>
  void bestFirst(Search& S, std::vector<double>& lo, std::vector<double>& hi, AtTop&& atTop, Split&& split) {
    const double tol = s.tolerance;
    uint32_t splits = 0;
    double hiBound = -kInf;
    bool certified = true;
    while (!heap.empty()) {
      const HeapEntry top = popBox(lo, hi);
      if (top.first <= S.bestV + tol) {
        hiBound = top.first;  // the largest remaining upper bound
        break;
      }
      if (splits >= s.maxBoxes) {
        hiBound = top.first;
        certified = false;
        break;
      }
      if (!atTop(top)) continue;
      if (++splits % 64 == 0) checkInterrupt();  // up to maxBoxes splits in one search
      const uint32_t d = widestDim(lo.data(), hi.data());
      const double mid = 0.5 * (lo[d] + hi[d]);
      if (!(mid > lo[d] && mid < hi[d])) {  // cannot split further: keep its bound
        hiBound = top.first;
        certified = top.first <= S.bestV + tol;
        break;
      }
      split(d, mid);
    }
    ExtremumResult& r = S.r;
    double hiAll = std::max({hiBound, S.prunedHi, S.bestV});
    r.value = sign * S.bestV;
    r.certified = certified;
    if (sign > 0) {
      r.lo = S.bestV;
      r.hi = hiAll;
    } else {
      r.lo = -hiAll;
      r.hi = -S.bestV;
    }
    finish(r, S.bestT);
  }

  ExtremumResult branchAndBoundTerms(const double* X, const double* warmT, bool signOnly = false);
  std::vector<double> tBest, tC, tLo, tHi, tLo2, tHi2, tHalf, tAsc, tFace;

  ExtremumResult branchAndBound(const double* X, const double* warmT);

  Interval bound(const Interval* X, bool signOnly, bool budgetOnly);
};


}  // namespace frep
