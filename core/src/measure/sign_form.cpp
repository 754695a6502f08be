// A sign-equivalent form of a field for measuring (mass_properties.h, measureForm).
#include <unordered_map>
#include <vector>

#include "frep/measure/mass_properties.h"

namespace frep {

namespace {

bool isZero(const Expr& e) { return e.isConst(0.0); }

// max(d, 0) or max(0, d) -> d.
bool positivePart(const Expr& m, Expr& d) {
  if (m.op() != Op::Max) return false;
  if (isZero(m.arg(1))) d = m.arg(0);
  else if (isZero(m.arg(0))) d = m.arg(1);
  else return false;
  return true;
}

// x * x or x^2 -> x.
bool squareOf(const Expr& s, Expr& x) {
  if (s.op() == Op::Mul && s.arg(0).same(s.arg(1))) x = s.arg(0);
  else if (s.op() == Op::PowI && s.node().value == 2.0) x = s.arg(0);
  else return false;
  return true;
}

void terms(const Expr& e, Op op, std::vector<Expr>& out) {
  if (e.op() == op) {
    terms(e.arg(0), op, out);
    terms(e.arg(1), op, out);
  } else {
    out.push_back(e);
  }
}

// sqrt(sum_k max(d_k, 0)^2) -> the d_k (a square of 0 may stand for a d that is always <= 0).
bool normOfPositiveParts(const Expr& p, std::vector<Expr>& ds) {
  if (p.op() != Op::Sqrt) return false;
  std::vector<Expr> sq;
  terms(p.arg(0), Op::Add, sq);
  for (const Expr& s : sq) {
    Expr x, d;
    if (!squareOf(s, x) || !positivePart(x, d)) return false;
    ds.push_back(d);
  }
  return !ds.empty();
}

bool sameSet(const std::vector<Expr>& a, const std::vector<Expr>& b) {
  auto covers = [](const std::vector<Expr>& x, const std::vector<Expr>& y) {
    for (const Expr& e : x) {
      bool found = false;
      for (const Expr& f : y) found = found || e.same(f);
      if (!found) return false;
    }
    return true;
  };
  return covers(a, b) && covers(b, a);
}

// |max(d, 0)| + min(max_k d_k, 0), the exact signed distance of a box (or a cylinder) from its
// slab distances d_k, has the sign of max_k d_k everywhere: positive iff some d_k > 0, where the
// first term is positive and the second 0; else the first is 0 and the sum is max_k d_k.
bool boxDistance(const Expr& e, Expr& m) {
  if (e.op() != Op::Add) return false;
  for (int side = 0; side < 2; ++side) {
    const Expr p = e.arg(side), q = e.arg(1 - side);
    std::vector<Expr> ds, ms;
    if (!normOfPositiveParts(p, ds) || q.op() != Op::Min) continue;
    const Expr mm = isZero(q.arg(1)) ? q.arg(0) : isZero(q.arg(0)) ? q.arg(1) : Expr();
    if (!(isZero(q.arg(1)) || isZero(q.arg(0)))) continue;
    terms(mm, Op::Max, ms);
    if (sameSet(ds, ms)) {
      m = mm;
      return true;
    }
  }
  return false;
}

// e as c0 + c . x when it is built of constants, x0..x2, +, -, negation and products by
// constants only.
bool affine(const Expr& e, double& c0, double c[3]) {
  c0 = c[0] = c[1] = c[2] = 0.0;
  double a0, a[3], b0, b[3];
  switch (e.op()) {
    case Op::Const: c0 = e.constValue(); return true;
    case Op::Var:
      if (e.node().index > 2) return false;
      c[e.node().index] = 1.0;
      return true;
    case Op::Neg:
      if (!affine(e.arg(0), a0, a)) return false;
      c0 = -a0;
      for (int i = 0; i < 3; ++i) c[i] = -a[i];
      return true;
    case Op::Add: case Op::Sub: {
      if (!affine(e.arg(0), a0, a) || !affine(e.arg(1), b0, b)) return false;
      const double s = e.op() == Op::Add ? 1.0 : -1.0;
      c0 = a0 + s * b0;
      for (int i = 0; i < 3; ++i) c[i] = a[i] + s * b[i];
      return true;
    }
    case Op::Mul: {
      const int k = e.arg(0).isConst() ? 0 : e.arg(1).isConst() ? 1 : -1;
      if (k < 0 || !affine(e.arg(1 - k), a0, a)) return false;
      const double m = e.arg(k).constValue();
      c0 = m * a0;
      for (int i = 0; i < 3; ++i) c[i] = m * a[i];
      return true;
    }
    default: return false;
  }
}

// a * b with a, b affine and a + b a positive constant (HyperFun's slab (x - v)(v + d - x)):
// both factors cannot be negative at once, so the product has the sign of min(a, b).
bool slabProduct(const Expr& e) {
  if (e.op() != Op::Mul || e.arg(0).same(e.arg(1))) return false;
  double a0, a[3], b0, b[3];
  if (!affine(e.arg(0), a0, a) || !affine(e.arg(1), b0, b)) return false;
  for (int i = 0; i < 3; ++i)
    if (a[i] + b[i] != 0.0) return false;
  return a0 + b0 > 0.0 && (a[0] != 0.0 || a[1] != 0.0 || a[2] != 0.0);
}

struct Rewriter {
  std::unordered_map<const Node*, Expr> done;
  Expr run(const Expr& e) {
    auto it = done.find(e.ptr().get());
    if (it != done.end()) return it->second;
    Expr out = e, m;
    switch (e.op()) {
      case Op::Neg: out = -run(e.arg(0)); break;
      case Op::Min: out = min(run(e.arg(0)), run(e.arg(1))); break;
      case Op::Max: out = max(run(e.arg(0)), run(e.arg(1))); break;
      // An R-conjunction (-1 < a < 1) is positive iff both arguments are, zero iff their min is:
      // it has the sign of min (R-disjunction: of max). Its smooth rounding of the level sets
      // near an edge is no part of the solid and only widens the enclosures there.
      case Op::RAnd: out = min(run(e.arg(0)), run(e.arg(1))); break;
      case Op::ROr: out = max(run(e.arg(0)), run(e.arg(1))); break;
      case Op::Mul:  // by a positive constant, or a slab
        if (e.arg(0).isConst() && e.arg(0).constValue() > 0.0) out = e.arg(0) * run(e.arg(1));
        else if (e.arg(1).isConst() && e.arg(1).constValue() > 0.0) out = run(e.arg(0)) * e.arg(1);
        else if (slabProduct(e)) out = min(e.arg(0), e.arg(1));
        break;
      case Op::Add:
        if (boxDistance(e, m)) out = m;
        break;
      default: break;
    }
    done.emplace(e.ptr().get(), out);
    return out;
  }
};

}  // namespace

Expr measureForm(const Expr& f) { return Rewriter().run(f); }

MassProperties measureMassProperties(const Expr& f, const Interval box[3], const MeasureOptions& options) {
  return measureMassProperties(Tape::compile(measureForm(f), 3), box, options);
}

}  // namespace frep
