// Reduction of block ⊕ disc ⊕ ball into ray-tracer primitives (Roerdink-Minkowski §IV.B, §IV.D,
// Theorem 5) and the primitives' exact signed distances.
//
// Derivation (canonical frame: the disc axis is z, radius r; ball radius s; block [0, L]):
// Q = block ⊕ zdisc is the rounded rectangle R ⊕ disc(r) extruded over z ∈ [0, Lz], and the sum
// is Q ⊕ ball(s) = {X : dist(X, Q) <= s}. Sorting X by where its nearest point of Q lies:
//   the two flat z faces of Q (and Q itself)  -> 2 blocks over z ∈ [−s, Lz + s] and
//                                                4 z-cylinders of radius r over z ∈ [−s, Lz + s]
//                                                (the discus cylinders, merged along z, §IV.D)
//   the flat side faces x = −r, Lx + r, ...   -> 2 blocks over z ∈ [0, Lz]
//   the curved side faces                     -> 4 z-cylinders of radius r + s over [0, Lz]
//   the straight edges of the z faces         -> 4 x- and 4 y-cylinders of radius s
//   the arcs of the z faces                   -> 8 z-tori (r, s), one per block corner
// Every piece lies in the sum and every point of the sum is in one: the union is exact. With
// r = 0 the tori are spheres and it is the paper's block ⊕ sphere (3 blocks, 12 cylinders, 8
// spheres); with s = 0 it is its block ⊕ zdisc (2 blocks, 4 cylinders, §IV.B). Degenerate
// sizes make pieces coincide or lose a dimension: duplicates are dropped, and pieces of lower
// dimension than the largest are covered by the others (a closed union covering the relative
// interior covers its closure), so they are dropped too.
//
// Block ⊕ zdisc ⊕ sphere takes 4 blocks here where §IV.D counts 3 (27 primitives): no 3 axis
// blocks can do. A block holding (−0.9r, Ly/2, −s + ε) and one holding (Lx/2, −0.9r, −s + ε)
// cannot be the same (their hull reaches (−0.9r, −0.9r, −s + ε), outside the sum; ε < 0.002 s so
// that the y-cylinder at x = −r misses the first point), and neither can
// hold (−r − s + ε, Ly/2, Lz/2) (the hull reaches (−r − s, Ly/2, −s), outside), nor
// (Lx/2, −r − s + ε, Lz/2); no cylinder or torus holds any of these four points for large L.
// tests/core/minkowski_algebra_test.cpp checks that each of the 4 blocks alone holds such points.
#include "frep/minkowski_algebra/reduction.h"

#include "frep/minkowski_algebra/bidisc.h"
#include "frep/minkowski_algebra/disc_sum_distance.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace frep::minkowski {

int Piece::dimension() const {
  switch (kind) {
    case PieceKind::Block: {
      int d = 0;
      for (int i = 0; i < 3; ++i) d += hi[i] > lo[i];
      return d;
    }
    case PieceKind::Cylinder: return (radius > 0 ? 2 : 0) + (length > 0 ? 1 : 0);
    case PieceKind::Sphere: return radius > 0 ? 3 : 0;
    case PieceKind::Torus: return minor > 0 ? 3 : (radius > 0 ? 1 : 0);
    case PieceKind::Bidisc:
    case PieceKind::Bicircle: return radius > 0 && minor > 0 ? 3 : 0;
    case PieceKind::DiscSum:
    case PieceKind::Tridiscsphere: return 3;  // two disc radii > 0 at least (reduce())
  }
  return 0;
}

namespace {

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}
std::string vec(const Vec3& v) { return "(" + num(v[0]) + ", " + num(v[1]) + ", " + num(v[2]) + ")"; }
const char* kAxis = "xyz";

