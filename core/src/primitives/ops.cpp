// Operation library (see ops.h). Formulas are cited to the papers by short name and section.
#include "frep/primitives/ops.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace frep {

namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
}

// Checks that need a value only apply to constants; fields are the caller's responsibility.
void requireNonZero(const Expr& e, const char* what) {
  require(!e.isConst() || e.constValue() != 0.0, std::string(what) + " must be non-zero");
}

void requireRParam(const Expr& a) {
  if (!a.isConst()) return;
  double v = a.constValue();
  require(v > -1.0 && v <= 1.0, "R-function parameter a must lie in (-1, 1], got " +
                                    std::to_string(v));
}

// Pasko-Survey, base operations: (f1 + f2 + sign·sqrt(f1² + f2² − 2a·f1·f2)) / (1 + a).
Expr rFunction(const Expr& f1, const Expr& f2, const Expr& a, double sign) {
  requireRParam(a);
  // a = 1: the square root is |f1 − f2| and the R-function is exactly max / min. Emitting the
  // extremum node itself lets interval evaluation decide it and prune the tape.
  if (a.isConst(1.0)) return sign > 0 ? max(f1, f2) : min(f1, f2);
  // A constant a: one monotone R-function node (exact interval bounds, see expr.h).
  if (a.isConst()) return sign > 0 ? rOr(f1, f2, a.constValue()) : rAnd(f1, f2, a.constValue());
  Expr s = square(f1) + square(f2);
  bool zero = a.isConst(0.0);  // the common sqrt system: skip the dead terms
  if (!zero) s = s - 2.0 * a * f1 * f2;
  Expr r = sign > 0 ? f1 + f2 + sqrt(s) : f1 + f2 - sqrt(s);
  return zero ? r : r / (1.0 + a);
}

// Rvachev's R_0^m: the a = 0 R-function times (f1² + f2²)^(m/2), which is C^m at f1 = f2 = 0.
Expr rSmooth(const Expr& f1, const Expr& f2, double m, double sign) {
  require(std::isfinite(m) && m >= 0.0, "smoothness m must be a finite number >= 0");
  Expr s = square(f1) + square(f2);
  Expr r = sign > 0 ? rOr(f1, f2, 0.0) : rAnd(f1, f2, 0.0);
  if (m == 0.0) return r;
  Expr w;
  if (m == std::floor(m) && m <= 64.0) {
    int mi = static_cast<int>(m);
    w = mi % 2 == 0 ? Expr::powi(s, mi / 2) : Expr::powi(sqrt(s), mi);
  } else {
    w = pow(s, Expr(0.5 * m));
  }
  return r * w;
}

// Coordinate indices of the rotation plane of `axis`, in HyperFun's cyclic order.
void planeOf(Axis axis, uint32_t& p, uint32_t& q) {
  uint32_t k = static_cast<uint32_t>(axis);
  require(k < 3, "axis must be X, Y or Z");
  p = (k + 1) % 3;
  q = (k + 2) % 3;
}

std::vector<Expr> identity(size_t n) {
  std::vector<Expr> v;
  for (size_t i = 0; i < n; ++i) v.push_back(Expr::x(static_cast<uint32_t>(i)));
  return v;
}

std::vector<Expr> padded(std::vector<Expr> v, size_t n) {
  for (size_t i = v.size(); i < n; ++i) v.push_back(Expr::x(static_cast<uint32_t>(i)));
  return v;
}

// Turns the (p, q) plane by `angle` (counter-clockwise looking down the axis).
std::vector<Expr> rotated(Axis axis, const Expr& angle) {
  uint32_t p, q;
  planeOf(axis, p, q);
  std::vector<Expr> v = identity(3);
  Expr c = cos(angle), s = sin(angle);
  v[p] = Expr::x(p) * c - Expr::x(q) * s;
  v[q] = Expr::x(p) * s + Expr::x(q) * c;
  return v;
}

