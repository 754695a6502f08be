// The extremum node's search engine (extremum.h): the eps-grid with quadratic refinement
// (Pasko-Minkowski, grid projection and eq. 4.2-4.4), interval branch-and-bound with a certified
// gap, sound interval bounds over X boxes, and Danskin gradients.
#include "frep/extremum/extremum.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "extremum/extremum_solver.h"

namespace frep {

namespace {
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

ExtremumSolver::Impl::Impl(const ExtremumSpec& spec, TapePtr b) : s(spec), body(std::move(b)) {
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

void ExtremumSolver::Impl::finish(ExtremumResult& r, const std::vector<double>& bestT) {
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
ExtremumResult ExtremumSolver::Impl::grid(const double* X) {
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
    if ((start / B) % 64 == 63) checkInterrupt();  // a fine grid over 3+ parameters is long
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

ExtremumSolver::ExtremumSolver(std::shared_ptr<const ExtremumSpec> spec, TapePtr body)
    : spec_(std::move(spec)) {
  if (!body) body = Tape::compile(spec_->body, spec_->outer() + spec_->hidden);
  impl_ = std::make_unique<Impl>(*spec_, std::move(body));
}
ExtremumSolver::~ExtremumSolver() = default;

// Every search starts by checking the run's interrupter (frep/interrupt/interrupter.h): the
// evaluators reach the searches without a parameter for it.
ExtremumResult ExtremumSolver::solve(const double* X, const double* warmT) {
  checkInterrupt();
  if (spec_->method == ExtremumMethod::Grid) return impl_->grid(X);
  return impl_->branchAndBound(X, warmT);
}
ExtremumResult ExtremumSolver::solveSign(const double* X) {
  checkInterrupt();
  if (spec_->method == ExtremumMethod::BranchAndBound && impl_->useTerms)
    return impl_->branchAndBoundTerms(X, nullptr, true);
  return solve(X);
}
ExtremumResult ExtremumSolver::solveGrid(const double* X) {
  checkInterrupt();
  return impl_->grid(X);
}
ExtremumResult ExtremumSolver::solveBranchAndBound(const double* X, const double* warmT) {
  checkInterrupt();
  return impl_->branchAndBound(X, warmT);
}
Interval ExtremumSolver::bound(const Interval* X, bool signOnly, bool budgetOnly) {
  checkInterrupt();
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