bool samePiece(const Piece& a, const Piece& b) {
  auto eq = [](double x, double y) { return std::fabs(x - y) <= 1e-12 * (1 + std::fabs(x)); };
  if (a.kind != b.kind) return false;
  for (int i = 0; i < 3; ++i)
    if (!eq(a.lo[i], b.lo[i]) || !eq(a.hi[i], b.hi[i]) || !eq(a.base[i], b.base[i])) return false;
  if (a.kind != PieceKind::Block && a.kind != PieceKind::Sphere && a.axis != b.axis) return false;
  if ((a.kind == PieceKind::Bidisc || a.kind == PieceKind::Bicircle) && a.axis2 != b.axis2) return false;
  for (int i = 0; i < 3; ++i)
    if (!eq(a.discs[i], b.discs[i])) return false;
  return eq(a.radius, b.radius) && eq(a.length, b.length) && eq(a.minor, b.minor) && eq(a.ball, b.ball);
}

// ---- exact signed distances, for Expr and double alike ----
template <class T>
T sq(const T& a) {
  return a * a;
}

// The disc-sum pieces' signed distance: a geometry field node (Expr) or its value (double), at the
// point relative to the block's corner (DiscSum) or the centre (Tridiscsphere).
DiscSumField discSumField(const Piece& p) {
  Vec3 len{0, 0, 0};
  if (p.kind == PieceKind::DiscSum)
    for (int i = 0; i < 3; ++i) len[i] = p.hi[i] - p.lo[i];
  return DiscSumField(len, p.discs, p.ball);
}
const Vec3& discSumCorner(const Piece& p) { return p.kind == PieceKind::DiscSum ? p.lo : p.base; }
double discSumSdf(const Piece& p, const double q[3]) {
  const Vec3& c = discSumCorner(p);
  const double x[3] = {q[0] - c[0], q[1] - c[1], q[2] - c[2]};
  return -discSumField(p).value(x);
}
Expr discSumSdf(const Piece& p, const Expr q[3]) {
  const Vec3& c = discSumCorner(p);
  return -fieldExpr(std::make_shared<DiscSumField>(discSumField(p)), q[0] - c[0], q[1] - c[1], q[2] - c[2]);
}

template <class T>
T pieceSdf(const Piece& p, const T q[3]) {
  using std::abs;
  using std::max;
  using std::min;
  using std::sqrt;
  const T zero(0.0);
  switch (p.kind) {
    case PieceKind::Block: {
      T d[3];
      for (int i = 0; i < 3; ++i)
        d[i] = abs(q[i] - T(0.5 * (p.lo[i] + p.hi[i]))) - T(0.5 * (p.hi[i] - p.lo[i]));
      T out = sqrt(sq(max(d[0], zero)) + sq(max(d[1], zero)) + sq(max(d[2], zero)));
      return out + min(max(d[0], max(d[1], d[2])), zero);
    }
    case PieceKind::Cylinder: {
      const int a = p.axis, b = (a + 1) % 3, c = (a + 2) % 3;
      T rho = sqrt(sq(q[b] - T(p.base[b])) + sq(q[c] - T(p.base[c])));
      T d1 = rho - T(p.radius);
      T d2 = abs(q[a] - T(p.base[a] + 0.5 * p.length)) - T(0.5 * p.length);
      return min(max(d1, d2), zero) + sqrt(sq(max(d1, zero)) + sq(max(d2, zero)));
    }
    case PieceKind::Sphere:
      return sqrt(sq(q[0] - T(p.base[0])) + sq(q[1] - T(p.base[1])) + sq(q[2] - T(p.base[2]))) -
             T(p.radius);
    case PieceKind::Torus: {
      const int a = p.axis, b = (a + 1) % 3, c = (a + 2) % 3;
      T rho = sqrt(sq(q[b] - T(p.base[b])) + sq(q[c] - T(p.base[c])));
      return sqrt(sq(rho - T(p.radius)) + sq(q[a] - T(p.base[a]))) - T(p.minor);
    }
    case PieceKind::Bidisc: {
      // Minus the bidisc gauge at the excess over the block (bidisc.h): 1-Lipschitz, sign-exact.
      const int i = p.axis, j = p.axis2, k = 3 - i - j;
      T e[3];
      for (int c = 0; c < 3; ++c)
        e[c] = max(abs(q[c] - T(0.5 * (p.lo[c] + p.hi[c]))) - T(0.5 * (p.hi[c] - p.lo[c])), zero);
      return -bidiscGauge(e[i], e[j], e[k], p.radius, p.minor);
    }
    case PieceKind::Bicircle: {
      // The quartic's sign only (tests of the ray-tracer form; no piece of an F-rep union).
      const int i = p.axis, j = p.axis2, k = 3 - i - j;
      const T x = q[i] - T(p.base[i]), y = q[j] - T(p.base[j]), z = q[k] - T(p.base[k]);
      const double a = p.radius, b = p.minor, c = a * a - b * b;
      const T quad = x * x - y * y + z * z + T(c);
      return quad * quad - T(4.0) * z * z * (T(a * a) - y * y);
    }
    case PieceKind::DiscSum:
    case PieceKind::Tridiscsphere: return discSumSdf(p, q);
  }
  return zero;
}