// B⁻¹ by Gauss-Jordan elimination with partial pivoting; throws if B is singular.
std::vector<double> inverted(const std::vector<double>& b, size_t n) {
  std::vector<double> m(b), inv(n * n, 0.0);
  for (size_t i = 0; i < n; ++i) inv[i * n + i] = 1.0;
  double scale = 0.0;
  for (double v : b) scale = std::max(scale, std::fabs(v));
  for (size_t col = 0; col < n; ++col) {
    size_t piv = col;
    for (size_t r = col + 1; r < n; ++r)
      if (std::fabs(m[r * n + col]) > std::fabs(m[piv * n + col])) piv = r;
    require(std::fabs(m[piv * n + col]) > 1e-14 * scale, "affine matrix B is singular");
    for (size_t k = 0; k < n; ++k) {
      std::swap(m[col * n + k], m[piv * n + k]);
      std::swap(inv[col * n + k], inv[piv * n + k]);
    }
    double d = m[col * n + col];
    for (size_t k = 0; k < n; ++k) {
      m[col * n + k] /= d;
      inv[col * n + k] /= d;
    }
    for (size_t r = 0; r < n; ++r) {
      if (r == col) continue;
      double f = m[r * n + col];
      if (f == 0.0) continue;
      for (size_t k = 0; k < n; ++k) {
        m[r * n + k] -= f * m[col * n + k];
        inv[r * n + k] -= f * inv[col * n + k];
      }
    }
  }
  return inv;
}

// Parameter t of a linear ramp from u1 (t = 0) to u2 (t = 1).
Expr ramp(const Expr& u, const Expr& u1, const Expr& u2) { return (u - u1) / (u2 - u1); }

}  // namespace

// ---- Set-theoretic ----

Expr rUnion(const Expr& f1, const Expr& f2, const Expr& a) { return rFunction(f1, f2, a, 1.0); }
Expr rIntersection(const Expr& f1, const Expr& f2, const Expr& a) {
  return rFunction(f1, f2, a, -1.0);
}
Expr rNegation(const Expr& f) { return -f; }
Expr rSubtraction(const Expr& f1, const Expr& f2, const Expr& a) {
  return rIntersection(f1, rNegation(f2), a);
}
Expr rUnionSmooth(const Expr& f1, const Expr& f2, double m) { return rSmooth(f1, f2, m, 1.0); }
Expr rIntersectionSmooth(const Expr& f1, const Expr& f2, double m) {
  return rSmooth(f1, f2, m, -1.0);
}

// ---- Blending (Pasko-Survey, blending) ----

Expr blendDisplacement(const Expr& f1, const Expr& f2, const Expr& a0, const Expr& a1,
                       const Expr& a2) {
  requireNonZero(a1, "blending parameter a1");
  requireNonZero(a2, "blending parameter a2");
  return a0 / (1.0 + square(f1 / a1) + square(f2 / a2));
}
Expr blendUnion(const Expr& f1, const Expr& f2, const Expr& a0, const Expr& a1,
                const Expr& a2, const Expr& a) {
  return rUnion(f1, f2, a) + blendDisplacement(f1, f2, a0, a1, a2);
}
Expr blendIntersection(const Expr& f1, const Expr& f2, const Expr& a0, const Expr& a1,
                       const Expr& a2, const Expr& a) {
  return rIntersection(f1, f2, a) + blendDisplacement(f1, f2, a0, a1, a2);
}

// ---- Offsets (Pasko-Survey, offsetting) ----

Expr offsetConst(const Expr& f, const Expr& c) { return f + c; }

Expr offsetNormal(const Expr& f, const Expr& d) {
  uint32_t n = numVars(f);
  std::vector<Expr> grad;
  Expr len2;
  for (uint32_t i = 0; i < n; ++i) {
    grad.push_back(derivative(f, i));
    len2 = len2 + square(grad.back());
  }
  Expr len = sqrt(len2);
  Expr moves = gt(len2, 0.0);  // a critical point has no normal: leave it in place
  std::vector<Expr> shifted;
  for (uint32_t i = 0; i < n; ++i)
    shifted.push_back(Expr::x(i) + select(moves, d * grad[i] / len, 0.0));
  return remap(f, shifted);
}

// ---- Cartesian product (Pasko-Survey, Cartesian product; Pasko-Minkowski eq. 3.2) ----

Expr product(const Expr& f1, uint32_t n1, const Expr& f2, const Expr& a) {
  require(numVars(f1) <= n1, "product: f1 uses coordinates beyond its n1 = " +
                                 std::to_string(n1));
  std::vector<Expr> shift;
  for (uint32_t i = 0; i < numVars(f2); ++i) shift.push_back(Expr::x(n1 + i));
  return rIntersection(f1, remap(f2, shift), a);
}

