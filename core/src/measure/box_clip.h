// Internal to mass_properties.cpp: exact geometry of an axis-aligned box cut by planes.
// Coordinates are relative to the box centre; the box is [-h, h] on each axis, and a half-space
// is {y : c + g . y >= 0}.
//   * volume and moments up to degree 2 of box ∩ half-space (the box's faces clipped by the
//     plane, Sutherland-Hodgman, then signed tetrahedra from a point of the plane: the cut face
//     contributes nothing and need not be built);
//   * the area of the projection of box ∩ half-spaces onto a plane (convex hull of the
//     projected vertices) and of the intersection of two such projections;
//   * the area of one face of the box cut by a half-space.
#pragma once

#include <array>

namespace frep::measure_detail {

struct HalfSpace {
  double c = 0.0;
  double g[3] = {0.0, 0.0, 0.0};
  double at(const double* y) const { return c + g[0] * y[0] + g[1] * y[1] + g[2] * y[2]; }
};

// Integrals over a region R of 1, y_i and y_i y_j (order xx, yy, zz, xy, yz, zx).
struct Moments {
  double v = 0.0;
  double m1[3] = {0.0, 0.0, 0.0};
  double m2[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
};

// The whole box [-h, h]^3.
Moments boxMoments(const double h[3]);
// box ∩ {c + g . y >= 0}.
Moments clippedMoments(const double h[3], const HalfSpace& s);
// Volume only (the same region).
double clippedVolume(const double h[3], const HalfSpace& s);

// Area of the projection along the unit vector n of box ∩ (every half-space in s[0..k)).
double projectedArea(const double h[3], const HalfSpace* s, int k, const double n[3]);
// Area of proj_n(box ∩ a) ∩ proj_n(box ∩ b).
double projectedOverlap(const double h[3], const HalfSpace& a, const HalfSpace& b, const double n[3]);

// Area of face (axis, side: 0 the -h side, 1 the +h side) of the box within {c + g . y >= 0}.
double faceArea(const double h[3], int axis, int side, const HalfSpace& s);
// The same for the rectangle u x v of that face's plane (u along axis + 1, v along axis + 2,
// mod 3, in the box's coordinates).
double rectArea(const double h[3], int axis, int side, const double u[2], const double v[2], const HalfSpace& s);

}  // namespace frep::measure_detail
