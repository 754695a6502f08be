// Builders on top of the extremum node (extremum.h): Minkowski sum and difference, projection,
// sweep, constant-radius offset, metamorphosis, and the exact analytic shortcuts.
#include <cmath>
#include <stdexcept>
#include <string>

#include "frep/expressions/min_max_form.h"
#include "frep/extremum/extremum.h"
#include "frep/primitives/ops.h"

namespace frep {

namespace {

std::vector<Expr> outerVars(uint32_t n) {
  std::vector<Expr> v;
  for (uint32_t i = 0; i < n; ++i) v.push_back(Expr::x(i));
  return v;
}

void checkOperand(const Expr& f, uint32_t n, const char* what) {
  if (numVars(f) > n)
    throw std::invalid_argument(std::string(what) + ": operand uses x[" + std::to_string(numVars(f) - 1) +
                                "] but the space has n = " + std::to_string(n) + " coordinates");
}

void checkBounds(const Bounds& b, uint32_t n, const char* what) {
  if (b.lo.size() != n || b.hi.size() != n)
    throw std::invalid_argument(std::string(what) + ": bounds need " + std::to_string(n) + " values per side");
}

ExtremumSpec baseSpec(ExtremumKind kind, uint32_t n, uint32_t m, const SearchOptions& o) {
  ExtremumSpec s;
  s.kind = kind;
  s.inputs = outerVars(n);
  s.hidden = m;
  s.method = o.method;
  s.eps = o.eps;
  s.tolerance = o.tolerance;
  s.maxBoxes = o.maxBoxes;
  s.intervalBudget = o.intervalBudget;
  return s;
}

// The operand as the search sees it (SearchOptions::minMaxOperands).
Expr searched(const Expr& f, const SearchOptions& o) { return o.minMaxOperands ? minMaxForm(f) : f; }

}  // namespace

Expr minkowskiBalls(const std::vector<double>& c1, double r1, const std::vector<double>& c2, double r2) {
  if (c1.size() != c2.size()) throw std::invalid_argument("minkowskiBalls: centres of different dimension");
  const double r = r1 + r2;
  Expr f = r * r;
  for (size_t i = 0; i < c1.size(); ++i) f = f - square(Expr::x(uint32_t(i)) - (c1[i] + c2[i]));
  return f;
}

Expr minkowskiSum(const Expr& A, const Expr& B, uint32_t n, const Bounds& boundsB, const MinkowskiOptions& o) {
  checkOperand(A, n, "minkowskiSum");
  checkOperand(B, n, "minkowskiSum");
  if (o.aIsDistance && o.bIsBall) {
    // Exact: the distance to A + ball(c, r) is the distance to A, shifted by c, minus r.
    if (o.ballCenter.size() != n) throw std::invalid_argument("minkowskiSum: ballCenter needs n values");
    std::vector<Expr> shifted;
    for (uint32_t i = 0; i < n; ++i) shifted.push_back(Expr::x(i) - o.ballCenter[i]);
    return remap(A, shifted) + o.ballRadius;
  }
  checkBounds(boundsB, n, "minkowskiSum");
  // Body over (X, u): A(X - u) & B(u) (Pasko-Minkowski eq. 3.5 with u the point of B).
  std::vector<Expr> xa, xb;
  for (uint32_t i = 0; i < n; ++i) {
    xa.push_back(Expr::x(i) - Expr::x(n + i));
    xb.push_back(Expr::x(n + i));
  }
  ExtremumSpec s = baseSpec(ExtremumKind::Max, n, n, o);
  s.body = rIntersection(remap(searched(A, o), xa), remap(searched(B, o), xb), o.a);
  s.domain = DomainKind::Box;
  s.lo = boundsB.lo;
  s.hi = boundsB.hi;
  return extremum(std::move(s));
}

Expr minkowskiDifference(const Expr& A, const Expr& B, uint32_t n, const Bounds& boundsB, const SearchOptions& o) {
  checkOperand(A, n, "minkowskiDifference");
  checkOperand(B, n, "minkowskiDifference");
  checkBounds(boundsB, n, "minkowskiDifference");
  // X is in the erosion iff A(X + u) >= 0 for every u in B: min over u of (A(X + u) | ~B(u)).
  std::vector<Expr> xa, xb;
  for (uint32_t i = 0; i < n; ++i) {
    xa.push_back(Expr::x(i) + Expr::x(n + i));
    xb.push_back(Expr::x(n + i));
  }
  ExtremumSpec s = baseSpec(ExtremumKind::Min, n, n, o);
  s.body = max(remap(searched(A, o), xa), -remap(searched(B, o), xb));
  s.domain = DomainKind::Box;
  s.lo = boundsB.lo;
  s.hi = boundsB.hi;
  return extremum(std::move(s));
}

Expr project(const Expr& A, uint32_t totalDims, const std::vector<uint32_t>& hiddenDims, const Bounds& box,
             const SearchOptions& o) {
  checkOperand(A, totalDims, "project");
  const uint32_t m = static_cast<uint32_t>(hiddenDims.size());
  if (m == 0 || m >= totalDims) throw std::invalid_argument("project: need 1 <= hidden dims < total dims");
  checkBounds(box, m, "project");
  const uint32_t n = totalDims - m;
  std::vector<Expr> vars(totalDims);
  std::vector<bool> hidden(totalDims, false);
  for (uint32_t j = 0; j < m; ++j) {
    if (hiddenDims[j] >= totalDims || hidden[hiddenDims[j]])
      throw std::invalid_argument("project: hidden dims must be distinct and < total dims");
    hidden[hiddenDims[j]] = true;
    vars[hiddenDims[j]] = Expr::x(n + j);
  }
  for (uint32_t i = 0, k = 0; i < totalDims; ++i)
    if (!hidden[i]) vars[i] = Expr::x(k++);
  ExtremumSpec s = baseSpec(ExtremumKind::Max, n, m, o);
  s.body = remap(searched(A, o), vars);
  s.domain = DomainKind::Box;
  s.lo = box.lo;
  s.hi = box.hi;
  return extremum(std::move(s));
}

Expr sweep(const Expr& A, uint32_t n, const Motion& motion, double t0, double t1, const SearchOptions& o) {
  checkOperand(A, n + 1, "sweep");
  if (n < 1 || n > 3) throw std::invalid_argument("sweep: n must be 1, 2 or 3");
  if (!(t0 <= t1)) throw std::invalid_argument("sweep: need t0 <= t1");
  const Expr t = Expr::x(n);
  auto ofT = [&](const std::vector<Expr>& v, size_t i) { return i < v.size() ? remap(v[i], {t}) : Expr(0.0); };
  // Y = M(t)^-1 X = R(t)^T (X - T(t)).
  std::vector<Expr> y;
  for (uint32_t i = 0; i < n; ++i) y.push_back(Expr::x(i) - ofT(motion.translation, i));
  if (n == 2 && !motion.rotation.empty()) {
    const Expr a = ofT(motion.rotation, 0), c = cos(a), s = sin(a);
    y = {c * y[0] + s * y[1], -s * y[0] + c * y[1]};
  } else if (n == 3 && !motion.rotation.empty()) {
    const Expr ax = ofT(motion.rotation, 0), ay = ofT(motion.rotation, 1), az = ofT(motion.rotation, 2);
    if (!az.isConst(0.0)) {
      const Expr c = cos(az), s = sin(az);
      y = {c * y[0] + s * y[1], -s * y[0] + c * y[1], y[2]};
    }
    if (!ay.isConst(0.0)) {
      const Expr c = cos(ay), s = sin(ay);
      y = {c * y[0] - s * y[2], y[1], s * y[0] + c * y[2]};
    }
    if (!ax.isConst(0.0)) {
      const Expr c = cos(ax), s = sin(ax);
      y = {y[0], c * y[1] + s * y[2], -s * y[1] + c * y[2]};
    }
  }
  y.push_back(t);  // a time-varying shape reads t as x[n]
  ExtremumSpec s = baseSpec(ExtremumKind::Max, n, 1, o);
  s.body = remap(searched(A, o), y);
  s.domain = DomainKind::Box;
  s.lo = {t0};
  s.hi = {t1};
  return extremum(std::move(s));
}

Expr offsetRadius(const Expr& A, uint32_t n, double r, const SearchOptions& o, bool surfaceOnly) {
  checkOperand(A, n, "offsetRadius");
  if (r == 0.0) return A;
  const double R = std::fabs(r);
  std::vector<Expr> xa;
  for (uint32_t i = 0; i < n; ++i) xa.push_back(Expr::x(i) + Expr::x(n + i));
  ExtremumSpec s = baseSpec(r > 0 ? ExtremumKind::Max : ExtremumKind::Min, n, n, o);
  s.body = remap(searched(A, o), xa);
  if (n == 1) {
    s.domain = DomainKind::Box;
    s.lo = {-R};  // 1D: the segment (the two-point "sphere" is not searched separately)
    s.hi = {R};
  } else {
    s.domain = surfaceOnly ? DomainKind::Sphere : DomainKind::Ball;
    s.radius = R;
  }
  return extremum(std::move(s));
}

Expr morphMinkowski(const Expr& A, const Expr& B, uint32_t n, double t, const Bounds& boundsB,
                    const MinkowskiOptions& o) {
  if (!(t >= 0.0 && t <= 1.0)) throw std::invalid_argument("morphMinkowski: t must be in [0, 1]");
  checkOperand(A, n, "morphMinkowski");
  checkOperand(B, n, "morphMinkowski");
  if (t == 0.0) return A;
  if (t == 1.0) return B;
  checkBounds(boundsB, n, "morphMinkowski");
  // (1 - t) A = {X : A(X / (1 - t)) >= 0}, t B likewise (eq. 4.5).
  std::vector<Expr> xa, xb;
  for (uint32_t i = 0; i < n; ++i) {
    xa.push_back(Expr::x(i) / (1.0 - t));
    xb.push_back(Expr::x(i) / t);
  }
  Bounds sb;
  for (uint32_t i = 0; i < n; ++i) {
    sb.lo.push_back(boundsB.lo[i] * t);
    sb.hi.push_back(boundsB.hi[i] * t);
  }
  MinkowskiOptions mo = o;
  mo.aIsDistance = mo.bIsBall = false;
  return minkowskiSum(remap(A, xa), remap(B, xb), n, sb, mo);
}

}  // namespace frep
