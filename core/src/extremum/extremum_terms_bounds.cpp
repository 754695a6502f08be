// The min-of-terms form's centred (mean-value) upper bounds over a box: values and interval
// gradients of the nodes, and the weighted combination of the terms (extremum_terms.h).
#include "extremum/extremum_terms.h"
#include "evaluators/interval_fast.h"
#include "frep/expressions/sin_cos.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <unordered_map>

#include "extremum/term_intervals.h"

namespace frep {
namespace detail {

void TermForm::evalBox(const double* tlo, const double* thi) {
  const Interval everything = Interval::everything();
  const uint32_t p = p_;
  for (uint32_t k : dep_) {
    const Nd& q = nodes_[k];
    Interval* d = &der_[size_t(k) * p];
    if (q.op == Op::Var) {
      val_[k] = Interval(tlo[q.var - n_], thi[q.var - n_]);
      for (uint32_t j = 0; j < p; ++j) d[j] = Interval(j == q.var - n_ ? 1.0 : 0.0);
      continue;
    }
    const Interval A = val_[size_t(q.a)];
    const Interval B = q.b >= 0 ? val_[size_t(q.b)] : Interval();
    const Interval C = q.c >= 0 ? val_[size_t(q.c)] : Interval();
    val_[k] = ival(q.op, A, B, C, q.imm, q.square);
    const bool depA = nodes_[size_t(q.a)].dep, depB = q.b >= 0 && nodes_[size_t(q.b)].dep;
    const Interval* da = &der_[size_t(q.a) * p];
    const Interval* db = q.b >= 0 ? &der_[size_t(q.b) * p] : nullptr;
    const Interval zero(0.0);
    auto dA = [&](uint32_t j) { return depA ? da[j] : zero; };
    auto dB = [&](uint32_t j) { return depB ? db[j] : zero; };
    // p * d; an input derivative of exactly 0 contributes 0 whatever p is.
    auto term = [&](const Interval& pa, const Interval& dd) { return isZeroIv(dd) ? zero : imul(pa, dd); };
    auto unary = [&](const Interval& pa) {
      for (uint32_t j = 0; j < p; ++j) d[j] = term(pa, dA(j));
    };
    auto binary = [&](const Interval& pa, const Interval& pb) {
      for (uint32_t j = 0; j < p; ++j) d[j] = iadd(term(pa, dA(j)), term(pb, dB(j)));
    };
    auto all = [&](const Interval& v) {
      for (uint32_t j = 0; j < p; ++j) d[j] = v;
    };
    auto hullOf = [&](bool onlyA, bool onlyB) {
      for (uint32_t j = 0; j < p; ++j) {
        const Interval x = dA(j), y = dB(j);
        if (onlyA) d[j] = x;
        else if (onlyB) d[j] = y;
        else d[j] = Interval(std::min(x.lo, y.lo), std::max(x.hi, y.hi));
      }
    };
    switch (q.op) {
      case Op::Neg: for (uint32_t j = 0; j < p; ++j) d[j] = ineg(dA(j)); break;
      case Op::Copy: for (uint32_t j = 0; j < p; ++j) d[j] = dA(j); break;
      case Op::Add:
        for (uint32_t j = 0; j < p; ++j) d[j] = !depB ? dA(j) : !depA ? dB(j) : iadd(dA(j), dB(j));
        break;
      case Op::Sub:
        for (uint32_t j = 0; j < p; ++j) d[j] = !depB ? dA(j) : !depA ? ineg(dB(j)) : isub(dA(j), dB(j));
        break;
      case Op::Mul:
        if (q.square) unary(imul(Interval(2.0), A));
        else binary(B, A);
        break;
      case Op::Div: {  // d(a / b) = da / b - (a / b) db / b
        const Interval inv = applyOp(Op::Div, Interval(1.0), B);
        binary(inv, ineg(imul(val_[k], inv)));
        break;
      }
      case Op::PowI:
        unary(imul(Interval(q.imm), applyOp(Op::PowI, A, Interval(), Interval(), q.imm - 1.0)));
        break;
      case Op::Sqrt:  // unbounded slope where the argument may be 0
        if (A.lo > 0.0) unary(applyOp(Op::Div, Interval(0.5), val_[k]));
        else unary(everything);
        break;
      case Op::Abs: unary(A.lo > 0.0 ? Interval(1.0) : A.hi < 0.0 ? Interval(-1.0) : Interval(-1.0, 1.0)); break;
      case Op::Exp: unary(val_[k]); break;
      case Op::Log: unary(A.lo > kLogFloor ? applyOp(Op::Div, Interval(1.0), A) : everything); break;
      case Op::Sin: unary(applyOp(Op::Cos, A)); break;
      case Op::Cos: unary(ineg(applyOp(Op::Sin, A))); break;
      case Op::Atan: unary(applyOp(Op::Div, Interval(1.0), iadd(Interval(1.0), ival(Op::PowI, A, {}, {}, 2.0, false)))); break;
      case Op::Sinh: unary(applyOp(Op::Cosh, A)); break;
      case Op::Cosh: unary(applyOp(Op::Sinh, A)); break;
      case Op::Tanh: unary(isub(Interval(1.0), ival(Op::PowI, val_[k], {}, {}, 2.0, false))); break;
      case Op::Min: hullOf(A.hi <= B.lo, B.hi < A.lo); break;
      case Op::Max: hullOf(B.hi <= A.lo, B.lo > A.hi); break;
      case Op::Select:
        if (A.lo > 0.0 || A.hi < 0.0) {
          for (uint32_t j = 0; j < p; ++j) d[j] = dB(j);
        } else if (A.lo == 0.0 && A.hi == 0.0) {
          const bool depC = nodes_[size_t(q.c)].dep;
          for (uint32_t j = 0; j < p; ++j) d[j] = depC ? der_[size_t(q.c) * p + j] : zero;
        } else {
          all(everything);  // may jump
        }
        break;
      case Op::RAnd: case Op::ROr: {
        // Partials (1 -+ (f1 - a f2) / s) / (1 + a) and (1 -+ (f2 - a f1) / s) / (1 + a),
        // s = sqrt(f1^2 + f2^2 - 2 a f1 f2). Both lie in [0, 2 / (1 + a)] (monotone, and
        // |f1 - a f2| <= s for |a| <= 1), which also covers s = 0 (Clarke gradient there).
        const double al = q.imm;
        if (!(al > -1.0 && al <= 1.0)) {
          all(everything);
          break;
        }
        const Interval onePlus = iadd(Interval(1.0), Interval(al));
        const Interval range(0.0, applyOp(Op::Div, Interval(2.0), onePlus).hi);
        Interval p1 = range, p2 = range;
        const Interval s2 = isub(iadd(ival(Op::PowI, A, {}, {}, 2.0, false), ival(Op::PowI, B, {}, {}, 2.0, false)),
                                 imul(Interval(2.0 * al), imul(A, B)));
        if (s2.lo > 0.0 && finiteIv(s2)) {
          const Interval s = ival(Op::Sqrt, s2, {}, {}, 0.0, false);
          Interval q1 = applyOp(Op::Div, isub(A, imul(Interval(al), B)), s);
          Interval q2 = applyOp(Op::Div, isub(B, imul(Interval(al), A)), s);
          const Interval sg(q.op == Op::RAnd ? -1.0 : 1.0);
          const Interval t1 = applyOp(Op::Div, iadd(Interval(1.0), imul(sg, q1)), onePlus);
          const Interval t2 = applyOp(Op::Div, iadd(Interval(1.0), imul(sg, q2)), onePlus);
          p1 = Interval(std::max(t1.lo, 0.0), std::min(t1.hi, range.hi));
          p2 = Interval(std::max(t2.lo, 0.0), std::min(t2.hi, range.hi));
          if (!(p1.lo <= p1.hi)) p1 = range;
          if (!(p2.lo <= p2.hi)) p2 = range;
        }
        binary(p1, p2);
        break;
      }
      case Op::Floor: case Op::Ceil: case Op::Trunc: case Op::Not: case Op::Lt: case Op::Le:
      case Op::Gt: case Op::Ge: case Op::Eq: case Op::Ne: case Op::And: case Op::Or:
        // piecewise constant: slope 0 where constant over the box, else it may jump
        all(val_[k].lo == val_[k].hi ? zero : everything);
        break;
      default:
        all(everything);
        break;
    }
    for (uint32_t j = 0; j < p; ++j)
      if (std::isnan(d[j].lo) || std::isnan(d[j].hi)) d[j] = everything;
  }
}

void TermForm::evalCentre(const double* c) {
  for (uint32_t k : dep_) {
    const Nd& q = nodes_[k];
    if (q.op == Op::Var) {
      valC_[k] = Interval(c[q.var - n_]);
      continue;
    }
    valC_[k] = ival(q.op, valC_[size_t(q.a)], q.b >= 0 ? valC_[size_t(q.b)] : Interval(),
                             q.c >= 0 ? valC_[size_t(q.c)] : Interval(), q.imm, q.square);
  }
}

double TermForm::upper(const double* tlo, const double* thi) {
  const uint32_t p = p_;
  evalBox(tlo, thi);
  cbuf_.resize(p);
  Dv_.resize(p);
  for (uint32_t j = 0; j < p; ++j) {
    cbuf_[j] = 0.5 * (tlo[j] + thi[j]);
    Dv_[j] = isub(Interval(tlo[j], thi[j]), Interval(cbuf_[j]));
  }
  evalCentre(cbuf_.data());
  const size_t K = terms_.size();
  Gl_.assign(K * p, 0.0);
  Gh_.assign(K * p, 0.0);
  vv_.assign(K, kInf);
  double best = kInf, slack = 0.0;
  for (size_t i = 0; i < K; ++i) {
    const size_t node = size_t(terms_[i]);
    const Interval vc = valC_[node];
    double ub = val_[node].hi;
    if (std::isnan(ub)) ub = kInf;
    if (!finiteIv(vc)) {
      best = std::min(best, ub);
      continue;
    }
    Interval acc = vc;
    bool finiteG = true;
    for (uint32_t j = 0; j < p; ++j) {
      const Interval g = nodes_[node].dep ? der_[node * p + j] : Interval(0.0);
      if (!finiteIv(g)) finiteG = false;
      Gl_[i * p + j] = g.lo;
      Gh_[i * p + j] = g.hi;
      acc = iadd(acc, imul(g, Dv_[j]));
    }
    if (finiteG) {
      ub = std::min(ub, acc.hi);
      vv_[i] = vc.hi;
      // Rounding of the computed body near c (the centred form bounds the exact terms): the
      // width of the centre's enclosure, which accumulates one ulp per operation.
      slack = std::max(slack, vc.hi - vc.lo);
    }
    best = std::min(best, ub);
  }
  // Weighted combination of the terms that may be active (centre value below the bound).
  csel_.clear();
  for (size_t i = 0; i < K; ++i)
    if (vv_[i] < best) csel_.push_back(uint32_t(i));
  if (csel_.size() >= 2 && p <= 16) {
    if (csel_.size() > 5) {
      std::partial_sort(csel_.begin(), csel_.begin() + 5, csel_.end(), [&](uint32_t a, uint32_t b) { return vv_[a] < vv_[b]; });
      csel_.resize(5);
    }
    const size_t S = csel_.size();
    clam_.assign(S, 0.0);
    size_t i0 = 0;
    for (size_t a = 1; a < S; ++a)
      if (vv_[csel_[a]] < vv_[csel_[i0]]) i0 = a;
    clam_[i0] = 1.0;
    // Surrogate phi(lambda) = sum lambda_i v_i + sum_j r_j max(H_j, -L_j), with H, L the
    // weighted sums of the gradient bounds: convex and piecewise linear, so exact line searches
    // moving weight between two terms only need its breakpoints.
    H_.assign(p, 0.0);
    L_.assign(p, 0.0);
    for (uint32_t j = 0; j < p; ++j) {
      H_[j] = Gh_[csel_[i0] * p + j];
      L_[j] = Gl_[csel_[i0] * p + j];
    }
    double V = vv_[csel_[i0]];
    double dH[16], dL[16];
    auto phiAt = [&](double s, double dV) {
      double f = V + s * dV;
      for (uint32_t j = 0; j < p; ++j) f += Dv_[j].hi * std::max(H_[j] + s * dH[j], -(L_[j] + s * dL[j]));
      return f;
    };
    for (int sweep = 0; sweep < 2; ++sweep) {
      for (size_t a = 0; a < S; ++a) {
        for (size_t b = 0; b < S; ++b) {
          if (a == b || clam_[a] <= 0.0) continue;
          const uint32_t ia = csel_[a], ib = csel_[b];
          for (uint32_t j = 0; j < p; ++j) {
            dH[j] = Gh_[ib * p + j] - Gh_[ia * p + j];
            dL[j] = Gl_[ib * p + j] - Gl_[ia * p + j];
          }
          const double dV = vv_[ib] - vv_[ia];
          double bestS = 0.0, bestF = phiAt(0.0, dV);
          auto tryS = [&](double s) {
            if (!(s > 0.0) || s > clam_[a]) return;
            const double f = phiAt(s, dV);
            if (f < bestF) {
              bestF = f;
              bestS = s;
            }
          };
          tryS(clam_[a]);
          for (uint32_t j = 0; j < p; ++j) {
            const double dm = dH[j] + dL[j];
            if (dm != 0.0) tryS(-(H_[j] + L_[j]) / dm);
          }
          if (bestS > 0.0) {
            clam_[a] = std::max(0.0, clam_[a] - bestS);
            clam_[b] += bestS;
            for (uint32_t j = 0; j < p; ++j) {
              H_[j] += bestS * dH[j];
              L_[j] += bestS * dL[j];
            }
            V += bestS * dV;
          }
        }
      }
    }
    // Rigorous value at these weights.
    Interval num(0.0), den(0.0);
    for (size_t a = 0; a < S; ++a) {
      if (clam_[a] <= 0.0) continue;
      num = iadd(num, imul(Interval(clam_[a]), valC_[size_t(terms_[csel_[a]])]));
      den = iadd(den, Interval(clam_[a]));
    }
    for (uint32_t j = 0; j < p; ++j) {
      Interval g(0.0);
      for (size_t a = 0; a < S; ++a)
        if (clam_[a] > 0.0) g = iadd(g, imul(Interval(clam_[a]), Interval(Gl_[csel_[a] * p + j], Gh_[csel_[a] * p + j])));
      num = iadd(num, imul(g, Dv_[j]));
    }
    if (den.lo > 0.0 && finiteIv(num)) {
      const Interval u = applyOp(Op::Div, num, den);
      if (u.hi < best) best = u.hi;
    }
  }
  return best + slack;
}

}  // namespace detail
}  // namespace frep