// The farthest distance from y to the piece (ball erosion).
template <class T>
T pieceFarthest(const Piece& p, const T y[3]) {
  using std::abs;
  using std::max;
  using std::sqrt;
  switch (p.kind) {
    case PieceKind::Block: {
      T s(0.0);
      for (int i = 0; i < 3; ++i) s = s + sq(max(abs(y[i] - T(p.lo[i])), abs(y[i] - T(p.hi[i]))));
      return sqrt(s);
    }
    case PieceKind::Cylinder:
    case PieceKind::Torus: {
      const int a = p.axis, b = (a + 1) % 3, c = (a + 2) % 3;
      T rho = sqrt(sq(y[b] - T(p.base[b])) + sq(y[c] - T(p.base[c])));
      if (p.kind == PieceKind::Torus)
        return sqrt(sq(rho + T(p.radius)) + sq(y[a] - T(p.base[a]))) + T(p.minor);
      T ax = max(abs(y[a] - T(p.base[a])), abs(y[a] - T(p.base[a] + p.length)));
      return sqrt(sq(ax) + sq(rho + T(p.radius)));
    }
    case PieceKind::Sphere:
      return sqrt(sq(y[0] - T(p.base[0])) + sq(y[1] - T(p.base[1])) + sq(y[2] - T(p.base[2]))) +
             T(p.radius);
    case PieceKind::Bidisc:
    case PieceKind::Bicircle:
    case PieceKind::DiscSum:
    case PieceKind::Tridiscsphere: break;  // no closed form; erosionExpr refuses these
  }
  return T(0.0);
}

// Local point R^T (X − offset) (or R^T (c − X − offset) for the erosion's y).
template <class T>
void toLocal(const Sum& s, const T x[3], T q[3]) {
  for (int i = 0; i < 3; ++i) {
    T v(0.0);
    bool any = false;
    for (int j = 0; j < 3; ++j) {
      double m = s.rot[j * 3 + i];
      if (m == 0.0) continue;
      T term = (x[j] - T(s.offset[j])) * T(m);
      v = any ? v + term : term;
      any = true;
    }
    q[i] = v;
  }
}

