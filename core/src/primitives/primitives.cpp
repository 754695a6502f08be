// Core primitives (see primitives.h). The curved ones follow HyperFun's formulas so that a
// model moved between the two libraries keeps its field; the box is built from R-functions
// (Pasko-Survey, base operations) so its parameter a chooses between min and the sqrt system.
#include "frep/primitives/primitives.h"

#include <stdexcept>
#include <string>

namespace frep {

namespace {

void requireNonZero(const Expr& e, const char* what) {
  if (e.isConst() && e.constValue() == 0.0)
    throw std::invalid_argument(std::string(what) + " must be non-zero");
}

Expr d(const Coords3& c, uint32_t i) { return Expr::x(i) - c[i]; }

// The two coordinates orthogonal to `axis`, in HyperFun's order (X: y, z; Y: x, z; Z: x, y).
void across(uint32_t axis, uint32_t& p, uint32_t& q) {
  p = axis == 0 ? 1 : 0;
  q = axis == 2 ? 1 : 2;
}

Expr cylinder(uint32_t axis, const Coords3& c, const Expr& r) {
  uint32_t p, q;
  across(axis, p, q);
  return square(r) - square(d(c, p)) - square(d(c, q));
}

Expr ellipticCylinder(uint32_t axis, const Coords3& c, const Expr& a, const Expr& b) {
  requireNonZero(a, "elliptic cylinder semi-axis a");
  requireNonZero(b, "elliptic cylinder semi-axis b");
  uint32_t p, q;
  across(axis, p, q);
  return 1.0 - square(d(c, p) / a) - square(d(c, q) / b);
}

Expr cone(uint32_t axis, const Coords3& c, const Expr& r) {
  requireNonZero(r, "cone radius");
  uint32_t p, q;
  across(axis, p, q);
  return square(d(c, axis)) - square(d(c, p) / r) - square(d(c, q) / r);
}

Expr torus(uint32_t axis, const Coords3& c, const Expr& majorR, const Expr& minorR) {
  uint32_t p, q;
  across(axis, p, q);
  Expr rho = sqrt(square(d(c, p)) + square(d(c, q)));
  return square(minorR) - square(rho - majorR) - square(d(c, axis));
}

// |t| <= h as the R-intersection of the half-spaces t >= −h and t <= h.
Expr slab(const Expr& t, const Expr& h, const Expr& a) { return rIntersection(h + t, h - t, a); }

}  // namespace

Expr ball(const std::vector<Expr>& c, const Expr& r) {
  Expr f = square(r);
  for (size_t i = 0; i < c.size(); ++i) f = f - square(Expr::x(static_cast<uint32_t>(i)) - c[i]);
  return f;
}

Expr sphere(const Coords3& c, const Expr& r) { return ball({c[0], c[1], c[2]}, r); }

Expr ellipsoid(const Coords3& c, const Coords3& radii) {
  Expr f = 1.0;
  for (uint32_t i = 0; i < 3; ++i) {
    requireNonZero(radii[i], "ellipsoid semi-axis");
    f = f - square(d(c, i) / radii[i]);
  }
  return f;
}

Expr halfSpace(const std::vector<Expr>& normal, const Expr& offset) {
  Expr dot;
  for (size_t i = 0; i < normal.size(); ++i)
    dot = dot + normal[i] * Expr::x(static_cast<uint32_t>(i));
  return offset - dot;
}

Expr block(const Coords3& c, const Coords3& halfSize, const Expr& a) {
  Expr f = slab(d(c, 0), halfSize[0], a);
  for (uint32_t i = 1; i < 3; ++i) f = rIntersection(f, slab(d(c, i), halfSize[i], a), a);
  return f;
}

Expr cylinderX(const Coords3& c, const Expr& r) { return cylinder(0, c, r); }
Expr cylinderY(const Coords3& c, const Expr& r) { return cylinder(1, c, r); }
Expr cylinderZ(const Coords3& c, const Expr& r) { return cylinder(2, c, r); }
Expr ellipticCylinderX(const Coords3& c, const Expr& a, const Expr& b) {
  return ellipticCylinder(0, c, a, b);
}
Expr ellipticCylinderY(const Coords3& c, const Expr& a, const Expr& b) {
  return ellipticCylinder(1, c, a, b);
}
Expr ellipticCylinderZ(const Coords3& c, const Expr& a, const Expr& b) {
  return ellipticCylinder(2, c, a, b);
}
Expr coneX(const Coords3& c, const Expr& r) { return cone(0, c, r); }
Expr coneY(const Coords3& c, const Expr& r) { return cone(1, c, r); }
Expr coneZ(const Coords3& c, const Expr& r) { return cone(2, c, r); }
Expr torusX(const Coords3& c, const Expr& majorR, const Expr& minorR) {
  return torus(0, c, majorR, minorR);
}
Expr torusY(const Coords3& c, const Expr& majorR, const Expr& minorR) {
  return torus(1, c, majorR, minorR);
}
Expr torusZ(const Coords3& c, const Expr& majorR, const Expr& minorR) {
  return torus(2, c, majorR, minorR);
}

Expr superellipsoid(const Coords3& c, const Coords3& radii, const Expr& s1, const Expr& s2) {
  requireNonZero(s1, "superellipsoid exponent s1");
  requireNonZero(s2, "superellipsoid exponent s2");
  Expr u[3];
  for (uint32_t i = 0; i < 3; ++i) {
    requireNonZero(radii[i], "superellipsoid semi-axis");
    u[i] = abs(d(c, i) / radii[i]);
  }
  Expr e2 = 2.0 / s2, e1 = 2.0 / s1;
  return 1.0 - pow(pow(u[0], e2) + pow(u[1], e2), s2 / s1) - pow(u[2], e1);
}

Expr disc(const Coords2& c, const Expr& r) { return ball({c[0], c[1]}, r); }

Expr rectangle(const Coords2& c, const Coords2& halfSize, const Expr& a) {
  return rIntersection(slab(Expr::x(0) - c[0], halfSize[0], a),
                       slab(Expr::x(1) - c[1], halfSize[1], a), a);
}

}  // namespace frep