// ---- Bijective mappings (Pasko-Survey, bijective mapping) ----

Mapping Mapping::then(const Mapping& next) const {
  size_t n = std::max({forward.size(), inverse.size(), next.forward.size(),
                       next.inverse.size()});
  // Deformed twice: f(q1(q2(X))); the points themselves move by g2(g1(X)).
  std::vector<Expr> q1 = padded(inverse, n), q2 = padded(next.inverse, n);
  std::vector<Expr> g1 = padded(forward, n), g2 = padded(next.forward, n);
  Mapping m;
  for (size_t i = 0; i < n; ++i) {
    m.inverse.push_back(remap(q1[i], q2));
    m.forward.push_back(remap(g2[i], g1));
  }
  return m;
}

Mapping affineMap(const std::vector<double>& b, const std::vector<double>& c) {
  size_t n = c.size();
  require(n > 0 && b.size() == n * n, "affine: B must be n x n with n = size of C");
  std::vector<double> a = inverted(b, n);
  Mapping m;
  for (size_t i = 0; i < n; ++i) {
    Expr q, g = c[i];
    for (size_t j = 0; j < n; ++j) {
      Expr xj = Expr::x(static_cast<uint32_t>(j));
      if (b[i * n + j] != 0.0) q = q + b[i * n + j] * (xj - c[j]);
      if (a[i * n + j] != 0.0) g = g + a[i * n + j] * xj;
    }
    m.inverse.push_back(q);
    m.forward.push_back(g);
  }
  return m;
}

Mapping translateMap(const std::vector<Expr>& d) {
  Mapping m;
  for (size_t i = 0; i < d.size(); ++i) {
    Expr xi = Expr::x(static_cast<uint32_t>(i));
    m.forward.push_back(xi + d[i]);
    m.inverse.push_back(xi - d[i]);
  }
  return m;
}

Mapping scaleMap(const std::vector<Expr>& s) {
  Mapping m;
  for (size_t i = 0; i < s.size(); ++i) {
    requireNonZero(s[i], "scale factor");
    Expr xi = Expr::x(static_cast<uint32_t>(i));
    m.forward.push_back(xi * s[i]);
    m.inverse.push_back(xi / s[i]);
  }
  return m;
}

Mapping rotateMap(Axis axis, const Expr& angle) {
  return {rotated(axis, angle), rotated(axis, -angle)};
}

Mapping twistMap(Axis axis, const Expr& u1, const Expr& u2, const Expr& angle1,
                 const Expr& angle2) {
  require(!(u1.isConst() && u2.isConst() && u1.constValue() == u2.constValue()),
          "twist: u1 and u2 must differ");
  uint32_t k = static_cast<uint32_t>(axis);
  Expr t = ramp(Expr::x(k), u1, u2);
  Expr angle = (1.0 - t) * angle1 + t * angle2;
  // The axis coordinate is unchanged by the turn, so the inverse is the opposite turn.
  return {rotated(axis, angle), rotated(axis, -angle)};
}

Mapping twistRateMap(Axis axis, const Expr& radiansPerUnit) {
  Expr angle = radiansPerUnit * Expr::x(static_cast<uint32_t>(axis));
  return {rotated(axis, angle), rotated(axis, -angle)};
}

Mapping taperMap(Axis axis, const Expr& u1, const Expr& u2, const Expr& s1, const Expr& s2) {
  require(!(u1.isConst() && u2.isConst() && u1.constValue() == u2.constValue()),
          "taper: u1 and u2 must differ");
  requireNonZero(s1, "taper scale s1");
  requireNonZero(s2, "taper scale s2");
  if (s1.isConst() && s2.isConst())
    require((s1.constValue() > 0) == (s2.constValue() > 0),
            "taper: s1 and s2 must have the same sign (else the map is not bijective)");
  uint32_t k = static_cast<uint32_t>(axis), p, q;
  planeOf(axis, p, q);
  Expr t = min(max(ramp(Expr::x(k), u1, u2), 0.0), 1.0);
  Expr s = s1 + t * (s2 - s1);
  Mapping m{identity(3), identity(3)};
  for (uint32_t i : {p, q}) {
    m.forward[i] = Expr::x(i) * s;
    m.inverse[i] = Expr::x(i) / s;
  }
  return m;
}