double pieceSupport(const Piece& p, const Vec3& m) {
  switch (p.kind) {
    case PieceKind::Block: {
      double h = 0;
      for (int i = 0; i < 3; ++i) h += std::max(m[i] * p.lo[i], m[i] * p.hi[i]);
      return h;
    }
    case PieceKind::Cylinder:
    case PieceKind::Torus:
    case PieceKind::Sphere: {
      double h = m[0] * p.base[0] + m[1] * p.base[1] + m[2] * p.base[2];
      if (p.kind == PieceKind::Sphere) return h + p.radius;
      const double across = std::sqrt(std::max(0.0, 1.0 - m[p.axis] * m[p.axis]));
      if (p.kind == PieceKind::Torus) return h + p.radius * across + p.minor;
      return h + std::max(0.0, m[p.axis] * p.length) + p.radius * across;
    }
    case PieceKind::Bidisc:
    case PieceKind::Bicircle: {
      // h(block) + a·|m across axis| + b·|m across axis2| (a disc's support, §II.C eq. 10).
      double h = 0;
      if (p.kind == PieceKind::Bidisc)
        for (int i = 0; i < 3; ++i) h += std::max(m[i] * p.lo[i], m[i] * p.hi[i]);
      else
        h = m[0] * p.base[0] + m[1] * p.base[1] + m[2] * p.base[2];
      return h + p.radius * std::sqrt(std::max(0.0, 1.0 - m[p.axis] * m[p.axis])) +
             p.minor * std::sqrt(std::max(0.0, 1.0 - m[p.axis2] * m[p.axis2]));
    }
    case PieceKind::DiscSum:
    case PieceKind::Tridiscsphere: {
      // h(block or centre) + h(discs) + ball (support of a sum = sum of supports).
      double h = 0;
      if (p.kind == PieceKind::DiscSum)
        for (int i = 0; i < 3; ++i) h += std::max(m[i] * p.lo[i], m[i] * p.hi[i]);
      else
        h = m[0] * p.base[0] + m[1] * p.base[1] + m[2] * p.base[2];
      return h + DiscSum{p.discs}.support(m) + p.ball;
    }
  }
  return 0;
}

}  // namespace

std::string Piece::describe() const {
  switch (kind) {
    case PieceKind::Block: return "block " + vec(lo) + " - " + vec(hi);
    case PieceKind::Cylinder:
      return std::string(1, kAxis[axis]) + "cylinder r " + num(radius) + " from " + vec(base) + " length " +
             num(length);
    case PieceKind::Sphere: return "sphere r " + num(radius) + " at " + vec(base);
    case PieceKind::Torus:
      return std::string(1, kAxis[axis]) + "torus " + num(radius) + ", " + num(minor) + " at " + vec(base);
    case PieceKind::Bidisc:
      return "block " + vec(lo) + " - " + vec(hi) + " + " + kAxis[axis] + "disc(" + num(radius) + ") + " +
             kAxis[axis2] + "disc(" + num(minor) + ")";
    case PieceKind::Bicircle:
      return std::string(1, kAxis[3 - axis - axis2]) + "bicircle " + num(radius) + ", " + num(minor) + " at " +
             vec(base);
    case PieceKind::DiscSum:
      return "block " + vec(lo) + " - " + vec(hi) + " + discs " + vec(discs) + " + ball " + num(ball);
    case PieceKind::Tridiscsphere: return "tridiscsphere discs " + vec(discs) + ", ball " + num(ball) + " at " + vec(base);
  }
  return "?";
}

int Reduction::count(PieceKind k) const {
  int n = 0;
  for (const Piece& p : pieces) n += p.kind == k;
  return n;
}

