// HyperFun's algebraic primitives (hfSphere ... hfSoft): each returns its field, inside >= 0.
// Formulas from HyperFun's library documentation (HF_lib), re-derived; p = x - center.
#include <array>
#include <string>

#include "library/fr_minkowski.h"
#include "library/hf_util.h"

namespace frep::lang::hf {
namespace {

// p = x - c for the first three coordinates.
std::array<Expr, 3> offset(const char* fn, std::vector<Arg>& args) {
  auto& x = arrayAtLeast(fn, args, 0, 3, "x");
  auto& c = arrayAtLeast(fn, args, 1, 3, "center");
  return {x[0] - c[0], x[1] - c[1], x[2] - c[2]};
}

// The two coordinates other than `axis`, in increasing index order.
std::array<int, 2> others(int axis) {
  if (axis == 0) return {1, 2};
  if (axis == 1) return {0, 2};
  return {0, 1};
}

const char* kAxisName[3] = {"X", "Y", "Z"};

std::vector<LibraryFunction> axisFamily(
    const std::string& base, const std::string& sig, const std::string& summary,
    Expr (*field)(const char*, std::vector<Arg>&, int axis)) {
  std::vector<LibraryFunction> out;
  for (int axis = 0; axis < 3; ++axis) {
    std::string name = base + kAxisName[axis];
    out.push_back({name, sig, summary + " (" + kAxisName[axis] + " axis)",
                   [field, axis, name](std::vector<Arg>& a) { return field(name.c_str(), a, axis); }});
  }
  return out;
}

Expr cylinder(const char* fn, std::vector<Arg>& a, int axis) {
  auto p = offset(fn, a);
  Expr R = scalarArg(fn, a, 2);
  auto o = others(axis);
  const Expr field = R * R - p[o[0]] * p[o[0]] - p[o[1]] * p[o[1]];
  // R^2 - rho^2 >= 0 exactly where R - rho >= 0, the cylinder's exact signed distance.
  if (!R.isConst() || !(R.constValue() > 0)) return field;
  return registerDistanceTwin(field, arrayAtLeast(fn, a, 0, 3, "x"), R - sqrt(p[o[0]] * p[o[0]] + p[o[1]] * p[o[1]]),
                              std::string(fn) + " (its exact distance R - rho)");
}

Expr ellCylinder(const char* fn, std::vector<Arg>& a, int axis) {
  auto p = offset(fn, a);
  auto o = others(axis);
  return 1.0 - square(p[o[0]] / scalarArg(fn, a, 2)) - square(p[o[1]] / scalarArg(fn, a, 3));
}

Expr torus(const char* fn, std::vector<Arg>& a, int axis) {
  auto p = offset(fn, a);
  Expr R = scalarArg(fn, a, 2), r0 = scalarArg(fn, a, 3);
  auto o = others(axis);
  Expr rho2 = p[o[0]] * p[o[0]] + p[o[1]] * p[o[1]];
  // (sqrt(rho2) - R)^2 + h^2 <= r0^2, expanded as HyperFun does.
  const Expr field = r0 * r0 - (rho2 + p[axis] * p[axis]) - R * R + 2.0 * R * sqrt(rho2);
  // The same set as r0 - |(rho - R, h)|, the exact signed distance of a ring torus (R >= r0:
  // for a spindle torus the nearest boundary point can lie across the axis).
  if (!R.isConst() || !r0.isConst() || !(r0.constValue() > 0) || !(R.constValue() >= r0.constValue())) return field;
  return registerDistanceTwin(field, arrayAtLeast(fn, a, 0, 3, "x"),
                              r0 - sqrt(square(sqrt(rho2) - R) + p[axis] * p[axis]),
                              std::string(fn) + " (its exact distance r0 - |(rho - R, h)|)");
}

Expr cone(const char* fn, std::vector<Arg>& a, int axis) {
  auto p = offset(fn, a);
  Expr R = scalarArg(fn, a, 2);
  auto o = others(axis);
  return p[axis] * p[axis] - square(p[o[0]] / R) - square(p[o[1]] / R);
}

Expr ellCone(const char* fn, std::vector<Arg>& a, int axis) {
  auto p = offset(fn, a);
  auto o = others(axis);
  return p[axis] * p[axis] - square(p[o[0]] / scalarArg(fn, a, 2)) -
         square(p[o[1]] / scalarArg(fn, a, 3));
}

Expr sphere(std::vector<Arg>& a) {
  auto p = offset("hfSphere", a);
  Expr R = scalarArg("hfSphere", a, 2);
  // R^2 - |p|^2 >= 0 exactly on the ball |p| <= R: the exact Minkowski paths apply.
  return registerHyperFunShape(R * R - p[0] * p[0] - p[1] * p[1] - p[2] * p[2], arrayAtLeast("hfSphere", a, 0, 3, "x"),
                               false, arrayAtLeast("hfSphere", a, 1, 3, "center"), {R});
}

Expr ellipsoid(std::vector<Arg>& a) {
  const char* fn = "hfEllipsoid";
  auto p = offset(fn, a);
  return 1.0 - square(p[0] / scalarArg(fn, a, 2)) - square(p[1] / scalarArg(fn, a, 3)) -
         square(p[2] / scalarArg(fn, a, 4));
}

// Block from vertex v with edges dx, dy, dz: intersection (a = 0) of three slabs.
Expr block(std::vector<Arg>& a) {
  const char* fn = "hfBlock";
  auto& x = arrayAtLeast(fn, a, 0, 3, "x");
  auto& v = arrayAtLeast(fn, a, 1, 3, "vertex");
  Expr s[3];
  for (int i = 0; i < 3; ++i) {
    const Expr& d = scalarArg(fn, a, 2 + i);
    if (d.isConst() && d.constValue() < 0)
      throw LibraryError(std::string(fn) + ": edge lengths must be >= 0", 2 + i);
    s[i] = (x[i] - v[i]) * (v[i] + d - x[i]);
  }
  // Each slab product is >= 0 exactly on [v, v + d] and &0 is sign-exact: the set is the block.
  return registerHyperFunShape(rInter0(rInter0(s[0], s[1]), s[2]), x, true, v,
                               {scalarArg(fn, a, 2), scalarArg(fn, a, 3), scalarArg(fn, a, 4)});
}

// 1 - (|X|^(2/s2) + |Y|^(2/s2))^(s2/s1) - |Z|^(2/s1), X = dx/a, ...
Expr superellipsoid(std::vector<Arg>& a) {
  const char* fn = "hfSuperell";
  auto p = offset(fn, a);
  Expr X = abs(p[0] / scalarArg(fn, a, 2)), Y = abs(p[1] / scalarArg(fn, a, 3)),
       Z = abs(p[2] / scalarArg(fn, a, 4));
  Expr s1 = scalarArg(fn, a, 5), s2 = scalarArg(fn, a, 6);
  Expr e2 = 2.0 / s2, e1 = 2.0 / s1;
  return 1.0 - pow(pow(X, e2) + pow(Y, e2), s2 / s1) - pow(Z, e1);
}

// Checks that the arrays args[first .. first+count) all have the same size and returns it.
size_t sameSizes(const char* fn, std::vector<Arg>& a, int first, int count, const char* names) {
  std::string sizes;
  int firstBad = -1;  // the diagnostic points at the first array whose size differs
  size_t n = arrayArg(fn, a, first).size();
  for (int i = first; i < first + count; ++i) {
    size_t k = arrayArg(fn, a, i).size();
    if (k != n && firstBad < 0) firstBad = i;
    sizes += (i > first ? ", " : "") + std::to_string(k);
  }
  if (firstBad >= 0)
    throw LibraryError(std::string(fn) + ": arrays " + names + " must have the same size (got " +
                           sizes + ")",
                       firstBad);
  return n;
}

Expr dist2(const std::vector<Expr>& x, const Expr& cx, const Expr& cy, const Expr& cz) {
  return square(x[0] - cx) + square(x[1] - cy) + square(x[2] - cz);
}

// Sum b_i exp(-a_i r_i^2) - T.
Expr blobby(std::vector<Arg>& a) {
  const char* fn = "hfBlobby";
  auto& x = arrayAtLeast(fn, a, 0, 3, "x");
  size_t n = sameSizes(fn, a, 1, 5, "x0, y0, z0, a, b");
  auto &x0 = *a[1].array, &y0 = *a[2].array, &z0 = *a[3].array, &aa = *a[4].array,
       &b = *a[5].array;
  Expr sum = 0.0;
  for (size_t i = 0; i < n; ++i) sum = sum + b[i] * exp(-aa[i] * dist2(x, x0[i], y0[i], z0[i]));
  return sum - scalarArg(fn, a, 6);
}

// Metaballs (Nishimura): b(1 - 3r^2/d^2) for r <= d/3, 1.5 b (1 - r/d)^2 for r < d, else 0;
// elements with d <= 0 contribute nothing.
Expr metaball(std::vector<Arg>& a) {
  const char* fn = "hfMetaball";
  auto& x = arrayAtLeast(fn, a, 0, 3, "x");
  size_t n = sameSizes(fn, a, 1, 5, "x0, y0, z0, b, d");
  auto &x0 = *a[1].array, &y0 = *a[2].array, &z0 = *a[3].array, &b = *a[4].array,
       &d = *a[5].array;
  Expr sum = 0.0;
  for (size_t i = 0; i < n; ++i) {
    Expr r2 = dist2(x, x0[i], y0[i], z0[i]);
    Expr r = sqrt(r2);
    Expr inner = b[i] * (1.0 - 3.0 * r2 / (d[i] * d[i]));
    Expr outer = 1.5 * b[i] * square(1.0 - r / d[i]);
    Expr term = select(le(r, d[i] / 3.0), inner, select(lt(r, d[i]), outer, 0.0));
    sum = sum + select(gt(d[i], 0.0), term, 0.0);
  }
  return sum - scalarArg(fn, a, 6);
}

// Soft objects (Wyvill): 1 - 22r^2/9d^2 + 17r^4/9d^4 - 4r^6/9d^6 for r <= d, else 0.
Expr soft(std::vector<Arg>& a) {
  const char* fn = "hfSoft";
  auto& x = arrayAtLeast(fn, a, 0, 3, "x");
  size_t n = sameSizes(fn, a, 1, 4, "x0, y0, z0, d");
  auto &x0 = *a[1].array, &y0 = *a[2].array, &z0 = *a[3].array, &d = *a[4].array;
  Expr sum = 0.0;
  for (size_t i = 0; i < n; ++i) {
    Expr r2 = dist2(x, x0[i], y0[i], z0[i]);
    Expr q = r2 / (d[i] * d[i]);  // (r/d)^2
    Expr term = 1.0 - (22.0 / 9.0) * q + (17.0 / 9.0) * q * q - (4.0 / 9.0) * q * q * q;
    sum = sum + select(le(r2, d[i] * d[i]), term, 0.0);
  }
  return sum - scalarArg(fn, a, 5);
}

std::vector<LibraryFunction> all() {
  std::vector<LibraryFunction> fns = {
      {"hfSphere", "AAS", "R^2 - |x - c|^2", sphere},
      {"hfEllipsoid", "AASSS", "1 - (dx/a)^2 - (dy/b)^2 - (dz/c)^2", ellipsoid},
      {"hfBlock", "AASSS", "(sx &0 sy) &0 sz, sx = (x - vx)(vx + dx - x)", block},
      {"hfSuperell", "AASSSSS", "1 - (|X|^(2/s2) + |Y|^(2/s2))^(s2/s1) - |Z|^(2/s1)",
       superellipsoid},
      {"hfBlobby", "AAAAAAS", "sum b_i exp(-a_i r_i^2) - T", blobby},
      {"hfMetaball", "AAAAAAS", "sum of piecewise-quadratic metaballs - T", metaball},
      {"hfSoft", "AAAAAS", "sum (1 - 22q/9 + 17q^2/9 - 4q^3/9), q = r^2/d^2 <= 1, - T", soft},
  };
  auto add = [&](std::vector<LibraryFunction> more) {
    for (auto& f : more) fns.push_back(std::move(f));
  };
  add(axisFamily("hfCylinder", "AAS", "R^2 - rho^2", cylinder));
  add(axisFamily("hfEllCyl", "AASS", "1 - (u/a)^2 - (v/b)^2", ellCylinder));
  add(axisFamily("hfTorus", "AASS", "r0^2 - |p|^2 - R^2 + 2 R rho", torus));
  add(axisFamily("hfCone", "AAS", "h^2 - (u/R)^2 - (v/R)^2", cone));
  add(axisFamily("hfEllCone", "AASS", "h^2 - (u/a)^2 - (v/b)^2", ellCone));
  return fns;
}

const bool registered = registerAll(all());

}  // namespace
}  // namespace frep::lang::hf
