// HyperFun's convolution surfaces with the Cauchy kernel k(r) = 1 / (1 + S^2 r^2)^2
// (McCormack and Sherstyuk 1998): the field is the kernel integrated over a skeleton, minus a
// threshold T. Sums over skeleton elements unroll (array sizes are known at compile time).
// Scales as hfp's library has them (checked against its formulas): segments integrate over the
// length, triangles give S^3 times the area integral, arcs integrate over the angle (the arc
// length integral divided by the radius).
#include <string>

#include "library/hf_util.h"

namespace frep::lang::hf {
namespace {

Vec3 at(const std::vector<Expr>& v, size_t i) { return {v[i], v[i + 1], v[i + 2]}; }
Vec3 minus(const Vec3& a, const Vec3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

// Kernel integrated along the segment b -> e:
// t/(2p^2(p^2+S^2t^2)) + (l-t)/(2p^2q^2) + (atan(St/p) + atan(S(l-t)/p))/(2Sp^3),
// t = (x-b).(e-b)/l, p^2 = 1 + S^2(|x-b|^2 - t^2), q^2 = 1 + S^2(|x-b|^2 + l^2 - 2lt).
Expr segment(const Vec3& x, const Vec3& b, const Vec3& e, const Expr& S) {
  Vec3 d = minus(x, b), be = minus(e, b);
  Expr l = sqrt(norm2(be));
  Expr t = dot3(d, be) / l;
  Expr d2 = norm2(d), S2 = S * S;
  Expr p2 = 1.0 + S2 * (d2 - t * t);
  Expr q2 = 1.0 + S2 * (d2 + l * l - 2.0 * l * t);
  Expr p = sqrt(p2);
  return t / (2.0 * p2 * (p2 + S2 * t * t)) + (l - t) / (2.0 * p2 * q2) +
         (atan(S * t / p) + atan(S * (l - t) / p)) / (2.0 * S * p2 * p);
}

// Kernel integrated over the triangle (A, B, C). With h the distance to the triangle's plane
// and c^2 = 1 + S^2 h^2, the integral is a signed sum over edges of fans from the foot of the
// perpendicular: for edge P -> Q with unit direction u, a = signed in-plane distance of x from
// the edge line (positive on the triangle's side), w = sqrt(c^2 + S^2 a^2):
//   a / (2 S c^2 w) * (atan(S (Q-x).u / w) - atan(S (P-x).u / w)).
Expr triangle(const Vec3& x, const Vec3 v[3], const Expr& S) {
  Vec3 n = cross(minus(v[1], v[0]), minus(v[2], v[0]));
  Expr nn = sqrt(norm2(n));
  Vec3 nu = {n.x / nn, n.y / nn, n.z / nn};
  Expr h = dot3(minus(x, v[0]), nu);
  Expr S2 = S * S;
  Expr c2 = 1.0 + S2 * h * h;
  Expr sum = 0.0;
  for (int i = 0; i < 3; ++i) {
    const Vec3 &P = v[i], &Q = v[(i + 1) % 3];
    Vec3 pq = minus(Q, P);
    Expr len = sqrt(norm2(pq));
    Vec3 u = {pq.x / len, pq.y / len, pq.z / len};
    Vec3 inward = cross(nu, u);
    Expr a = dot3(minus(x, P), inward);
    Expr w = sqrt(c2 + S2 * a * a);
    Expr uq = dot3(minus(Q, x), u), up = dot3(minus(P, x), u);
    sum = sum + a / (2.0 * S * c2 * w) * (atan(S * uq / w) - atan(S * up / w));
  }
  return sum;
}

// Kernel integrated along the arc of radius r in the local xy-plane from angle 0 to theta
// (radians), for the local point p. With rho, phi0 the polar coordinates of (px, py),
// A = 1 + S^2 (|p|^2 + r^2), B = 2 S^2 r rho, D = A - B cos psi, k^2 = A^2 - B^2 (> 0):
//   r [B sin psi / (k^2 D) + (A/k^2) F(psi)] from psi = -phi0 to theta - phi0,
//   F(psi) = psi/k + (2/k) atan((c-1) sin psi / ((c+1) - (c-1) cos psi)), c = sqrt((A+B)/(A-B)),
// a continuous antiderivative of 1/D (valid for arcs longer than pi).
Expr arc(const Vec3& p, const Expr& r, const Expr& theta, const Expr& S) {
  Expr S2 = S * S;
  Expr rho = sqrt(p.x * p.x + p.y * p.y);
  Expr phi0 = atan2(p.y, p.x);
  Expr A = 1.0 + S2 * (norm2(p) + r * r), B = 2.0 * S2 * r * rho;
  Expr k2 = A * A - B * B, k = sqrt(k2);
  Expr c = sqrt((A + B) / (A - B));
  auto prim = [&](const Expr& psi) {
    Expr F = psi / k + (2.0 / k) * atan((c - 1.0) * sin(psi) / ((c + 1.0) - (c - 1.0) * cos(psi)));
    return B * sin(psi) / (k2 * (A - B * cos(psi))) + A / k2 * F;
  };
  return r * (prim(theta - phi0) - prim(-phi0));
}

const std::vector<Expr>& coords(const char* fn, std::vector<Arg>& a) {
  return arrayAtLeast(fn, a, 0, 3, "x");
}

Expr convPoint(std::vector<Arg>& a) {
  const char* fn = "hfConvPoint";
  Vec3 x = at(coords(fn, a), 0);
  auto& S = arrayArg(fn, a, 2);
  auto& v = arrayExactly(fn, a, 1, 3 * S.size(), " (3 per element of " + argName(a, 2, "S") + ")");
  Expr sum = 0.0;
  for (size_t i = 0; i < S.size(); ++i) {
    Expr r2 = norm2(minus(x, at(v, 3 * i)));
    sum = sum + 1.0 / square(1.0 + S[i] * S[i] * r2);
  }
  return sum - scalarArg(fn, a, 3);
}

Expr convLine(std::vector<Arg>& a) {
  const char* fn = "hfConvLine";
  Vec3 x = at(coords(fn, a), 0);
  auto& S = arrayArg(fn, a, 3);
  std::string why = " (3 per element of " + argName(a, 3, "S") + ")";
  auto& b = arrayExactly(fn, a, 1, 3 * S.size(), why);
  auto& e = arrayExactly(fn, a, 2, 3 * S.size(), why);
  Expr sum = 0.0;
  for (size_t i = 0; i < S.size(); ++i) sum = sum + segment(x, at(b, 3 * i), at(e, 3 * i), S[i]);
  return sum - scalarArg(fn, a, 4);
}

// Polyline v0 -> v1 -> ... -> vN with one S per segment.
Expr convCurve(std::vector<Arg>& a) {
  const char* fn = "hfConvCurve";
  Vec3 x = at(coords(fn, a), 0);
  auto& S = arrayArg(fn, a, 2);
  auto& v = arrayExactly(fn, a, 1, 3 * (S.size() + 1),
                         " (3 per vertex, one more vertex than " + argName(a, 2, "S") + ")");
  Expr sum = 0.0;
  for (size_t i = 0; i < S.size(); ++i)
    sum = sum + segment(x, at(v, 3 * i), at(v, 3 * i + 3), S[i]);
  return sum - scalarArg(fn, a, 3);
}

// Triangles given by 9 coordinates each, one S per triangle.
Expr convTriangle(std::vector<Arg>& a) {
  const char* fn = "hfConvTriangle";
  Vec3 x = at(coords(fn, a), 0);
  auto& S = arrayArg(fn, a, 2);
  auto& v = arrayExactly(fn, a, 1, 9 * S.size(), " (9 per element of " + argName(a, 2, "S") + ")");
  Expr sum = 0.0;
  for (size_t i = 0; i < S.size(); ++i) {
    Vec3 tri[3] = {at(v, 9 * i), at(v, 9 * i + 3), at(v, 9 * i + 6)};
    sum = sum + S[i] * S[i] * S[i] * triangle(x, tri, S[i]);
  }
  return sum - scalarArg(fn, a, 3);
}

// Indexed mesh: vertices v[3V], triangles tri[3N] of 1-based vertex numbers (compile-time
// constants), one S per triangle.
Expr convMesh(std::vector<Arg>& a) {
  const char* fn = "hfConvMesh";
  Vec3 x = at(coords(fn, a), 0);
  auto& v = arrayArg(fn, a, 1);
  auto& S = arrayArg(fn, a, 3);
  auto& tri = arrayExactly(fn, a, 2, 3 * S.size(), " (3 per element of " + argName(a, 3, "S") + ")");
  if (v.size() % 3 != 0)
    throw LibraryError(std::string(fn) + ": vertex array " + argName(a, 1, "v") +
                           " size must be a multiple of 3 (got " + std::to_string(v.size()) + ")",
                       1);
  Expr sum = 0.0;
  for (size_t i = 0; i < S.size(); ++i) {
    Vec3 corners[3];
    for (int k = 0; k < 3; ++k) {
      const Expr& idx = tri[3 * i + k];
      if (!idx.isConst())
        throw LibraryError(std::string(fn) + ": triangle indices must be constants", 2);
      long n = std::lround(idx.constValue());
      if (n < 1 || 3 * static_cast<size_t>(n) > v.size())
        throw LibraryError(std::string(fn) + ": triangle index " + std::to_string(n) +
                               " out of range 1.." + std::to_string(v.size() / 3),
                           2);
      corners[k] = at(v, 3 * (n - 1));
    }
    sum = sum + S[i] * S[i] * S[i] * triangle(x, corners, S[i]);
  }
  return sum - scalarArg(fn, a, 4);
}

// Arcs: centre c, radius, opening theta (degrees, from the local x axis counter-clockwise), in
// the local xy-plane, then turned by `angle` degrees about `axis` (through the centre, right-hand
// rule). The point is taken into the arc's frame by the inverse rotation (Rodrigues).
// hfp's quirks, kept for value-for-value agreement: degrees convert with pi = 3.141592, every
// axis component and the angle get + 1e-6 (EPS) before use, theta is capped at 360. (hfp also
// writes angle + 1e-6 and a theta over 180 back into the arrays, so its later points see other
// arcs; frepfarm gives every point the first call's value, docs/language.md.)
Expr convArc(std::vector<Arg>& a) {
  const char* fn = "hfConvArc";
  Vec3 x = at(coords(fn, a), 0);
  auto& S = arrayArg(fn, a, 6);
  size_t n = S.size();
  std::string per = " (one per element of " + argName(a, 6, "S") + ")";
  std::string per3 = " (3 per element of " + argName(a, 6, "S") + ")";
  auto& c = arrayExactly(fn, a, 1, 3 * n, per3);
  auto& radius = arrayExactly(fn, a, 2, n, per);
  auto& theta = arrayExactly(fn, a, 3, n, per);
  auto& axis = arrayExactly(fn, a, 4, 3 * n, per3);
  auto& angle = arrayExactly(fn, a, 5, n, per);
  const double deg = 3.141592 / 180.0, eps = 1e-6;
  Expr sum = 0.0;
  for (size_t i = 0; i < n; ++i) {
    Vec3 p = minus(x, at(c, 3 * i)), ax = at(axis, 3 * i);
    ax = {ax.x + eps, ax.y + eps, ax.z + eps};
    Expr len = max(sqrt(norm2(ax)), eps);
    Vec3 u = {ax.x / len, ax.y / len, ax.z / len};
    Expr cb = cos((angle[i] + eps) * deg), sb = sin((angle[i] + eps) * deg);
    Vec3 uxp = cross(u, p);
    Expr up = dot3(u, p) * (1.0 - cb);
    Vec3 local = {p.x * cb - uxp.x * sb + u.x * up, p.y * cb - uxp.y * sb + u.y * up,
                  p.z * cb - uxp.z * sb + u.z * up};
    sum = sum + arc(local, radius[i], min(theta[i], 360.0) * deg, S[i]) / radius[i];
  }
  return sum - scalarArg(fn, a, 7);
}

// hfConvLineR(x, b, e, R): segments b_i -> e_i with one kernel width S = 1/R if R < 1, else 1,
// whose summed field is capped at 1 (hfp adds the segments in order and stops at 1; all terms
// are positive, so that is min(1, sum)). The threshold is the field of one segment at distance
// R from its start point, perpendicular to it (t = 0 in segment()):
//   T = l/(2 pT^2 qT^2) + atan(S l/pT)/(2 S pT^3), pT^2 = 1 + S^2 R^2, qT^2 = 1 + S^2 (R^2 + l^2),
// with l the length of the LAST segment (hfp recomputes T in its loop). So for one segment the
// surface passes at distance R from b on the plane through b perpendicular to the segment, and
// further out elsewhere (the field is larger near the middle).
Expr convLineR(std::vector<Arg>& a) {
  const char* fn = "hfConvLineR";
  Vec3 x = at(coords(fn, a), 0);
  auto& e = arrayArg(fn, a, 2);
  if (e.empty() || e.size() % 3 != 0)
    throw LibraryError(std::string(fn) + ": array " + argName(a, 2, "e") +
                           " size must be a positive multiple of 3 (got " +
                           std::to_string(e.size()) + ")",
                       2);
  auto& b = arrayExactly(fn, a, 1, e.size(), " (as many as " + argName(a, 2, "e") + ")");
  Expr R = scalarArg(fn, a, 3);
  Expr S = select(lt(R, 1.0), 1.0 / R, 1.0);
  size_t n = e.size() / 3;
  Expr sum = 0.0;
  for (size_t i = 0; i < n; ++i) sum = sum + segment(x, at(b, 3 * i), at(e, 3 * i), S);
  Expr l = sqrt(norm2(minus(at(e, 3 * (n - 1)), at(b, 3 * (n - 1)))));
  Expr S2 = S * S;
  Expr pT2 = 1.0 + S2 * R * R, qT2 = 1.0 + S2 * (R * R + l * l);
  Expr pT = sqrt(pT2);
  Expr T = l / (2.0 * pT2 * qT2) + atan(S * l / pT) / (2.0 * S * pT2 * pT);
  return min(sum, 1.0) - T;
}

// frConvPlane(x, p, n, S, T): planes through p_i with normals n_i (Vyatkin-Perturbation lists
// the plane among the Cauchy kernel's primitives, eq. 7). The kernel over a plane at distance h,
// in polar coordinates about the foot: 2 pi int rho / (1 + S^2 h^2 + S^2 rho^2)^2 d rho =
// pi / (S^2 (1 + S^2 h^2)). At hfConvTriangle's scale (S^3 times the area integral) that is
// pi S / (1 + S^2 h^2): the limit of a growing hfConvTriangle, so the two mix.
Expr convPlane(std::vector<Arg>& a) {
  const char* fn = "frConvPlane";
  Vec3 x = at(coords(fn, a), 0);
  auto& S = arrayArg(fn, a, 3);
  std::string per3 = " (3 per element of " + argName(a, 3, "S") + ")";
  auto& p = arrayExactly(fn, a, 1, 3 * S.size(), per3);
  auto& n = arrayExactly(fn, a, 2, 3 * S.size(), per3);
  Expr sum = 0.0;
  for (size_t i = 0; i < S.size(); ++i) {
    Vec3 nv = at(n, 3 * i);
    Expr len2 = norm2(nv);
    if (len2.isConst() && len2.constValue() == 0.0)
      throw LibraryError(std::string(fn) + ": normal " + std::to_string(i + 1) + " of " +
                             argName(a, 2, "n") + " is zero",
                         2);
    Expr h = dot3(minus(x, at(p, 3 * i)), nv) / sqrt(len2);
    sum = sum + kPi * S[i] / (1.0 + S[i] * S[i] * h * h);
  }
  return sum - scalarArg(fn, a, 4);
}

const bool registered = registerAll({
    {"hfConvPoint", "AAAS", "sum 1/(1 + S_i^2 r_i^2)^2 - T", convPoint},
    {"hfConvLine", "AAAAS", "sum of Cauchy kernel integrals over segments b_i -> e_i - T",
     convLine},
    {"hfConvCurve", "AAAS", "sum of Cauchy kernel integrals over polyline segments - T",
     convCurve},
    {"hfConvTriangle", "AAAS", "sum of Cauchy kernel integrals over triangles - T", convTriangle},
    {"hfConvArc", "AAAAAAAS", "sum of Cauchy kernel integrals over arcs - T", convArc},
    {"hfConvMesh", "AAAAS", "sum of Cauchy kernel integrals over indexed triangles - T",
     convMesh},
    {"frConvPlane", "AAAAS", "sum pi S_i / (1 + S_i^2 h_i^2) - T: Cauchy kernel over planes",
     convPlane},
    {"hfConvLineR", "AAAS",
     "min(1, sum of segment integrals, S = 1/R if R < 1 else 1) - field at distance R",
     convLineR},
});

}  // namespace
}  // namespace frep::lang::hf