namespace {
// Drops coincident pieces and pieces of lower dimension than the largest (covered by the others:
// a closed union covering the relative interior covers its closure).
std::vector<Piece> keepLargest(const std::vector<Piece>& all) {
  int top = 0;
  for (const Piece& p : all) top = std::max(top, p.dimension());
  std::vector<Piece> kept;
  for (const Piece& p : all) {
    if (p.dimension() < top) continue;
    bool dup = false;
    for (const Piece& q : kept) dup = dup || samePiece(p, q);
    if (!dup) kept.push_back(p);
  }
  return kept;
}

// Block [lo, hi] ⊕ xdisc(a) ⊕ ydisc(b) (canonical axes x = p.axis, y = p.axis2) as ray-tracer
// primitives, by where X's excess e over the block is nonzero (the bidisc is symmetric in the
// coordinate planes, so e lies in its projection onto those axes):
//   z only, or none        -> block with z widened by a + b
//   x and y (and subsets)  -> block widened by b in x and a in y
//   x and z                -> projection: ydisc(b) ⊕ zline(±a) = block widened (b, 0, a), block
//                             widened (0, 0, a + b), 4 y-cylinders r b at z = −a, Lz + a
//   y and z                -> block widened (0, a, b), 4 x-cylinders r a at z = −b, Lz + b
//   all three              -> a bidisc at each corner: 8 bicircles, and their cylinders merged
//                             along the edges: 4 x-cylinders r a, 4 y-cylinders r b
// 4 blocks, 16 cylinders, 8 bicircles; a bidisc alone (L = 0) is 1 bicircle and 2 cylinders.
std::vector<Piece> bidiscPrimitives(const Piece& bd) {
  const int perm[3] = {bd.axis, bd.axis2, 3 - bd.axis - bd.axis2};
  const double a = bd.radius, b = bd.minor;
  double L[3];
  for (int c = 0; c < 3; ++c) L[c] = bd.hi[perm[c]] - bd.lo[perm[c]];
  auto local = [&](const Vec3& c) {
    Vec3 l{};
    for (int k = 0; k < 3; ++k) l[perm[k]] = bd.lo[perm[k]] + c[k];
    return l;
  };
  std::vector<Piece> all;
  auto block = [&](const Vec3& lo, const Vec3& hi) {
    Piece p;
    p.kind = PieceKind::Block;
    p.lo = local(lo);
    p.hi = local(hi);
    all.push_back(p);
  };
  auto cylinder = [&](int axis, Vec3 base, double radius, double length) {
    Piece p;
    p.kind = PieceKind::Cylinder;
    p.axis = perm[axis];
    p.base = local(base);
    p.radius = radius;
    p.length = length;
    all.push_back(p);
  };
  const double Lx = L[0], Ly = L[1], Lz = L[2];
  block({0, 0, -a - b}, {Lx, Ly, Lz + a + b});
  block({-b, -a, 0}, {Lx + b, Ly + a, Lz});
  block({-b, 0, -a}, {Lx + b, Ly, Lz + a});
  block({0, -a, -b}, {Lx, Ly + a, Lz + b});
  for (double x : {0.0, Lx})
    for (double z : {-a, Lz + a}) cylinder(1, {x, 0, z}, b, Ly);
  for (double y : {0.0, Ly})
    for (double z : {-b, Lz + b}) cylinder(0, {0, y, z}, a, Lx);
  for (double y : {0.0, Ly})
    for (double z : {0.0, Lz}) cylinder(0, {-b, y, z}, a, Lx + 2 * b);
  for (double x : {0.0, Lx})
    for (double z : {0.0, Lz}) cylinder(1, {x, -a, z}, b, Ly + 2 * a);
  for (double x : {0.0, Lx})
    for (double y : {0.0, Ly})
      for (double z : {0.0, Lz}) {
        Piece p;
        p.kind = PieceKind::Bicircle;
        p.axis = bd.axis;
        p.axis2 = bd.axis2;
        p.base = local({x, y, z});
        p.radius = a;
        p.minor = b;
        all.push_back(p);
      }
  return keepLargest(all);
}

// Block [lo, hi] ⊕ C, C = discs ⊕ ball, as ray-tracer primitives. X is in the sum iff its excess
// e over the block lies in C (C is convex and symmetric in the coordinate planes). Where e_k = 0
// for some axis k, e lies in C's section by x_k = 0, which is the rectangle of half-widths
// (r_j, r_i) along (i, j) (the discs normal to j and i cut there in segments) ⊕ the disc of
// radius r_k + s: extruded over the block's k range that is 2 blocks and 4 k-cylinders of radius
// r_k + s. Where every e_i > 0, X − (nearest corner) is in C: a tridiscsphere at each corner.
// 6 blocks, 12 cylinders, 8 tridiscspheres (Appendix B's B* takes 3 + 24 + 8: see docs/pov.md).
std::vector<Piece> discSumPrimitives(const Piece& ds) {
  std::vector<Piece> all;
  const Vec3& o = ds.lo;
  Vec3 L;
  for (int c = 0; c < 3; ++c) L[c] = ds.hi[c] - ds.lo[c];
  const Vec3& r = ds.discs;
  for (int k = 0; k < 3; ++k) {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    const double wi = r[j], wj = r[i], round = r[k] + ds.ball;
    for (int b = 0; b < 2; ++b) {
      Piece p;
      p.kind = PieceKind::Block;
      const double ei = wi + (b == 0 ? round : 0), ej = wj + (b == 1 ? round : 0);
      p.lo[i] = o[i] - ei, p.hi[i] = o[i] + L[i] + ei;
      p.lo[j] = o[j] - ej, p.hi[j] = o[j] + L[j] + ej;
      p.lo[k] = o[k], p.hi[k] = o[k] + L[k];
      all.push_back(p);
    }
    for (double a : {-wi, L[i] + wi})
      for (double b : {-wj, L[j] + wj}) {
        Piece p;
        p.kind = PieceKind::Cylinder;
        p.axis = k;
        p.base[i] = o[i] + a, p.base[j] = o[j] + b, p.base[k] = o[k];
        p.radius = round;
        p.length = L[k];
        all.push_back(p);
      }
  }
  for (double x : {0.0, L[0]})
    for (double y : {0.0, L[1]})
      for (double z : {0.0, L[2]}) {
        Piece p;
        p.kind = PieceKind::Tridiscsphere;
        p.base = {o[0] + x, o[1] + y, o[2] + z};
        p.discs = ds.discs;
        p.ball = ds.ball;
        all.push_back(p);
      }
  return keepLargest(all);
}
}  // namespace

