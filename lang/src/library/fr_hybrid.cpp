// Boundary representations as operands (Choporov-Hybrid): a region bounded by a polygon, a
// closed composite Bezier curve, closed Bezier patches, a triangle mesh file or a sampled .vdb
// volume becomes the signed distance f = sign * dist (eq. 1-3), positive inside. The geometry is
// built once at compile time into a field node (Op::Field with a DistanceField object, core
// geometry/distance_fields.h); files go through the loader the program installs (library.h,
// io/geometry_files.h), which caches them by content hash.
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include "frep/geometry/distance_fields.h"
#include "library/hf_util.h"

namespace frep::lang {
namespace {

using hf::arrayArg;
using hf::arrayAtLeast;
using hf::argName;

// The numbers of a control or vertex array: every element must be known at compile time.
std::vector<double> constants(const char* fn, std::vector<Arg>& a, int i, size_t multiple, const char* what) {
  std::vector<Expr>& arr = arrayArg(fn, a, i);
  if (arr.empty() || arr.size() % multiple != 0)
    throw LibraryError(std::string(fn) + ": array " + argName(a, i, what) + " must hold " +
                           std::to_string(multiple) + " numbers per point (got " + std::to_string(arr.size()) + ")",
                       i);
  std::vector<double> v(arr.size());
  for (size_t k = 0; k < arr.size(); ++k) {
    if (!arr[k].isConst())
      throw LibraryError(std::string(fn) + ": element " + std::to_string(k + 1) + " of " + argName(a, i, what) +
                             " must be a constant known at compile time (the geometry is built once)",
                         i);
    v[k] = arr[k].constValue();
  }
  return v;
}

// Optional trailing scalar i (a compile-time constant), else `fallback`.
double optionalConst(const char* fn, std::vector<Arg>& a, size_t i, double fallback, const char* what) {
  if (i >= a.size()) return fallback;
  if (a[i].isArray || a[i].isText || a[i].file || !a[i].value.isConst())
    throw LibraryError(std::string(fn) + ": " + what + " must be a constant number", int(i));
  return a[i].value.constValue();
}

void checkCount(const char* fn, std::vector<Arg>& a, size_t lo, size_t hi, const char* usage) {
  if (a.size() < lo || a.size() > hi) throw LibraryError(std::string(fn) + " takes " + usage);
}

int wholeNumber(const char* fn, double v, int lo, int hi, const char* what, int arg) {
  if (!(v >= lo && v <= hi) || v != std::floor(v))
    throw LibraryError(std::string(fn) + ": " + what + " must be a whole number from " + std::to_string(lo) + " to " +
                           std::to_string(hi),
                       arg);
  return int(v);
}

// Diagonal of the points' bounding box (default chord deviations are relative to it).
double diagonal(const std::vector<double>& v, int dims) {
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY}, s = 0;
  for (size_t k = 0; k < v.size(); ++k) lo[k % dims] = std::min(lo[k % dims], v[k]), hi[k % dims] = std::max(hi[k % dims], v[k]);
  for (int k = 0; k < dims; ++k) s += (hi[k] - lo[k]) * (hi[k] - lo[k]);
  return std::sqrt(s);
}

Expr planar(const std::shared_ptr<const FieldFunction>& f, std::vector<Expr>& x) { return fieldCall(f, x[0], x[1], Expr(0.0)); }
Expr spatial(const std::shared_ptr<const FieldFunction>& f, std::vector<Expr>& x) { return fieldCall(f, x[0], x[1], x[2]); }

// frPolygon(x, v): v = [x1, y1, x2, y2, ...], the closed polygon through the vertices.
Expr frPolygon(std::vector<Arg>& a) {
  const char* fn = "frPolygon";
  std::vector<Expr>& x = arrayAtLeast(fn, a, 0, 2, "x");
  std::vector<double> v = constants(fn, a, 1, 2, "v");
  try {
    return planar(std::make_shared<PolygonField>(std::move(v), "polygon " + argName(a, 1, "v")), x);
  } catch (const std::invalid_argument& e) {
    throw LibraryError(std::string(fn) + ": " + e.what(), 1);
  }
}

// frBezierCurve(x, c, degree [, n [, delta]]): a closed composite curve of arcs of `degree`.
Expr frBezierCurve(std::vector<Arg>& a) {
  const char* fn = "frBezierCurve";
  checkCount(fn, a, 3, 5, "3 to 5 arguments (x, control points, degree [, n [, delta]])");
  std::vector<Expr>& x = arrayAtLeast(fn, a, 0, 2, "x");
  std::vector<double> c = constants(fn, a, 1, 2, "c");
  const int degree = wholeNumber(fn, optionalConst(fn, a, 2, 0, "the degree"), 1, 63, "the degree", 2);
  const int n = wholeNumber(fn, optionalConst(fn, a, 3, 4 * degree + 1, "n"), 2, 100000, "n", 3);
  const double delta = optionalConst(fn, a, 4, diagonal(c, 2) > 0 ? 1e-3 * diagonal(c, 2) : 1.0, "delta");
  try {
    std::vector<double> poly = tessellateBezierLoop(c, degree, n, delta);
    return planar(std::make_shared<PolygonField>(std::move(poly), "Bezier curve " + argName(a, 1, "c")), x);
  } catch (const std::invalid_argument& e) {
    throw LibraryError(std::string(fn) + ": " + e.what(), 1);
  }
}

// frBezierSurface(x, c, du, dv [, n [, delta]]): closed surface of tensor-product patches.
Expr frBezierSurface(std::vector<Arg>& a) {
  const char* fn = "frBezierSurface";
  checkCount(fn, a, 4, 6, "4 to 6 arguments (x, control points, du, dv [, n [, delta]])");
  std::vector<Expr>& x = arrayAtLeast(fn, a, 0, 3, "x");
  std::vector<double> c = constants(fn, a, 1, 3, "c");
  const int du = wholeNumber(fn, optionalConst(fn, a, 2, 0, "du"), 1, 63, "du", 2);
  const int dv = wholeNumber(fn, optionalConst(fn, a, 3, 0, "dv"), 1, 63, "dv", 3);
  const int n = wholeNumber(fn, optionalConst(fn, a, 4, std::max(du, dv) + 1, "n"), 1, 512, "n", 4);
  const double delta = optionalConst(fn, a, 5, diagonal(c, 3) > 0 ? 1e-3 * diagonal(c, 3) : 1.0, "delta");
  try {
    TriangleMesh m = tessellateBezierPatches(c, du, dv, n, delta);
    auto f = std::make_shared<MeshField>(std::move(m.xyz), std::move(m.tris), "Bezier patches " + argName(a, 1, "c"));
    if (!f->check().closed())
      throw LibraryError(std::string(fn) + ": the patches do not form a closed surface (" +
                             std::to_string(f->check().openEdges) + " open edges in the tessellation): neighbouring "
                             "patches must share their boundary control points exactly",
                         1);
    return spatial(f, x);
  } catch (const std::invalid_argument& e) {
    throw LibraryError(std::string(fn) + ": " + e.what(), 1);
  }
}

// frMesh(x, "part.stl"): the signed distance to a triangle mesh file (.stl, .obj, .ply).
Expr frMesh(std::vector<Arg>& a) {
  const char* fn = "frMesh";
  std::vector<Expr>& x = arrayAtLeast(fn, a, 0, 3, "x");
  LoadedFileField l = loadFileForCall(fn, {a[1].name, a[1].file, "mesh", ""}, 1);
  return spatial(l.field, x);
}

// frVolume(x, "scan.vdb" [, "grid"]): a sampled volume, interpolated trilinearly.
Expr frVolume(std::vector<Arg>& a) {
  const char* fn = "frVolume";
  checkCount(fn, a, 2, 3, "2 or 3 arguments (x, \"file.vdb\" [, \"grid name\"])");
  std::vector<Expr>& x = arrayAtLeast(fn, a, 0, 3, "x");
  if (!a[1].file) throw LibraryError(std::string(fn) + ": argument 2 must be a file name in double quotes", 1);
  if (a.size() == 3 && !a[2].isText) throw LibraryError(std::string(fn) + ": argument 3 must be a grid name in double quotes", 2);
  LoadedFileField l = loadFileForCall(fn, {a[1].name, a[1].file, "volume", a.size() == 3 ? a[2].name : ""},
                                      a.size() == 3 ? 2 : 1);
  return spatial(l.field, x);
}

const bool registered = registerAll({
    {"frPolygon", "AA", "signed distance to the closed polygon v = [x1, y1, ...] (positive inside)", frPolygon},
    {"frBezierCurve", "*",
     "signed distance to a closed composite Bezier curve (x, c, degree [, n, delta]), tessellated to chord deviation delta",
     frBezierCurve},
    {"frBezierSurface", "*",
     "signed distance to a closed surface of Bezier patches (x, c, du, dv [, n, delta]), tessellated to delta",
     frBezierSurface},
    {"frMesh", "AF", "signed distance to a closed triangle mesh file (.stl, .obj, .ply), path relative to the model", frMesh},
    {"frVolume", "*", "a .vdb volume (x, \"file\" [, \"grid\"]) in F-rep sign, trilinear", frVolume},
});

}  // namespace
}  // namespace frep::lang
