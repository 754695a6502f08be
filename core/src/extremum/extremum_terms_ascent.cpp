// The min-of-terms form's point values and gradients, and the local ascent that polishes the
// branch-and-bound incumbent (extremum_terms.h).
#include "extremum/extremum_terms.h"
#include "evaluators/interval_fast.h"
#include "frep/expressions/sin_cos.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <unordered_map>

#include "extremum/term_intervals.h"
#include "extremum/term_step_grad.h"

namespace frep {
namespace detail {

namespace {
// Values of the common ops as applyOp computes them (same bits), without its call.
inline double pointValue(Op op, double a, double b, double c, double imm) {
  switch (op) {
    case Op::Add: return a + b;
    case Op::Sub: return a - b;
    case Op::Mul: return a * b;
    case Op::Neg: return -a;
    case Op::Min: return b < a ? b : a;
    case Op::Max: return b > a ? b : a;
    default: return applyOp(op, a, b, c, imm);
  }
}
}  // namespace

template <uint32_t P>
double TermForm::pointGradImpl(const double* t) {
  const uint32_t p = P ? P : p_;
  double* pv = pv_.data();
  const double* pd = pd_.data();
  for (const Step& q : steps_) {
    if (q.op == Op::Var) {
      pv[q.k] = t[q.var];
      continue;  // constant gradient (build)
    }
    const double a = pv[q.a], b = pv[q.b];
    const double v = pointValue(q.op, a, b, pv[q.c], q.imm);
    pv[q.k] = v;
    if (!q.constGrad) stepGrad<P>(q, a, b, v);
  }
  const size_t K = terms_.size();
  tv_.resize(K);
  tg_.resize(K * p);
  double f = kInf;
  for (size_t i = 0; i < K; ++i) {
    const size_t node = size_t(terms_[i]);
    tv_[i] = pv[node];
    const bool dep = nodes_[node].dep;
    for (uint32_t j = 0; j < p; ++j) tg_[i * p + j] = dep ? pd[node * p + j] : 0.0;
    f = std::min(f, tv_[i]);
  }
  return f;
}

double TermForm::pointMin(const double* t) {
  double* pv = pv_.data();
  for (const Step& q : steps_) pv[q.k] = q.op == Op::Var ? t[q.var] : pointValue(q.op, pv[q.a], pv[q.b], pv[q.c], q.imm);
  double f = kInf;
  for (int32_t node : terms_) f = std::min(f, pv[size_t(node)]);
  return f;
}

double TermForm::pointGrad(const double* t) {
  switch (p_) {
    case 1: return pointGradImpl<1>(t);
    case 2: return pointGradImpl<2>(t);
    case 3: return pointGradImpl<3>(t);
    default: return pointGradImpl<0>(t);
  }
}

uint32_t TermForm::ascend(double* t, const double* plo, const double* phi, double tol, double stopAbove) {
  switch (p_) {
    case 1: return ascendImpl<1>(t, plo, phi, tol, stopAbove);
    case 2: return ascendImpl<2>(t, plo, phi, tol, stopAbove);
    case 3: return ascendImpl<3>(t, plo, phi, tol, stopAbove);
    default: return ascendImpl<0>(t, plo, phi, tol, stopAbove);
  }
}

template <uint32_t P>
uint32_t TermForm::ascendImpl(double* t, const double* plo, const double* phi, double tol, double stopAbove) {
  lastF_ = -kInf;
  const size_t K = terms_.size();
  const uint32_t p = P ? P : p_;
  uint32_t calls = 1;
  double F = pointGradImpl<P>(t);
  lastF_ = F;
  if (!std::isfinite(F) || F > stopAbove) return calls;
  std::vector<double>& av = av_;
  std::vector<double>& ag = ag_;
  av.assign(tv_.begin(), tv_.end());
  ag.assign(tg_.begin(), tg_.end());
  double width = 0.0, gmax = 0.0;
  for (uint32_t k = 0; k < p; ++k) width = std::max(width, phi[k] - plo[k]);
  for (size_t i = 0; i < K; ++i) {
    double g2 = 0.0;
    for (uint32_t j = 0; j < p; ++j) g2 += ag[i * p + j] * ag[i * p + j];
    if (std::isfinite(g2)) gmax = std::max(gmax, std::sqrt(g2));
  }
  if (!(gmax > 0.0) || !(width > 0.0)) return calls;
  double mu = gmax / (0.125 * width);
  std::vector<double>& lam = lam_;
  std::vector<double>& w = w_;
  std::vector<double>& t1 = t1_;
  std::vector<uint32_t>& S = sel_;
  w.resize(p);
  t1.resize(p);
  for (int it = 0; it < 8 && calls < 8; ++it) {
    // Terms that can become active within the step scale.
    const double reach = 2.0 * gmax * gmax / mu;
    S.clear();
    size_t i0 = 0;
    for (size_t i = 0; i < K; ++i) {
      if (av[i] < av[i0]) i0 = i;
      if (av[i] <= F + reach && std::isfinite(av[i])) S.push_back(uint32_t(i));
    }
    lam.assign(K, 0.0);
    lam[i0] = 1.0;
    for (uint32_t j = 0; j < p; ++j) w[j] = ag[i0 * p + j];
    // Per pair (a, b) of S: the gradient difference g_b - g_a and its square norm, computed on
    // first use and kept for the later sweeps.
    const size_t ns = S.size();
    pairDone_.assign(ns * ns, 0);
    pairD_.resize(ns * ns * p);
    pairDD_.resize(ns * ns);
    for (int sweep = 0; sweep < 6 && ns > 1; ++sweep) {
      bool moved = false;  // a sweep that moves nothing leaves the same state for the next
      for (size_t ia = 0; ia < ns; ++ia) {
        const uint32_t a = S[ia];
        if (lam[a] <= 0.0) continue;  // (lam[a] only decreases while a gives weight away)
        for (size_t ib = 0; ib < ns; ++ib) {
          const uint32_t b = S[ib];
          if (a == b || lam[a] <= 0.0) continue;
          const size_t pair = ia * ns + ib;
          double* D = &pairD_[pair * p];
          if (!pairDone_[pair]) {
            double dd = 0.0;
            for (uint32_t j = 0; j < p; ++j) {
              D[j] = ag[b * p + j] - ag[a * p + j];
              dd += D[j] * D[j];
            }
            pairDD_[pair] = dd;
            pairDone_[pair] = 1;
          }
          double wd = 0.0;
          for (uint32_t j = 0; j < p; ++j) wd += w[j] * D[j];
          const double dd = pairDD_[pair];
          double sMove;
          if (dd > 0.0) sMove = -(mu * (av[b] - av[a]) + wd) / dd;
          else sMove = av[b] < av[a] ? lam[a] : 0.0;
          sMove = std::min(lam[a], sMove);
          if (!(sMove > 0.0)) continue;
          lam[a] -= sMove;
          lam[b] += sMove;
          for (uint32_t j = 0; j < p; ++j) w[j] += sMove * D[j];
          moved = true;
        }
      }
      if (!moved) break;
    }
    for (uint32_t j = 0; j < p; ++j) t1[j] = std::min(phi[j], std::max(plo[j], t[j] + w[j] / mu));
    double pred = kInf;
    for (size_t i = 0; i < K; ++i) {
      double v = av[i];
      for (uint32_t j = 0; j < p; ++j) v += ag[i * p + j] * (t1[j] - t[j]);
      pred = std::min(pred, v);
    }
    pred -= F;
    if (!(pred > 1e-3 * tol)) break;
    ++calls;
    const double F1 = pointGradImpl<P>(t1.data());
    if (F1 - F >= 0.1 * pred) {
      // mu only grows: halving it after well-predicted steps (longer steps) took fewer steps
      // but more work per step in the dual (more terms within reach), 3% more in all.
      const bool small = F1 - F < 1e-2 * tol;
      std::copy(t1.begin(), t1.end(), t);
      F = lastF_ = F1;
      av.assign(tv_.begin(), tv_.end());
      ag.assign(tg_.begin(), tg_.end());
      if (small || F > stopAbove) break;
    } else {
      mu *= 4.0;
    }
  }
  return calls;
}

}  // namespace detail
}  // namespace frep