std::vector<Piece> primitives(const Reduction& r) {
  std::vector<Piece> out;
  for (const Piece& p : r.pieces) {
    if (p.kind == PieceKind::Bidisc)
      for (const Piece& q : bidiscPrimitives(p)) out.push_back(q);
    else if (p.kind == PieceKind::DiscSum)
      for (const Piece& q : discSumPrimitives(p)) out.push_back(q);
    else
      out.push_back(p);
  }
  return out;
}

bool primitiveHolds(const Piece& p, const Vec3& local) {
  const double q[3] = {local[0], local[1], local[2]};
  return pieceSdf(p, q) <= 0;  // a bicircle's quartic is <= 0 on its shell only (bidisc.h)
}

Reduction reduce(const Sum& sum) {
  Reduction red;
  red.sum = sum;
  if (sum.terms == 0) {
    red.reason = "empty sum";
    return red;
  }
  if (sum.discAxes() == 3 || (sum.discAxes() == 2 && sum.ball > 0)) {
    // The bicircle-sphere / tricircle(-sphere) cases (R12–R16): one exact convex-projection piece.
    Piece p;
    p.kind = PieceKind::DiscSum;
    p.hi = sum.lengths;
    p.discs = sum.disc;
    p.ball = sum.ball;
    red.pieces.push_back(p);
    red.ok = true;
    return red;
  }
  if (sum.discAxes() == 2) {
    Piece p;
    p.kind = PieceKind::Bidisc;
    int found = 0;
    for (int i = 0; i < 3; ++i)
      if (sum.disc[i] > 0) (found++ == 0 ? p.axis : p.axis2) = i;
    p.radius = sum.disc[p.axis];
    p.minor = sum.disc[p.axis2];
    p.hi = sum.lengths;
    red.pieces.push_back(p);
    red.ok = true;
    return red;
  }
  int d = 2;
  for (int i = 0; i < 3; ++i)
    if (sum.disc[i] > 0) d = i;
  const int perm[3] = {(d + 1) % 3, (d + 2) % 3, d};  // canonical axis c -> local axis perm[c]
  const double r = sum.disc[d], s = sum.ball;
  const double Lx = sum.lengths[perm[0]], Ly = sum.lengths[perm[1]], Lz = sum.lengths[perm[2]];
  auto toLocalVec = [&](const Vec3& c) {
    Vec3 l{};
    for (int k = 0; k < 3; ++k) l[perm[k]] = c[k];
    return l;
  };
  std::vector<Piece> all;
  auto block = [&](Vec3 lo, Vec3 hi) {
    Piece p;
    p.kind = PieceKind::Block;
    p.lo = toLocalVec(lo);
    p.hi = toLocalVec(hi);
    all.push_back(p);
  };
  auto cylinder = [&](int axis, Vec3 base, double radius, double length) {
    Piece p;
    p.kind = PieceKind::Cylinder;
    p.axis = perm[axis];
    p.base = toLocalVec(base);
    p.radius = radius;
    p.length = length;
    all.push_back(p);
  };
  auto torus = [&](Vec3 c) {
    Piece p;
    p.base = toLocalVec(c);
    if (r == 0) {
      p.kind = PieceKind::Sphere;
      p.radius = s;
    } else {
      p.kind = PieceKind::Torus;
      p.axis = perm[2];
      p.radius = r;
      p.minor = s;
    }
    all.push_back(p);
  };
  block({-r, 0, -s}, {Lx + r, Ly, Lz + s});
  block({0, -r, -s}, {Lx, Ly + r, Lz + s});
  block({-r - s, 0, 0}, {Lx + r + s, Ly, Lz});
  block({0, -r - s, 0}, {Lx, Ly + r + s, Lz});
  for (double x : {0.0, Lx})
    for (double y : {0.0, Ly}) cylinder(2, {x, y, -s}, r, Lz + 2 * s);
  for (double x : {0.0, Lx})
    for (double y : {0.0, Ly}) cylinder(2, {x, y, 0}, r + s, Lz);
  for (double y : {-r, Ly + r})
    for (double z : {0.0, Lz}) cylinder(0, {0, y, z}, s, Lx);
  for (double x : {-r, Lx + r})
    for (double z : {0.0, Lz}) cylinder(1, {x, 0, z}, s, Ly);
  for (double x : {0.0, Lx})
    for (double y : {0.0, Ly})
      for (double z : {0.0, Lz}) torus({x, y, z});

  red.pieces = keepLargest(all);
  red.ok = true;
  return red;
}

