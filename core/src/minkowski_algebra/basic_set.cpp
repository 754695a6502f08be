// The basic set and the grouping of a sum by type (Roerdink-Minkowski Theorem 1, eq. 14).
#include "frep/minkowski_algebra/basic_set.h"

#include <cmath>
#include <cstdio>

namespace frep::minkowski {

Mat3 identityRotation() { return {1, 0, 0, 0, 1, 0, 0, 0, 1}; }

namespace {
Mat3 mul(const Mat3& a, const Mat3& b) {
  Mat3 c{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) c[i * 3 + j] += a[i * 3 + k] * b[k * 3 + j];
  return c;
}
Vec3 apply(const Mat3& m, const Vec3& v) {
  return {m[0] * v[0] + m[1] * v[1] + m[2] * v[2], m[3] * v[0] + m[4] * v[1] + m[5] * v[2],
          m[6] * v[0] + m[7] * v[1] + m[8] * v[2]};
}
std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}
const char* kAxis = "xyz";
}  // namespace

Mat3 rotationXYZ(double ax, double ay, double az) {
  const double cx = std::cos(ax), sx = std::sin(ax), cy = std::cos(ay), sy = std::sin(ay),
               cz = std::cos(az), sz = std::sin(az);
  Mat3 rx{1, 0, 0, 0, cx, -sx, 0, sx, cx};
  Mat3 ry{cy, 0, sy, 0, 1, 0, -sy, 0, cy};
  Mat3 rz{cz, -sz, 0, sz, cz, 0, 0, 0, 1};
  return mul(rz, mul(ry, rx));
}

bool sameRotation(const Mat3& a, const Mat3& b) {
  for (int i = 0; i < 9; ++i)
    if (std::fabs(a[i] - b[i]) > 1e-12) return false;
  return true;
}

std::string Shape::describe() const {
  std::string at = " at (" + num(pos[0]) + ", " + num(pos[1]) + ", " + num(pos[2]) + ")";
  switch (kind) {
    case ShapeKind::Segment: return std::string(1, kAxis[axis]) + "line(" + num(size[0]) + at + ")";
    case ShapeKind::Disc: return std::string(1, kAxis[axis]) + "disc(r " + num(size[0]) + at + ")";
    case ShapeKind::Sphere: return "sphere(r " + num(size[0]) + at + ")";
    case ShapeKind::Block:
      return "block(" + num(size[0]) + " x " + num(size[1]) + " x " + num(size[2]) + at + ")";
  }
  return "?";
}

bool Sum::add(const Shape& s) {
  if (s.kind != ShapeKind::Sphere) {
    if (hasFrame && !sameRotation(rot, s.rot)) return false;
    if (!hasFrame) {
      rot = s.rot;
      hasFrame = true;
    }
  }
  for (int i = 0; i < 3; ++i) offset[i] += s.pos[i];
  switch (s.kind) {
    case ShapeKind::Segment:
    case ShapeKind::Block: {
      Vec3 l = s.kind == ShapeKind::Block ? s.size : Vec3{0, 0, 0};
      if (s.kind == ShapeKind::Segment) l[s.axis] = s.size[0];
      // A negative edge starts at the other end: move the local origin there.
      Vec3 neg{0, 0, 0};
      for (int i = 0; i < 3; ++i) {
        if (l[i] < 0) neg[i] = l[i];
        lengths[i] += std::fabs(l[i]);
      }
      Vec3 w = apply(rot, neg);
      for (int i = 0; i < 3; ++i) offset[i] += w[i];
      break;
    }
    case ShapeKind::Disc: disc[s.axis] += s.size[0]; break;
    case ShapeKind::Sphere: ball += s.size[0]; break;
  }
  ++terms;
  return true;
}

bool Sum::add(const Sum& s) {
  if (s.hasFrame && hasFrame && !sameRotation(rot, s.rot)) return false;
  if (s.hasFrame && !hasFrame) {
    rot = s.rot;
    hasFrame = true;
  }
  for (int i = 0; i < 3; ++i) {
    offset[i] += s.offset[i];
    lengths[i] += s.lengths[i];
    disc[i] += s.disc[i];
  }
  ball += s.ball;
  terms += s.terms;
  return true;
}

int Sum::discAxes() const { return (disc[0] > 0) + (disc[1] > 0) + (disc[2] > 0); }

std::string Sum::describe() const {
  std::string s = "block(" + num(lengths[0]) + " x " + num(lengths[1]) + " x " + num(lengths[2]) + ")";
  for (int i = 0; i < 3; ++i)
    if (disc[i] > 0) s += " + " + std::string(1, kAxis[i]) + "disc(" + num(disc[i]) + ")";
  if (ball > 0) s += " + sphere(" + num(ball) + ")";
  return s + " at (" + num(offset[0]) + ", " + num(offset[1]) + ", " + num(offset[2]) + ")";
}

Sum sumOf(const Shape& s) {
  Sum r;
  r.add(s);
  return r;
}

}  // namespace frep::minkowski
