// Internal to the min-of-terms form: the forward gradient of one step, which build() (constant
// gradients) and the point gradients of the ascent (extremum_terms_ascent.cpp) both inline.
#pragma once

#include <cmath>
#include <cstdint>

#include "extremum/extremum_terms.h"
#include "frep/expressions/sin_cos.h"

namespace frep {
namespace detail {

// P: the number of parameters when known at compile time (the loops over them unroll), else 0.
// The gradient of step q from its operands' gradients (pd_), a = its first operand's value,
// b = its second's, v = its own.
template <uint32_t P>
inline void TermForm::stepGrad(const Step& q, double a, double b, double v) {
  const uint32_t p = P ? P : p_;
  double* pd = pd_.data();
  double* d = pd + size_t(q.k) * p;
  const bool depA = q.depA, depB = q.depB;
  const double* da = pd + size_t(q.a) * p;
  const double* db = pd + size_t(q.b) * p;
  double pa = 0.0, pb = 0.0;
  const double* pass = nullptr;
  switch (q.op) {
    case Op::Neg: pa = -1.0; break;
    case Op::Copy: pa = 1.0; break;
    case Op::Add: pa = 1.0; pb = 1.0; break;
    case Op::Sub: pa = 1.0; pb = -1.0; break;
    case Op::Mul: pa = b; pb = a; break;
    case Op::Div: pa = 1.0 / b; pb = -v / b; break;
    case Op::PowI: pa = q.imm * applyOp(Op::PowI, a, 0.0, 0.0, q.imm - 1.0); break;
    case Op::Sqrt: pa = a > 0.0 ? 0.5 / v : 0.0; break;
    case Op::Abs: pa = a > 0.0 ? 1.0 : a < 0.0 ? -1.0 : 0.0; break;
    case Op::Exp: pa = v; break;
    case Op::Log: pa = a > kLogFloor ? 1.0 / a : 0.0; break;
    case Op::Sin: pa = ownCos(a); break;
    case Op::Cos: pa = -ownSin(a); break;
    case Op::Atan: pa = 1.0 / (1.0 + a * a); break;
    case Op::Tanh: pa = 1.0 - v * v; break;
    case Op::Min: if (b < a ? depB : depA) pass = b < a ? db : da; break;
    case Op::Max: if (b > a ? depB : depA) pass = b > a ? db : da; break;
    case Op::RAnd: case Op::ROr: rFunctionPartials(q.op == Op::ROr, a, b, q.imm, pa, pb); break;
    default: break;
  }
  if (pass) {
    for (uint32_t j = 0; j < p; ++j) d[j] = pass[j];
  } else {
    const bool useA = depA && pa != 0.0, useB = depB && pb != 0.0;
    for (uint32_t j = 0; j < p; ++j) {
      double s = 0.0;
      if (useA) s += pa * da[j];
      if (useB) s += pb * db[j];
      d[j] = std::isfinite(s) ? s : 0.0;
    }
  }
}

}  // namespace detail
}  // namespace frep
