// Small helpers shared by the hf* library sources (hf_*.cpp): argument access, array-size
// checks with messages naming the function and the argument, and the a = 0 R-functions.
#pragma once

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "frep/expressions/expr.h"
#include "frep/primitives/ops.h"
#include "frep/lang/library/library.h"

namespace frep::lang::hf {

inline std::vector<Expr>& arrayArg(const char* fn, std::vector<Arg>& args, int i) {
  if (i >= static_cast<int>(args.size()) || !args[i].isArray || !args[i].array)
    throw LibraryError(std::string(fn) + ": argument " + std::to_string(i + 1) +
                           " must be an array name", i);
  return *args[i].array;
}

inline const Expr& scalarArg(const char* fn, std::vector<Arg>& args, int i) {
  if (i >= static_cast<int>(args.size()) || args[i].isArray)
    throw LibraryError(std::string(fn) + ": argument " + std::to_string(i + 1) +
                           " must be a scalar expression", i);
  return args[i].value;
}

inline std::string argName(std::vector<Arg>& args, int i, const char* fallback) {
  return args[i].name.empty() ? std::string(fallback) : args[i].name;
}

// Throws unless array argument i has at least `n` elements.
inline std::vector<Expr>& arrayAtLeast(const char* fn, std::vector<Arg>& args, int i, size_t n,
                                       const char* what) {
  std::vector<Expr>& a = arrayArg(fn, args, i);
  if (a.size() < n)
    throw LibraryError(std::string(fn) + ": array " + argName(args, i, what) + " must have at least " +
                           std::to_string(n) + " elements (got " + std::to_string(a.size()) + ")",
                       i);
  return a;
}

// Throws unless array argument i has exactly `n` elements.
inline std::vector<Expr>& arrayExactly(const char* fn, std::vector<Arg>& args, int i, size_t n,
                                       const std::string& why) {
  std::vector<Expr>& a = arrayArg(fn, args, i);
  if (a.size() != n)
    throw LibraryError(std::string(fn) + ": array " + argName(args, i, "argument") + " must have " +
                           std::to_string(n) + " elements" + why + " (got " +
                           std::to_string(a.size()) + ")",
                       i);
  return a;
}

// A scalar that must be known at compile time (a loop count, a degree).
inline double constArg(const char* fn, std::vector<Arg>& args, int i, const char* what) {
  const Expr& e = scalarArg(fn, args, i);
  if (!e.isConst())
    throw LibraryError(std::string(fn) + ": " + what + " must be a constant known at compile time",
                       i);
  return e.constValue();
}

struct Vec3 {
  Expr x, y, z;
};
inline Vec3 sub3(const std::vector<Expr>& a, const std::vector<Expr>& b, size_t bi = 0) {
  return {a[0] - b[bi], a[1] - b[bi + 1], a[2] - b[bi + 2]};
}
inline Expr dot3(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Expr norm2(const Vec3& a) { return dot3(a, a); }

// HyperFun's set operations with alpha = 0 (int_calc.c semantics, see docs/language.md).
inline Expr rUnion0(const Expr& a, const Expr& b) { return rUnion(a, b, 0.0); }
inline Expr rInter0(const Expr& a, const Expr& b) { return rIntersection(a, b, 0.0); }

constexpr double kPi = 3.14159265358979323846;

// Runs a core builder, turning its std::invalid_argument into a diagnostic at argument `arg`.
template <typename F>
auto guarded(const char* fn, int arg, F&& build) -> decltype(build()) {
  try {
    return build();
  } catch (const std::invalid_argument& e) {
    throw LibraryError(std::string(fn) + ": " + e.what(), arg);
  }
}

}  // namespace frep::lang::hf
