// frep slice: f over a plane, as a heat map PNG with the zero contour.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>

#include "arg_parse.h"
#include "frep/io/atomic_output.h"
#include "commands.h"
#include "exit_codes.h"
#include "frep/evaluators/eval.h"
#include "frep/expressions/tape.h"
#include "frep/sampling/plane.h"
#include "frep/io/heatmap.h"
#include "sampling_grid.h"

namespace frep::cli {
namespace {

constexpr int kMaxSide = 16384;  // pixels per side; keeps the image in memory

struct Plane {
  int u = 0, v = 1;   // model axes along the image's columns and rows (rows go up)
  int normal = -1;    // axis held at `at`; -1 for 2D objects
};

Plane choosePlane(const SliceRequest& r, int dims) {
  if (dims <= 2) {
    if (!r.axis.empty()) spdlog::warn("--axis: ignored, the object is two-dimensional");
    return {};
  }
  int normal = r.axis.empty() ? 2 : parseAxis("--axis", r.axis);
  Plane p;
  p.normal = normal;
  p.u = normal == 0 ? 1 : 0;
  p.v = normal == 2 ? 1 : 2;
  return p;
}

}  // namespace

int runSlice(const SliceRequest& request) {
  if (!std::isfinite(request.at)) throw badArgs("--at: expected a finite number");
  if (request.region.out.empty()) throw badArgs("-O/--out: the output PNG path is required");
  Box box = request.region.bounds.empty() ? Box{} : parseBounds("-b/--bounds", request.region.bounds);
  Resolution res = resolutionFrom(request.region.res, request.region.cells, 512);
  LoadedModel m = loadModel(request.model, true);
  Plane plane = choosePlane(request, m.dims);

  Box planeBox;  // the image's two axes in slots 0 and 1
  planeBox.lo = {box.lo[size_t(plane.u)], box.lo[size_t(plane.v)], 0.0};
  planeBox.hi = {box.hi[size_t(plane.u)], box.hi[size_t(plane.v)], 0.0};
  if (res.res == 0) res.cells = {res.cells[size_t(plane.u)], res.cells[size_t(plane.v)], 1};
  GridSpec grid = makeGrid(planeBox, 2, res);
  const int width = grid.dims[0], height = grid.dims[1];
  if (width > kMaxSide || height > kMaxSide)
    throw badArgs("--res/-g: the image would be " + std::to_string(width) + "x" + std::to_string(height) +
                  " pixels; the limit is " + std::to_string(kMaxSide) + " per side");

  io::AtomicOutput out("-O/--out", request.region.out);
  const uint32_t vars = uint32_t(std::max(m.dims, plane.normal < 0 ? 2 : 3));
  TapePtr tape = Tape::compile(m.field, vars);
  PlaneLattice lattice;
  lattice.u = uint32_t(plane.u), lattice.v = uint32_t(plane.v);
  lattice.normal = plane.normal, lattice.at = request.at;
  lattice.origin[0] = grid.origin[0], lattice.origin[1] = grid.origin[1];
  lattice.step = grid.voxel, lattice.width = width, lattice.height = height;
  PlaneOptions options;
  options.signOnly = request.mask;
  PlaneStats stats;
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<double> values = evaluatePlane(tape, lattice, options, &stats);
  const double evalMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();

  io::writePng(out.tempPath(), request.mask ? io::renderMask(values, width, height) : io::renderHeatmap(values, width, height));
  out.commit();
  double lo = INFINITY, hi = -INFINITY;
  size_t nans = 0;
  for (double f : values) {
    if (std::isnan(f)) { ++nans; continue; }
    if (std::isinf(f)) continue;  // --mask: a tile decided the sign, the pixel was not evaluated
    lo = std::min(lo, f), hi = std::max(hi, f);
  }
  std::cout << "wrote " << request.region.out << ": " << width << "x" << height << " pixels";
  if (plane.normal >= 0) std::cout << " at " << char('x' + plane.normal) << " = " << formatNumber(request.at);
  std::cout << ", pixel " << formatNumber(grid.voxel) << ", f in [" << formatNumber(lo) << ", "
            << formatNumber(hi) << "]";
  if (nans) std::cout << ", " << nans << " NaN pixels (grey)";
  std::cout << "; evaluated " << stats.pointEvals << " of " << values.size() << " pixels ("
            << formatNumber(stats.tapeBatches ? double(stats.tapeInstrs) / double(stats.tapeBatches) : 0.0)
            << " of " << tape->size() << " instructions on average) in " << formatNumber(std::round(evalMs * 10) / 10)
            << " ms";
  std::cout << "\n";
  return kExitOk;
}

}  // namespace frep::cli
