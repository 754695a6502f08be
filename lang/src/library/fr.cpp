// frepfarm's fr* extensions to the HyperFun library: the core operation library (frep/primitives/ops.h)
// exposed to models. Set operations take the survey's R-function parameter a (HyperFun fixes
// a = 0); transformations rewrite their coordinate array in place and return 1, like hf*.
#include <cmath>
#include <stdexcept>
#include <string>

#include "frep/primitives/ops.h"
#include "library/hf_util.h"

namespace frep::lang {
namespace {

using hf::arrayAtLeast;
using hf::constArg;
using hf::scalarArg;

using hf::guarded;

// An axis given as 1, 2 or 3 (x, y, z), constant at compile time.
Axis axisArg(const char* fn, std::vector<Arg>& a, int i) {
  double v = constArg(fn, a, i, "the axis");
  if (v != 1.0 && v != 2.0 && v != 3.0)
    throw LibraryError(std::string(fn) + ": the axis must be 1, 2 or 3 (x, y, z)", i);
  return static_cast<Axis>(static_cast<uint32_t>(v) - 1);
}

// xt := q(xt): the deformed object reads the original at the mapping's inverse image.
Expr mapCoords(const char* fn, std::vector<Arg>& a, const Mapping& m) {
  std::vector<Expr>& xt = arrayAtLeast(fn, a, 0, 3, "xt");
  std::vector<Expr> old(xt.begin(), xt.begin() + 3);
  for (size_t i = 0; i < 3; ++i) xt[i] = remap(m.inverse[i], old);
  return 1.0;
}

using SetOp = Expr (*)(const Expr&, const Expr&, const Expr&);
LibraryFunction setOp(const char* name, SetOp op, const char* summary) {
  return {name, "SSS", summary, [name, op](std::vector<Arg>& a) {
            return guarded(name, 2, [&] {
              return op(scalarArg(name, a, 0), scalarArg(name, a, 1), scalarArg(name, a, 2));
            });
          }};
}

using SmoothOp = Expr (*)(const Expr&, const Expr&, double);
LibraryFunction smoothOp(const char* name, SmoothOp op, const char* summary) {
  return {name, "SSS", summary, [name, op](std::vector<Arg>& a) {
            double m = constArg(name, a, 2, "the smoothness m");
            return guarded(name, 2, [&] {
              return op(scalarArg(name, a, 0), scalarArg(name, a, 1), m);
            });
          }};
}

using BlendOp = Expr (*)(const Expr&, const Expr&, const Expr&, const Expr&, const Expr&,
                         const Expr&);
LibraryFunction blendOp(const char* name, BlendOp op, const char* summary) {
  return {name, "SSSSS", summary, [name, op](std::vector<Arg>& a) {
            return guarded(name, -1, [&] {
              return op(scalarArg(name, a, 0), scalarArg(name, a, 1), scalarArg(name, a, 2),
                        scalarArg(name, a, 3), scalarArg(name, a, 4), 0.0);
            });
          }};
}

Expr frOffset(std::vector<Arg>& a) {
  return offsetConst(scalarArg("frOffset", a, 0), scalarArg("frOffset", a, 1));
}

// frOffsetNormal(f, D): f(X + D grad f / |grad f|), the survey's offset along the normal; f is
// the object's field as an expression of x, differentiated symbolically.
Expr frOffsetNormal(std::vector<Arg>& a) {
  return offsetNormal(scalarArg("frOffsetNormal", a, 0), scalarArg("frOffsetNormal", a, 1));
}

Expr frMorph(std::vector<Arg>& a) {
  const char* fn = "frMorph";
  return morph(scalarArg(fn, a, 0), scalarArg(fn, a, 1), scalarArg(fn, a, 2));
}

// frBend(xt, along, toward, R): the `along` axis wraps around a circle of radius R centred at
// distance R on the `toward` axis.
Expr frBend(std::vector<Arg>& a) {
  const char* fn = "frBend";
  Axis along = axisArg(fn, a, 1), toward = axisArg(fn, a, 2);
  if (along == toward) throw LibraryError("frBend: the two axes must differ", 2);
  Mapping m = guarded(fn, 3, [&] { return bendMap(along, toward, scalarArg(fn, a, 3)); });
  return mapCoords(fn, a, m);
}

// frTwist(xt, axis, u1, u2, theta1, theta2): the turn angle goes linearly from theta1 at u1 to
// theta2 at u2 (radians, not clamped).
Expr frTwist(std::vector<Arg>& a) {
  const char* fn = "frTwist";
  Axis axis = axisArg(fn, a, 1);
  Mapping m = guarded(fn, -1, [&] {
    return twistMap(axis, scalarArg(fn, a, 2), scalarArg(fn, a, 3), scalarArg(fn, a, 4),
                    scalarArg(fn, a, 5));
  });
  return mapCoords(fn, a, m);
}

// frTaper(xt, axis, u1, u2, s1, s2): cross-sections scaled by s1 below u1, s2 above u2,
// linearly between.
Expr frTaper(std::vector<Arg>& a) {
  const char* fn = "frTaper";
  Axis axis = axisArg(fn, a, 1);
  Mapping m = guarded(fn, -1, [&] {
    return taperMap(axis, scalarArg(fn, a, 2), scalarArg(fn, a, 3), scalarArg(fn, a, 4),
                    scalarArg(fn, a, 5));
  });
  return mapCoords(fn, a, m);
}

const bool registered = registerAll({
    setOp("frUnion", rUnion, "(f1 + f2 + sqrt(f1^2 + f2^2 - 2a f1 f2)) / (1 + a), a in (-1, 1]"),
    setOp("frIntersection", rIntersection,
          "(f1 + f2 - sqrt(f1^2 + f2^2 - 2a f1 f2)) / (1 + a), a in (-1, 1]"),
    setOp("frSubtraction", rSubtraction, "frIntersection(f1, -f2, a)"),
    smoothOp("frUnionSmooth", rUnionSmooth, "(f1 + f2 + sqrt(f1^2 + f2^2)) (f1^2 + f2^2)^(m/2)"),
    smoothOp("frIntersectionSmooth", rIntersectionSmooth,
             "(f1 + f2 - sqrt(f1^2 + f2^2)) (f1^2 + f2^2)^(m/2)"),
    blendOp("frBlendUnion", blendUnion, "f1 | f2 + a0 / (1 + (f1/a1)^2 + (f2/a2)^2)"),
    blendOp("frBlendIntersection", blendIntersection,
            "f1 & f2 + a0 / (1 + (f1/a1)^2 + (f2/a2)^2)"),
    {"frOffset", "SS", "f + C", frOffset},
    {"frOffsetNormal", "SS", "f(X + D grad f / |grad f|)", frOffsetNormal},
    {"frMorph", "SSS", "f1 (1 - g) + f2 g", frMorph},
    {"frBend", "ASSS", "bend axis `along` (1-3) around radius R toward axis `toward`", frBend},
    {"frTwist", "ASSSSS", "turn about axis (1-3) by theta lerped from theta1 at u1 to theta2 at u2",
     frTwist},
    {"frTaper", "ASSSSS", "scale across axis (1-3) by s1 below u1 .. s2 above u2", frTaper},
});

}  // namespace
}  // namespace frep::lang
