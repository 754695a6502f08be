// HyperFun's space transformations: they rewrite the coordinate array they are given (in place,
// so the change holds for the rest of the object) and return 1. Each maps a point to the point
// the untransformed object is evaluated at (inverse mapping).
#include <string>

#include "library/hf_util.h"

namespace frep::lang::hf {
namespace {

const char* kAxisName[3] = {"X", "Y", "Z"};

std::vector<Expr>& coords(const char* fn, std::vector<Arg>& a) {
  return arrayAtLeast(fn, a, 0, 3, "xt");
}

// Rotation about `axis` by theta, in HyperFun's sense: about Z, x' = x cos + y sin,
// y' = -x sin + y cos; about X the pair (y, z), about Y the pair (z, x).
void rotate(std::vector<Expr>& xt, int axis, const Expr& theta) {
  int i = (axis + 1) % 3, j = (axis + 2) % 3;
  Expr c = cos(theta), s = sin(theta);
  Expr u = xt[i], v = xt[j];
  xt[i] = u * c + v * s;
  xt[j] = -u * s + v * c;
}

Expr scale3D(std::vector<Arg>& a) {
  const char* fn = "hfScale3D";
  auto& xt = coords(fn, a);
  for (int i = 0; i < 3; ++i) xt[i] = xt[i] / scalarArg(fn, a, 1 + i);
  return 1.0;
}

Expr shift3D(std::vector<Arg>& a) {
  const char* fn = "hfShift3D";
  auto& xt = coords(fn, a);
  for (int i = 0; i < 3; ++i) xt[i] = xt[i] - scalarArg(fn, a, 1 + i);
  return 1.0;
}

// xt = x0 + (xt - x0) / s
Expr stretch3D(std::vector<Arg>& a) {
  const char* fn = "hfStretch3D";
  auto& xt = coords(fn, a);
  auto& x0 = arrayAtLeast(fn, a, 1, 3, "x0");
  for (int i = 0; i < 3; ++i) xt[i] = x0[i] + (xt[i] - x0[i]) / scalarArg(fn, a, 2 + i);
  return 1.0;
}

Expr rotate3D(const char* fn, std::vector<Arg>& a, int axis) {
  rotate(coords(fn, a), axis, scalarArg(fn, a, 1));
  return 1.0;
}

// Angle interpolated linearly (not clamped) between theta1 at u1 and theta2 at u2.
Expr twist(const char* fn, std::vector<Arg>& a, int axis) {
  auto& xt = coords(fn, a);
  Expr u1 = scalarArg(fn, a, 1), u2 = scalarArg(fn, a, 2);
  Expr th1 = scalarArg(fn, a, 3), th2 = scalarArg(fn, a, 4);
  Expr t = (xt[axis] - u1) / (u2 - u1);
  rotate(xt, axis, (1.0 - t) * th1 + t * th2);
  return 1.0;
}

// Scale s1 below u1, s2 above u2, linear between; a scale with |s| < 1e-6 counts as 1.
// The two coordinates across the axis are divided by it.
Expr taper(const char* fn, std::vector<Arg>& a, int axis) {
  auto& xt = coords(fn, a);
  Expr u1 = scalarArg(fn, a, 1), u2 = scalarArg(fn, a, 2);
  Expr s1 = scalarArg(fn, a, 3), s2 = scalarArg(fn, a, 4);
  Expr u = xt[axis];
  Expr lerp = s1 + (u - u1) / (u2 - u1) * (s2 - s1);
  Expr s = select(lt(u, u1), s1, select(gt(u, u2), s2, lerp));
  s = select(lt(abs(s), 1e-6), 1.0, s);
  int i = (axis + 1) % 3, j = (axis + 2) % 3;
  xt[i] = xt[i] / s;
  xt[j] = xt[j] / s;
  return 1.0;
}

// For each control triple k: dt = dst_k - src_k, u = (xt - dst_k) / (b_k (1 + |dt|)) per axis,
// r = |u|, w = kernel(r), xt -= w dt. Triples are applied one after the other.
Expr spaceMap(const char* fn, std::vector<Arg>& a, bool cubic) {
  auto& xt = coords(fn, a);
  auto& src = arrayArg(fn, a, 1);
  auto& dst = arrayArg(fn, a, 2);
  auto& b = arrayArg(fn, a, 3);
  if (src.size() % 3 != 0 || src.size() != dst.size() || src.size() != b.size())
    throw LibraryError(std::string(fn) + ": arrays " + argName(a, 1, "src") + ", " +
                           argName(a, 2, "dst") + ", " + argName(a, 3, "b") +
                           " must have the same size, a multiple of 3 (got " +
                           std::to_string(src.size()) + ", " + std::to_string(dst.size()) + ", " +
                           std::to_string(b.size()) + ")",
                       1);
  for (size_t k = 0; k < src.size(); k += 3) {
    Expr dt[3], r2 = 0.0;
    for (int i = 0; i < 3; ++i) {
      dt[i] = dst[k + i] - src[k + i];
      Expr u = (xt[i] - dst[k + i]) / (b[k + i] * (1.0 + abs(dt[i])));
      r2 = r2 + u * u;
    }
    Expr w;
    if (cubic) {
      Expr r = sqrt(r2);
      w = select(le(r, 1.0), pow(1.0 - r, 3.0) / (1.0 + r), 0.0);
    } else {
      w = exp(-r2);
    }
    for (int i = 0; i < 3; ++i) xt[i] = xt[i] - w * dt[i];
  }
  return 1.0;
}

std::vector<LibraryFunction> all() {
  std::vector<LibraryFunction> fns = {
      {"hfScale3D", "ASSS", "xt /= (sx, sy, sz)", scale3D},
      {"hfShift3D", "ASSS", "xt -= (dx, dy, dz)", shift3D},
      {"hfStretch3D", "AASSS", "xt = x0 + (xt - x0) / (sx, sy, sz)", stretch3D},
      {"hfSpaceMapCubic", "AAAA", "xt -= w dt, w = (1-r)^3/(1+r) for r <= 1",
       [](std::vector<Arg>& a) { return spaceMap("hfSpaceMapCubic", a, true); }},
      {"hfSpaceMapExp", "AAAA", "xt -= w dt, w = exp(-r^2)",
       [](std::vector<Arg>& a) { return spaceMap("hfSpaceMapExp", a, false); }},
  };
  for (int axis = 0; axis < 3; ++axis) {
    std::string ax = kAxisName[axis];
    std::string rot = "hfRotate3D" + ax, tw = "hfTwist" + ax, tp = "hfTaper" + ax;
    fns.push_back({rot, "AS", "rotate xt about the " + ax + " axis by theta (radians)",
                   [rot, axis](std::vector<Arg>& a) { return rotate3D(rot.c_str(), a, axis); }});
    fns.push_back({tw, "ASSSS", "rotate by theta lerped from theta1 at u1 to theta2 at u2",
                   [tw, axis](std::vector<Arg>& a) { return twist(tw.c_str(), a, axis); }});
    fns.push_back({tp, "ASSSS", "divide the cross coordinates by s lerped from s1 to s2",
                   [tp, axis](std::vector<Arg>& a) { return taper(tp.c_str(), a, axis); }});
  }
  return fns;
}

const bool registered = registerAll(all());

}  // namespace
}  // namespace frep::lang::hf
