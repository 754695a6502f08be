// The extremum node's search engine (extremum.h): the eps-grid with quadratic refinement
// (Pasko-Minkowski, grid projection and eq. 4.2-4.4), interval branch-and-bound with a certified
// gap, sound interval bounds over X boxes, and Danskin gradients.
#include "frep/extremum/extremum.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "extremum/extremum_terms.h"

namespace frep {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPiD = 3.14159265358979323846;
}  // namespace

uint32_t ExtremumSpec::numParams() const {
  return domain == DomainKind::Sphere ? (hidden > 0 ? hidden - 1 : 0) : hidden;
}

ExtremumCounters& extremumCounters() {
  static ExtremumCounters c;
  return c;
}
void resetExtremumCounters() {
  auto& c = extremumCounters();
  c.searches = 0;
  c.pointEvals = 0;
  c.intervalEvals = 0;
  c.uncertified = 0;
  c.signDecided = 0;
  c.widestGap = 0.0;
  c.boundCalls = 0;
  c.boundIntervalEvals = 0;
}

Expr extremum(ExtremumSpec s) {
  auto bad = [](const std::string& what) { throw std::invalid_argument("extremum: " + what); };
  const uint32_t n = s.outer(), m = s.hidden;
  if (m == 0) bad("hidden: need at least one hidden variable");
  if (numVars(s.body) > n + m)
    bad("body uses x[" + std::to_string(numVars(s.body) - 1) + "] but has only n + m = " +
        std::to_string(n + m) + " variables (n = inputs.size(), m = hidden)");
  if (numParams(s.body) > 0) bad("body: parameters must be bound before building an extremum");
  if (s.domain == DomainKind::Box) {
    if (s.lo.size() != m || s.hi.size() != m) bad("lo/hi: need one bound per hidden variable");
    for (uint32_t i = 0; i < m; ++i)
      if (!(s.lo[i] <= s.hi[i]) || !std::isfinite(s.lo[i]) || !std::isfinite(s.hi[i]))
        bad("lo/hi: bounds of hidden variable " + std::to_string(i) + " must be finite with lo <= hi");
  } else {
    if (m < 2) bad("sphere/ball domain: need m >= 2 hidden variables (use a box for m = 1)");
    if (!(s.radius > 0) || !std::isfinite(s.radius)) bad("radius must be positive and finite");
  }
  if (!(s.eps > 0)) bad("eps must be positive");
  if (!(s.tolerance > 0)) bad("tolerance must be positive");
  if (s.maxBoxes == 0) bad("maxBoxes must be positive");
  return Expr::makeExtremum(std::make_shared<const ExtremumSpec>(std::move(s)));
}