namespace {
// A sum with a sphere and at most one disc axis as one closed form: its signed distance is the
// discus C = disc(r) ⊕ ball(s)'s at the excess e of the local point over the block (C is convex
// and symmetric in the coordinate planes, so the block's nearest point is the clamp),
// |(max(|e_⊥| − r, 0), e_axis)| − s: exact outside, 1-Lipschitz, and > 0 exactly inside because C
// has an interior (without the sphere it has none, and the pieces' union gives the inside).
template <class T>
T discusSdf(const Sum& sum, const T q[3]) {
  using std::abs;
  using std::max;
  using std::sqrt;
  const T zero(0.0);
  T e[3];
  for (int i = 0; i < 3; ++i) {
    const double h = 0.5 * sum.lengths[i];
    e[i] = h > 0 ? max(abs(q[i] - T(h)) - T(h), zero) : abs(q[i]);
  }
  int d = -1;
  for (int i = 0; i < 3; ++i)
    if (sum.disc[i] > 0) d = i;
  T dist;
  if (d < 0) {
    dist = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
  } else {
    const T across = max(sqrt(e[(d + 1) % 3] * e[(d + 1) % 3] + e[(d + 2) % 3] * e[(d + 2) % 3]) - T(sum.disc[d]), zero);
    dist = sqrt(across * across + e[d] * e[d]);
  }
  return dist - T(sum.ball);
}
}  // namespace

Expr unionExpr(const Reduction& r, const std::vector<Expr>& coords) {
  const Expr x[3] = {coords[0], coords[1], coords[2]};
  Expr q[3];
  toLocal(r.sum, x, q);
  if (r.sum.discAxes() <= 1 && r.sum.ball > 0) return -discusSdf(r.sum, q);
  return piecesUnionExpr(r, coords);
}

