// Volume splines in the language (Pasko-Survey: deformation by algebraic sums, reconstruction
// from scattered points): frVolumeSpline from arrays, frVolumeSplineFile from a point file.
// The fit runs here, once per compile (frep/primitives/volume_spline.h has the method).
#include <algorithm>
#include <cmath>
#include <string>

#include "frep/primitives/volume_spline.h"
#include "library/hf_util.h"
#include "library/point_cloud.h"

namespace frep::lang {
namespace {

using hf::argName;
using hf::arrayArg;
using hf::arrayAtLeast;
using hf::scalarArg;

Expr splineAt(const std::vector<Expr>& x, const std::vector<Point3>& c, const std::vector<double>& v) {
  return fieldCall(VolumeSpline::fit(c, v), x[0], x[1], x[2]);
}

double constant(const char* fn, std::vector<Arg>& a, int i, const Expr& e, size_t k) {
  if (!e.isConst())
    throw LibraryError(std::string(fn) + ": element " + std::to_string(k + 1) + " of " + argName(a, i, "the array") +
                           " must be known at compile time (the spline is fitted when the model compiles)",
                       i);
  return e.constValue();
}

// frVolumeSpline(x, c, v): the volume spline through v[i] at the centres c[3i-2..3i].
Expr frVolumeSpline(std::vector<Arg>& a) {
  const char* fn = "frVolumeSpline";
  std::vector<Expr>& x = arrayAtLeast(fn, a, 0, 3, "x");
  std::vector<Expr>& c = arrayArg(fn, a, 1);
  std::vector<Expr>& v = arrayArg(fn, a, 2);
  if (c.size() != 3 * v.size())
    throw LibraryError(std::string(fn) + ": " + argName(a, 1, "c") + " has " + std::to_string(c.size()) +
                           " elements, expected 3 per value of " + argName(a, 2, "v") + " (" +
                           std::to_string(3 * v.size()) + ")",
                       1);
  std::vector<Point3> centres(v.size());
  std::vector<double> values(v.size());
  for (size_t i = 0; i < v.size(); ++i) {
    for (size_t k = 0; k < 3; ++k) centres[i][k] = constant(fn, a, 1, c[3 * i + k], 3 * i + k);
    values[i] = constant(fn, a, 2, v[i], i);
  }
  try {
    return splineAt(x, centres, values);
  } catch (const std::invalid_argument& e) {
    throw LibraryError(std::string(fn) + ": " + e.what());
  }
}

// frVolumeSplineFile(x, "file", eps): points with values are interpolated as they are; surface
// points with normals get off-surface points at +-eps along the normal (eps <= 0: 1% of the
// points' bounding-box diagonal).
Expr frVolumeSplineFile(std::vector<Arg>& a) {
  const char* fn = "frVolumeSplineFile";
  std::vector<Expr>& x = arrayAtLeast(fn, a, 0, 3, "x");
  const Expr& epsArg = scalarArg(fn, a, 2);
  if (!epsArg.isConst())
    throw LibraryError(std::string(fn) + ": the offset eps must be known at compile time", 2);
  PointCloud pc;
  try {
    pc = parsePointCloud(*a[1].file, a[1].name);
  } catch (const std::runtime_error& e) {
    throw LibraryError(std::string(fn) + ": " + e.what(), 1);
  }
  try {
    if (!pc.values.empty()) return splineAt(x, pc.points, pc.values);
    double eps = epsArg.constValue();
    if (!(eps > 0.0)) {
      double diag2 = 0.0;
      for (int k = 0; k < 3; ++k) {
        double lo = pc.points[0][size_t(k)], hi = lo;
        for (const auto& p : pc.points) lo = std::min(lo, p[size_t(k)]), hi = std::max(hi, p[size_t(k)]);
        diag2 += (hi - lo) * (hi - lo);
      }
      eps = 0.01 * std::sqrt(diag2);
    }
    std::vector<Point3> centres;
    std::vector<double> values;
    offSurfacePoints(pc.points, pc.normals, eps, centres, values);
    return splineAt(x, centres, values);
  } catch (const std::invalid_argument& e) {
    throw LibraryError(std::string(fn) + ": " + a[1].name + ": " + e.what(), 1);
  }
}

const bool registered = registerAll({
    {"frVolumeSpline", "AAA",
     "volume spline through v[i] at centres c[3i-2..3i]: sum l_i |x - c_i|^3 + linear part (Pasko-Survey)",
     frVolumeSpline},
    {"frVolumeSplineFile", "AFS",
     "volume spline through a point file (x y z value, x y z nx ny nz, PLY); normals: off-surface points at +-eps",
     frVolumeSplineFile},
});

}  // namespace
}  // namespace frep::lang