// ---- solver --------------------------------------------------------------------------------

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

  Impl(const ExtremumSpec& spec, TapePtr b) : s(spec), body(std::move(b)) {
    n = s.outer();
    m = s.hidden;
    p = s.numParams();
    sign = s.kind == ExtremumKind::Max ? 1.0 : -1.0;
    x.assign(n + m, 0.0);
    xi.assign(n + m, Interval());
    ie.setExtremumSignOnly(false);  // nested extrema in the body: tight bounds for this search
    ti.assign(p, Interval());
    tt.assign(p, 0.0);
    if (s.domain == DomainKind::Box) {
      plo = s.lo;
      phi = s.hi;
      scale.assign(p, 1.0);
    } else {
      uint32_t k = 0;
      if (s.domain == DomainKind::Ball) {
        plo.push_back(0.0);
        phi.push_back(s.radius);
        scale.push_back(1.0);
        ++k;
      }
      // Hyperspherical angles: m - 2 polar angles in [0, pi], the last in [0, 2 pi].
      for (uint32_t a = 0; a + 1 < m; ++a, ++k) {
        plo.push_back(0.0);
        phi.push_back(a + 2 < m ? kPiD : 2.0 * kPiD);
        scale.push_back(s.radius);
      }
    }
    if (s.method == ExtremumMethod::BranchAndBound) {
      // The objective sign * g over (X, t): u written in the search parameters t.
      std::vector<Expr> uOfT;
      if (s.domain == DomainKind::Box) {
        for (uint32_t k = 0; k < m; ++k) uOfT.push_back(Expr::x(n + k));
      } else {
        Expr r = s.domain == DomainKind::Ball ? Expr::x(n) : Expr(s.radius);
        const uint32_t a0 = s.domain == DomainKind::Ball ? n + 1 : n;
        for (uint32_t k = 0; k + 1 < m; ++k) {  // as toU below
          uOfT.push_back(r * cos(Expr::x(a0 + k)));
          r = r * sin(Expr::x(a0 + k));
        }
        uOfT.push_back(r);
      }
      tf.build(sign > 0 ? s.body : -s.body, n, p, uOfT);
      useTerms = tf.ok();
    }
  }

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

  void finish(ExtremumResult& r, const std::vector<double>& bestT) {
    r.t = bestT;
    r.u.assign(m, 0.0);
    toU(bestT.data(), r.u.data());
    auto& c = extremumCounters();
    c.searches.fetch_add(1, std::memory_order_relaxed);
    c.pointEvals.fetch_add(r.pointEvals, std::memory_order_relaxed);
    c.intervalEvals.fetch_add(r.intervalEvals, std::memory_order_relaxed);
    if (s.method != ExtremumMethod::BranchAndBound || r.certified) return;
    if (r.signDecided) {
      c.signDecided.fetch_add(1, std::memory_order_relaxed);
      return;
    }
    c.uncertified.fetch_add(1, std::memory_order_relaxed);
    const double gap = r.hi - r.lo;
    double seen = c.widestGap.load(std::memory_order_relaxed);
    while (!(seen >= gap) && !c.widestGap.compare_exchange_weak(seen, gap, std::memory_order_relaxed)) {
    }
  }

  // Pasko-Minkowski's eps-grid: every node of a grid with step <= eps (per parameter, in length
  // units), then quadratic refinement (eq. 4.3-4.4) on each grid line through three nodes whose
  // middle one is a local maximum along that line. Max is the union R-function with a = 1.
  ExtremumResult grid(const double* X) {
    ExtremumResult r;
    std::vector<uint32_t> cnt(p);
    std::vector<double> step(p);
    size_t total = 1;
    for (uint32_t k = 0; k < p; ++k) {
      const double w = (phi[k] - plo[k]) * scale[k];
      cnt[k] = std::max<uint32_t>(2, static_cast<uint32_t>(std::ceil(w / s.eps - 1e-9)) + 1);
      if (w == 0) cnt[k] = 1;
      step[k] = cnt[k] > 1 ? (phi[k] - plo[k]) / double(cnt[k] - 1) : 0.0;
      total *= cnt[k];
    }
    if (total > (size_t(1) << 31)) throw std::runtime_error("extremum grid: too many nodes (raise eps)");
    gv.resize(total);
    // Batch evaluation of the nodes: X fixed, u varying (node index: last parameter fastest).
    constexpr size_t B = BatchEvaluator<double>::kBatch;
    be.reserve(*body);
    std::vector<double> t(p), u(m);
    size_t best = 0;
    for (size_t start = 0; start < total; start += B) {
      const size_t count = std::min(B, total - start);
      for (size_t i = 0; i < count; ++i) {
        size_t idx = start + i;
        for (uint32_t k = p; k-- > 0;) {
          t[k] = plo[k] + double(idx % cnt[k]) * step[k];
          idx /= cnt[k];
        }
        toU(t.data(), u.data());
        for (uint32_t k = 0; k < n; ++k) be.in(k)[i] = X[k];
        for (uint32_t k = 0; k < m; ++k) be.in(n + k)[i] = u[k];
      }
      const double* out = be.eval(*body, count);
      for (size_t i = 0; i < count; ++i) {
        double v = sign * out[i];
        if (std::isnan(v)) v = -kInf;
        gv[start + i] = v;
        if (v > gv[best]) best = start + i;
      }
    }
    r.pointEvals = total;
    auto nodeT = [&](size_t idx, double* tp) {
      for (uint32_t k = p; k-- > 0;) {
        tp[k] = plo[k] + double(idx % cnt[k]) * step[k];
        idx /= cnt[k];
      }
    };
    double bestV = gv[best];
    std::vector<double> bestT(p);
    nodeT(best, bestT.data());
    // Quadratic refinement along each axis.
    size_t stride = 1;
    for (uint32_t k = p; k-- > 0;) {
      if (cnt[k] >= 3) {
        for (size_t idx = 0; idx < total; ++idx) {
          const size_t j = (idx / stride) % cnt[k];
          if (j == 0 || j + 1 >= cnt[k]) continue;
          const double f0 = gv[idx - stride], f1 = gv[idx], f2 = gv[idx + stride];
          if (!(f1 >= f0 && f1 >= f2)) continue;
          const double den = f2 - 2.0 * f1 + f0;
          if (!(den < 0)) continue;
          const double c0 = 0.5 - (f1 - f0) / den;  // eq. 4.4, in steps from node j - 1
          if (!(c0 > 0 && c0 < 2) || c0 == 1.0) continue;
          nodeT(idx, t.data());
          t[k] = plo[k] + (double(j - 1) + c0) * step[k];
          const double v = evalPoint(X, t.data());
          ++r.pointEvals;
          if (v > bestV) {
            bestV = v;
            bestT = t;
          }
        }
      }
      stride *= cnt[k];
    }
    r.value = sign * bestV;
    // The grid's value is a real body value: one side is certain, the other needs Lipschitz
    // information (see extremum.h).
    if (sign > 0) {
      r.lo = r.value;
      r.hi = kInf;
    } else {
      r.lo = -kInf;
      r.hi = r.value;
    }
    r.certified = false;
    finish(r, bestT);
    return r;
  }

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
      ++splits;
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
  ExtremumResult branchAndBoundTerms(const double* X, const double* warmT, bool signOnly = false) {
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
  std::vector<double> tBest, tC, tLo, tHi, tLo2, tHi2, tHalf, tAsc, tFace;

  // Interval branch-and-bound over the parameter box (best-first on the upper bound), for
  // bodies without a term form (nested extrema): natural interval bounds and pruned tapes.
  ExtremumResult branchAndBound(const double* X, const double* warmT) {
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
  Interval bound(const Interval* X, bool signOnly, bool budgetOnly) {
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
};

ExtremumSolver::ExtremumSolver(std::shared_ptr<const ExtremumSpec> spec, TapePtr body)
    : spec_(std::move(spec)) {
  if (!body) body = Tape::compile(spec_->body, spec_->outer() + spec_->hidden);
  impl_ = std::make_unique<Impl>(*spec_, std::move(body));
}
ExtremumSolver::~ExtremumSolver() = default;

ExtremumResult ExtremumSolver::solve(const double* X, const double* warmT) {
  if (spec_->method == ExtremumMethod::Grid) return impl_->grid(X);
  return impl_->branchAndBound(X, warmT);
}
ExtremumResult ExtremumSolver::solveSign(const double* X) {
  if (spec_->method == ExtremumMethod::BranchAndBound && impl_->useTerms)
    return impl_->branchAndBoundTerms(X, nullptr, true);
  return solve(X);
}
ExtremumResult ExtremumSolver::solveGrid(const double* X) { return impl_->grid(X); }
ExtremumResult ExtremumSolver::solveBranchAndBound(const double* X, const double* warmT) {
  return impl_->branchAndBound(X, warmT);
}
Interval ExtremumSolver::bound(const Interval* X, bool signOnly, bool budgetOnly) {
  return impl_->bound(X, signOnly, budgetOnly);
}

double ExtremumSolver::gradient(const double* X, double* grad) {
  ExtremumResult r = solve(X);
  Impl& I = *impl_;
  // Danskin needs the arg-extremum itself, which the search only pins down to where g is within
  // the tolerance: polish it with coordinate-wise parabolic steps (eq. 4.4's interpolation with
  // a shrinking step), keeping only real improvements.
  if (I.p > 0) {
    std::vector<double> t = r.t;
    double best = I.sign * r.value;
    double h = 0;
    for (uint32_t k = 0; k < I.p; ++k) h = std::max(h, (I.phi[k] - I.plo[k]) * 1e-3);
    for (int it = 0; it < 40 && h > 1e-13; ++it) {
      bool moved = false;
      for (uint32_t k = 0; k < I.p; ++k) {
        std::vector<double> tm = t, tp = t;
        tm[k] = std::max(I.plo[k], t[k] - h);
        tp[k] = std::min(I.phi[k], t[k] + h);
        const double fm = I.evalPoint(X, tm.data()), fp = I.evalPoint(X, tp.data());
        std::vector<double> cand = t;
        double fc = best;
        const double den = fp - 2.0 * best + fm;
        if (den < 0 && tp[k] - t[k] == h && t[k] - tm[k] == h) {
          cand[k] = t[k] + 0.5 * h * (fm - fp) / den;
          cand[k] = std::min(I.phi[k], std::max(I.plo[k], cand[k]));
          fc = I.evalPoint(X, cand.data());
        }
        if (fm > best && fm >= fc && fm >= fp) { t = tm; best = fm; moved = true; }
        else if (fp > best && fp >= fc) { t = tp; best = fp; moved = true; }
        else if (fc > best) { t = cand; best = fc; moved = true; }
      }
      if (!moved) h *= 0.25;
    }
    r.t = t;
    r.value = I.sign * best;
    I.toU(t.data(), r.u.data());
  }
  for (uint32_t k = 0; k < I.n; ++k) I.x[k] = X[k];
  for (uint32_t k = 0; k < I.m; ++k) I.x[I.n + k] = r.u[k];
  std::vector<double> g(I.n + I.m);
  I.ge.eval(*I.body, I.x.data(), g.data());
  for (uint32_t k = 0; k < I.n; ++k) grad[k] = g[k];
  return r.value;
}

// ---- per-evaluator slots ---------------------------------------------------------------------

ExtremumSlots::ExtremumSlots() = default;
ExtremumSlots::~ExtremumSlots() = default;
ExtremumSlots::ExtremumSlots(const ExtremumSlots&) {}
ExtremumSlots& ExtremumSlots::operator=(const ExtremumSlots& o) {
  if (this != &o) {
    rootId_ = 0;
    solvers_.clear();
  }
  return *this;
}

ExtremumSolver& ExtremumSlots::get(const Tape& tape, uint32_t entry) {
  const uint64_t root = tape.root()->id();
  if (root != rootId_) {
    solvers_.clear();
    rootId_ = root;
  }
  if (solvers_.size() <= entry) solvers_.resize(tape.extrema().size());
  auto& slot = solvers_[entry];
  if (!slot) {
    const ExtremumEntry& e = tape.extrema()[entry];
    slot = std::make_unique<ExtremumSolver>(e.spec, e.body);
  }
  return *slot;
}

}  // namespace frep
