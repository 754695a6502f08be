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
#include "geometric_types.h"
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

constexpr int kGutter = 2;  // pixels between the cells of a V/W grid

}  // namespace

// Geometric types (geometric_types.h): T writes numbered slices, V/W a grid of slices, G the
// heat map of the union (max) of the sections, C the union's inside coloured by the spectral
// colour of the section each pixel belongs to (the largest section value there).
int runSlice(const SliceRequest& request) {
  if (!std::isfinite(request.at)) throw badArgs("--at: expected a finite number");
  if (request.region.out.empty()) throw badArgs("-O/--out: the output PNG path is required");
  Box box = request.region.bounds.empty() ? Box{} : parseBounds("-b/--bounds", request.region.bounds);
  Resolution res = resolutionFrom(request.region.res, request.region.cells, 512);
  const GeometricTypes g = parseGeometricTypes(request.model.mapping, request.geometric, true);
  const std::vector<double> frameValues = g.t.empty() ? std::vector<double>{0} : g.t;
  const std::vector<double> columns = g.v.empty() ? std::vector<double>{0} : g.v, rows = g.w.empty() ? std::vector<double>{0} : g.w;
  const std::vector<double> sections = g.sections.empty() ? std::vector<double>{0} : g.sections;
  auto mappingOf = [&](double t, double v, double w, double section) {
    return g.items.empty() ? request.model.mapping : g.mapping(t, v, w, section);
  };
  ModelRequest firstRequest = request.model;
  firstRequest.mapping = mappingOf(frameValues[0], columns[0], rows[0], sections[0]);
  LoadedModel m = loadModel(firstRequest, true);
  Plane plane = choosePlane(request, m.dims);

  Box planeBox;  // the image's two axes in slots 0 and 1
  planeBox.lo = {box.lo[size_t(plane.u)], box.lo[size_t(plane.v)], 0.0};
  planeBox.hi = {box.hi[size_t(plane.u)], box.hi[size_t(plane.v)], 0.0};
  if (res.res == 0) res.cells = {res.cells[size_t(plane.u)], res.cells[size_t(plane.v)], 1};
  GridSpec grid = makeGrid(planeBox, 2, res);
  const int width = grid.dims[0], height = grid.dims[1];
  const int nv = int(columns.size()), nw = int(rows.size());
  const int W = nv * width + (nv - 1) * kGutter, H = nw * height + (nw - 1) * kGutter;
  if (W > kMaxSide || H > kMaxSide)
    throw badArgs("--res/-g: the image would be " + std::to_string(W) + "x" + std::to_string(H) +
                  " pixels; the limit is " + std::to_string(kMaxSide) + " per side");

  const uint32_t vars = uint32_t(std::max(m.dims, plane.normal < 0 ? 2 : 3));
  PlaneLattice lattice;
  lattice.u = uint32_t(plane.u), lattice.v = uint32_t(plane.v);
  lattice.normal = plane.normal, lattice.at = request.at;
  lattice.origin[0] = grid.origin[0], lattice.origin[1] = grid.origin[1];
  lattice.step = grid.voxel, lattice.width = width, lattice.height = height;
  PlaneOptions options;
  options.signOnly = request.mask || g.colourSections;
  // --mask reads signs only, so float with the certified double fallback gives the same image
  // (also for a union of sections: the max of values of the right signs has the right sign); the
  // section colours compare values across sections, so they stay in double.
  options.floatSigns = request.mask && !g.colourSections;
  PlaneStats stats;
  double evalMs = 0, lo = INFINITY, hi = -INFINITY;
  size_t nans = 0, instrs = 0;
  const int frames = int(frameValues.size());
  for (int k = 0; k < frames; ++k) {
    const std::string path = framePath(request.region.out, k, frames);
    io::AtomicOutput out("-O/--out", path);
    io::RgbImage img(W, H);
    std::fill(img.rgb.begin(), img.rgb.end(), uint8_t(128));  // the gutters
    for (int cw = 0; cw < nw; ++cw)
      for (int cv = 0; cv < nv; ++cv) {
        std::vector<double> values;  // the union of the sections
        std::vector<size_t> owner;   // C: the section with the largest value at each pixel
        for (size_t s = 0; s < sections.size(); ++s) {
          ModelRequest mr = request.model;
          mr.mapping = mappingOf(frameValues[size_t(k)], columns[size_t(cv)], rows[size_t(cw)], sections[s]);
          TapePtr tape = Tape::compile(loadModel(mr, true).field, vars);
          instrs = tape->size();
          PlaneStats one;
          const auto t0 = std::chrono::steady_clock::now();
          std::vector<double> section = evaluatePlane(tape, lattice, options, &one);
          evalMs += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
          stats.pointEvals += one.pointEvals, stats.tapeInstrs += one.tapeInstrs, stats.tapeBatches += one.tapeBatches;
          if (s == 0) {
            values = std::move(section);
            owner.assign(values.size(), 0);
            continue;
          }
          for (size_t i = 0; i < values.size(); ++i)
            if (section[i] > values[i] || (std::isnan(values[i]) && !std::isnan(section[i]))) values[i] = section[i], owner[i] = s;
        }
        io::RgbImage cell = request.mask ? io::renderMask(values, width, height) : io::renderHeatmap(values, width, height);
        if (g.colourSections)  // inside: the section's colour; outside: white
          for (size_t i = 0; i < values.size(); ++i) {
            const auto c = spectralColour(sections.size() > 1 ? double(owner[i]) / double(sections.size() - 1) : 0.0);
            for (size_t ch = 0; ch < 3; ++ch) cell.rgb[i * 3 + ch] = values[i] >= 0 ? uint8_t(std::lround(c[ch] * 255)) : 255;
          }
        for (int y = 0; y < height; ++y)
          std::copy(&cell.rgb[size_t(y) * size_t(width) * 3], &cell.rgb[size_t(y + 1) * size_t(width) * 3],
                    &img.rgb[(size_t(cw * (height + kGutter) + y) * size_t(W) + size_t(cv * (width + kGutter))) * 3]);
        for (double f : values) {
          if (std::isnan(f)) { ++nans; continue; }
          if (std::isinf(f)) continue;  // --mask: a tile decided the sign, the pixel was not evaluated
          lo = std::min(lo, f), hi = std::max(hi, f);
        }
      }
    io::writePng(out.tempPath(), img);
    out.commit();
  }
  const size_t pixels = size_t(width) * size_t(height) * size_t(nv * nw) * size_t(frames) * sections.size();
  std::cout << "wrote " << (frames > 1 ? framePath(request.region.out, 0, frames) + " .. " + framePath(request.region.out, frames - 1, frames) : request.region.out)
            << ": " << W << "x" << H << " pixels";
  if (frames > 1) std::cout << ", " << frames << " frames";
  if (nv * nw > 1) std::cout << ", " << nv << "x" << nw << " cells";
  if (g.sections.size() > 0) std::cout << ", union of " << g.sections.size() << " sections";
  if (plane.normal >= 0) std::cout << " at " << char('x' + plane.normal) << " = " << formatNumber(request.at);
  std::cout << ", pixel " << formatNumber(grid.voxel) << ", f in [" << formatNumber(lo) << ", "
            << formatNumber(hi) << "]";
  if (nans) std::cout << ", " << nans << " NaN pixels (grey)";
  std::cout << "; evaluated " << stats.pointEvals << " of " << pixels << " pixels ("
            << formatNumber(stats.tapeBatches ? double(stats.tapeInstrs) / double(stats.tapeBatches) : 0.0)
            << " of " << instrs << " instructions on average) in " << formatNumber(std::round(evalMs * 10) / 10)
            << " ms";
  std::cout << "\n";
  return kExitOk;
}

}  // namespace frep::cli