Expr piecesUnionExpr(const Reduction& r, const std::vector<Expr>& coords) {
  const Expr x[3] = {coords[0], coords[1], coords[2]};
  Expr q[3];
  toLocal(r.sum, x, q);
  Expr f;
  bool first = true;
  for (const Piece& p : r.pieces) {
    Expr v = -pieceSdf(p, q);
    f = first ? v : max(f, v);
    first = false;
  }
  return f;
}

Expr unionExpr(const Reduction& r) { return unionExpr(r, {Expr::x(0), Expr::x(1), Expr::x(2)}); }

double unionValue(const Reduction& r, const Vec3& world) {
  const double x[3] = {world[0], world[1], world[2]};
  double q[3];
  toLocal(r.sum, x, q);
  if (r.sum.discAxes() <= 1 && r.sum.ball > 0) return -discusSdf(r.sum, q);
  double f = -INFINITY;
  for (const Piece& p : r.pieces) f = std::max(f, -pieceSdf(p, q));
  return f;
}

double supportValue(const Reduction& r, const Vec3& n) {
  Vec3 m{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m[i] += r.sum.rot[j * 3 + i] * n[j];
  double h = -INFINITY;
  for (const Piece& p : r.pieces) h = std::max(h, pieceSupport(p, m));
  return h + n[0] * r.sum.offset[0] + n[1] * r.sum.offset[1] + n[2] * r.sum.offset[2];
}

bool erosionExpr(const Sum& c0, const Reduction& r, const std::vector<Expr>& coords, Expr* out,
                 std::string* reason) {
  const bool isBlock = c0.discAxes() == 0 && c0.ball == 0;
  const bool isBall = c0.discAxes() == 0 && c0.lengths == Vec3{0, 0, 0};
  bool bidisc = false;
  for (const Piece& p : r.pieces) bidisc = bidisc || p.kind == PieceKind::Bidisc || p.kind == PieceKind::DiscSum;
  if (r.ok && isBall && c0.ball > 0 && bidisc) {
    if (reason) *reason = "a sphere eroded by a bidisc or tridisc sum (the farthest point has no closed form)";
    return false;
  }
  if (!r.ok || !(isBlock || isBall)) {
    if (reason)
      *reason = !r.ok ? r.reason
                      : "the eroded solid is " + c0.describe() + ", not a block or a sphere";
    return false;
  }
  const Expr x[3] = {coords[0], coords[1], coords[2]};
  Expr f;
  bool first = true;
  if (isBall && c0.ball > 0) {
    // C0 ⊖ R_j = {X : max over k in R_j of |X + k − c| <= rho} (eq. 21), per primitive.
    Sum shifted = r.sum;  // y = R^T (c − X − offset) = −(R^T (X − (c − offset)))
    for (int i = 0; i < 3; ++i) shifted.offset[i] = c0.offset[i] - r.sum.offset[i];
    Expr q[3], y[3];
    toLocal(shifted, x, q);
    for (int i = 0; i < 3; ++i) y[i] = -q[i];
    for (const Piece& p : r.pieces) {
      Expr v = Expr(c0.ball) - pieceFarthest(p, y);
      f = first ? v : min(f, v);
      first = false;
    }
  } else {
    // A block C0 ⊖ R_j is C0 with its faces moved in by R_j's support function (eq. 21):
    // z_i in [h(−n_i), L_i − h(n_i)], n_i = C0's axes; the intersection over j keeps the max.
    Expr z[3];
    toLocal(c0, x, z);
    for (int i = 0; i < 3; ++i) {
      Vec3 n{c0.rot[i], c0.rot[3 + i], c0.rot[6 + i]};
      Vec3 mn{-n[0], -n[1], -n[2]};
      double lo = supportValue(r, mn), hi = c0.lengths[i] - supportValue(r, n);
      Expr v = min(z[i] - lo, Expr(hi) - z[i]);
      f = first ? v : min(f, v);
      first = false;
    }
  }
  *out = f;
  return true;
}

}  // namespace frep::minkowski
