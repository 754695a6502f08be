// The simplifier's geometry (mesh_simplify.cpp and the simplifier_*.cpp files): 3-vectors
// (frep/geometry/vec3.h), the quadric error metric, point-triangle distance and triangle quality.
#pragma once

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "frep/geometry/vec3.h"

namespace frep::simplify_detail {

using V3 = Vec3;
using Tri = std::array<uint32_t, 3>;

using vec3::add;
using vec3::cross;
using vec3::dot;
using vec3::norm;
using vec3::scale;
using vec3::sub;

// Sum of squared distances to planes n.x = n.p (Garland & Heckbert's quadric), here the model's
// tangent planes at surface points.
struct Quadric {
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  double c = 0, weight = 0;
  void addPlane(const V3& n, const V3& p) {
    Eigen::Vector3d nn(n[0], n[1], n[2]);
    double d = -dot(n, p);
    A += nn * nn.transpose();
    b += d * nn;
    c += d * d;
    weight += 1;
  }
  // The 11 numbers SimplifyCarry::Vertex holds (A: xx xy xz yy yz zz, b, c, weight), and back.
  std::array<double, 11> packed() const {
    return {A(0, 0), A(0, 1), A(0, 2), A(1, 1), A(1, 2), A(2, 2), b[0], b[1], b[2], c, weight};
  }
  static Quadric unpacked(const std::array<double, 11>& d) {
    Quadric q;
    q.A << d[0], d[1], d[2], d[1], d[3], d[4], d[2], d[4], d[5];
    q.b = Eigen::Vector3d(d[6], d[7], d[8]);
    q.c = d[9];
    q.weight = d[10];
    return q;
  }
  Quadric& operator+=(const Quadric& o) {
    A += o.A, b += o.b, c += o.c, weight += o.weight;
    return *this;
  }
  double operator()(const V3& x) const {
    Eigen::Vector3d v(x[0], x[1], x[2]);
    return std::max(0.0, v.dot(A * v) + 2 * b.dot(v) + c);
  }
  // The least-squares point nearest to `ref`. Directions with less support than half a plane
  // (eigenvalue < 0.5; each unit-normal plane adds 1 to the trace) stay at ref: nearly parallel
  // planes do not define a crease. An absolute threshold, not one relative to the largest
  // eigenvalue: a vertex that has absorbed a whole face holds thousands of that face's planes
  // and still only a few dozen of the face across the crease.
  V3 minimiser(const V3& ref) const {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
    es.computeDirect(A);  // closed form for 3x3: several times faster than the iterative solver
    Eigen::Vector3d r(ref[0], ref[1], ref[2]), g = -(A * r + b), x = r;
    double top = es.eigenvalues().maxCoeff();
    for (int i = 0; i < 3; ++i) {
      double l = es.eigenvalues()[i];
      if (l > 0.5 && l > 1e-9 * top) {
        x += es.eigenvectors().col(i) * (es.eigenvectors().col(i).dot(g) / l);
      }
    }
    return {x[0], x[1], x[2]};
  }
};

// Closest distance from p to triangle abc (Ericson, Real-Time Collision Detection, 5.1.5).
inline double pointTriangleDistance(const V3& p, const V3& a, const V3& b, const V3& c) {
  V3 ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
  double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return norm(ap);
  V3 bp = sub(p, b);
  double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return norm(bp);
  double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return norm(sub(p, add(a, scale(ab, d1 / (d1 - d3)))));
  V3 cp = sub(p, c);
  double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return norm(cp);
  double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return norm(sub(p, add(a, scale(ac, d2 / (d2 - d6)))));
  double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return norm(sub(p, add(b, scale(sub(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6))))));
  double denom = 1 / (va + vb + vc);
  return norm(sub(p, add(a, add(scale(ab, vb * denom), scale(ac, vc * denom)))));
}

inline double quality(const V3& a, const V3& b, const V3& c) {
  double s = dot(sub(b, a), sub(b, a)) + dot(sub(c, b), sub(c, b)) + dot(sub(a, c), sub(a, c));
  return s > 0 ? 2 * std::sqrt(3.0) * norm(cross(sub(b, a), sub(c, a))) / s : 0;
}

}  // namespace frep::simplify_detail
