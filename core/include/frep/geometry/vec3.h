// A 3-vector of doubles and its few operations, for the code that works with points and
// directions (the simplifier, the renderer, ...). A plain std::array, and each operation the
// expression written out in full, in this order: a function using them computes the same bits
// as one that spells them out.
#pragma once

#include <array>
#include <cmath>

namespace frep {

using Vec3 = std::array<double, 3>;

namespace vec3 {

inline Vec3 add(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
inline Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline Vec3 scale(const Vec3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
inline double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }
// a / |a| (componentwise division by the norm; not finite for the zero vector).
inline Vec3 normalized(const Vec3& a) {
  const double n = norm(a);
  return {a[0] / n, a[1] / n, a[2] / n};
}

}  // namespace vec3
}  // namespace frep