Mapping bendMap(Axis along, Axis toward, const Expr& radius) {
  require(along != toward, "bend: the two axes must differ");
  requireNonZero(radius, "bend radius");
  uint32_t iu = static_cast<uint32_t>(along), iv = static_cast<uint32_t>(toward);
  require(iu < 3 && iv < 3, "axis must be X, Y or Z");
  Expr u = Expr::x(iu), v = Expr::x(iv), r = radius;
  Mapping m{identity(3), identity(3)};
  // Forward: (u, v) -> polar (ρ = r − v, θ = u / r) about the centre (0, r) of the (u, v) plane.
  Expr theta = u / r, rho = r - v;
  m.forward[iu] = rho * sin(theta);
  m.forward[iv] = r - rho * cos(theta);
  // Inverse: back from the circle; σ = sign(r) keeps ρ's sign for a bend toward −v.
  Expr sigma = sign(r);
  Expr rhoBack = sigma * sqrt(square(u) + square(r - v));
  m.inverse[iu] = r * atan2(sigma * u, sigma * (r - v));
  m.inverse[iv] = r - rhoBack;
  return m;
}

Mapping cylindricalToCartesianMap() {
  Expr x = Expr::x(0), y = Expr::x(1), z = Expr::x(2);
  Mapping m;
  m.inverse = {sqrt(square(x) + square(y)), atan2(y, x), z};  // (r, phi, z) of a point
  m.forward = {x * cos(y), x * sin(y), z};                     // (r, phi, z) -> Cartesian
  return m;
}

Expr affine(const Expr& f, const std::vector<double>& b, const std::vector<double>& c) {
  return affineMap(b, c).apply(f);
}
Expr translate(const Expr& f, const std::vector<Expr>& d) { return translateMap(d).apply(f); }
Expr scale(const Expr& f, const std::vector<Expr>& s) { return scaleMap(s).apply(f); }
Expr rotateX(const Expr& f, const Expr& angle) { return rotateMap(Axis::X, angle).apply(f); }
Expr rotateY(const Expr& f, const Expr& angle) { return rotateMap(Axis::Y, angle).apply(f); }
Expr rotateZ(const Expr& f, const Expr& angle) { return rotateMap(Axis::Z, angle).apply(f); }
Expr twist(const Expr& f, Axis axis, const Expr& u1, const Expr& u2, const Expr& angle1,
           const Expr& angle2) {
  return twistMap(axis, u1, u2, angle1, angle2).apply(f);
}
Expr twistRate(const Expr& f, Axis axis, const Expr& radiansPerUnit) {
  return twistRateMap(axis, radiansPerUnit).apply(f);
}
Expr taper(const Expr& f, Axis axis, const Expr& u1, const Expr& u2, const Expr& s1,
           const Expr& s2) {
  return taperMap(axis, u1, u2, s1, s2).apply(f);
}
Expr bend(const Expr& f, Axis along, Axis toward, const Expr& radius) {
  return bendMap(along, toward, radius).apply(f);
}
Expr cylindricalToCartesian(const Expr& f) { return cylindricalToCartesianMap().apply(f); }
Expr cartesianToCylindrical(const Expr& f) {
  return cylindricalToCartesianMap().inverted().apply(f);
}

// ---- Metamorphosis ----

Expr morph(const Expr& f1, const Expr& f2, const Expr& g) { return f1 * (1.0 - g) + f2 * g; }

Expr morphAlongAxis(const Expr& f1, const Expr& f2, uint32_t n, double x0, double x1) {
  require(x0 != x1, "morph: x0 and x1 must differ");
  require(numVars(f1) <= n && numVars(f2) <= n,
          "morph: the operands must use only coordinates below n = " + std::to_string(n));
  Expr g = min(max(ramp(Expr::x(n), x0, x1), 0.0), 1.0);
  return morph(f1, f2, g);
}

Expr morphLinear(const Expr& f1, const Expr& f2, const Expr& beta) {
  return beta * f1 + (1.0 - beta) * f2;  // written out: 1 − (1 − β) would round
}

Expr cutByBox(const Expr& f, const std::array<double, 3>& lo, const std::array<double, 3>& hi) {
  Expr e = f;
  for (uint32_t i = 0; i < 3; ++i)
    for (const Expr& face : {Expr::x(i) - lo[i], hi[i] - Expr::x(i)}) e = select(ge(e, face), face, e);
  return e;
}

}  // namespace frep
