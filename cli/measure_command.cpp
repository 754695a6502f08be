// frep measure model.hf: certified mass properties (volume, surface area, centroid, inertia
// tensors) by interval integration over an adaptive octree of the box (core:
// frep/measure/mass_properties.h; docs/measure.md). In-process on TBB threads; the numbers do not
// depend on the thread count.
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "arg_parse.h"
#include "commands.h"
#include "exit_codes.h"
#include "frep/measure/mass_properties.h"
#include "frep/master/status_line.h"

namespace frep::cli {
namespace {

std::atomic<bool> gStop{false};
extern "C" void onMeasureSignal(int) { gStop.store(true); }

// SIGINT/SIGTERM stop the refinement within the current round (the last whole round's bounds
// are valid; core's Interrupter, frep/interrupt/interrupter.h); the old handlers come back after.
struct SignalScope {
  struct sigaction oldInt {}, oldTerm {};
  SignalScope() {
    struct sigaction sa {};
    sa.sa_handler = onMeasureSignal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &oldInt);
    sigaction(SIGTERM, &sa, &oldTerm);
  }
  ~SignalScope() {
    sigaction(SIGINT, &oldInt, nullptr);
    sigaction(SIGTERM, &oldTerm, nullptr);
  }
};

std::string faceNames(unsigned faces) {
  std::string s;
  for (int b = 0; b < 6; ++b)
    if (faces & (1u << b)) s += std::string(s.empty() ? "" : ", ") + "xyz"[b / 2] + (b % 2 ? "-max" : "-min");
  return s;
}

nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }
nlohmann::json bound(const MeasureBound& b) { return {{"lower", number(b.lower)}, {"upper", number(b.upper)}}; }
nlohmann::json tensor(const std::array<MeasureBound, 9>& t) {
  nlohmann::json rows = nlohmann::json::array();
  for (int i = 0; i < 3; ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (int j = 0; j < 3; ++j) row.push_back(bound(t[size_t(i * 3 + j)]));
    rows.push_back(row);
  }
  return rows;
}

// "4.18879  [4.1710, 4.2066]  (width 0.42 %)"; relative: a width in % (volume, area), else ± half of it.
std::string boundText(const MeasureBound& b, bool relative = false) {
  char buf[160];
  if (!std::isfinite(b.lower) || !std::isfinite(b.upper)) {
    std::snprintf(buf, sizeof buf, "[%.10g, %s]", b.lower, std::isfinite(b.upper) ? formatNumber(b.upper).c_str() : "+inf");
    return buf;
  }
  if (relative && b.lower > 0)
    std::snprintf(buf, sizeof buf, "%.8g  [%.10g, %.10g]  (width %.3g %%)", b.mid(), b.lower, b.upper,
                  100.0 * b.width() / b.lower);
  else
    std::snprintf(buf, sizeof buf, "%.8g  [%.10g, %.10g]  (± %.2g)", b.mid(), b.lower, b.upper, 0.5 * b.width());
  return buf;
}

void printTensor(const char* title, const std::array<MeasureBound, 9>& t) {
  std::cout << title << "\n";
  const char* names[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j)
      std::cout << "  I_" << names[i] << names[j] << ": " << boundText(t[size_t(i * 3 + j)]) << "\n";
}

}  // namespace

int runMeasure(const MeasureRequest& request) {
  if (!(request.tolerance > 0.0 && request.tolerance < 1.0))
    throw badArgs("--tolerance: expected a relative width in (0, 1), e.g. 0.005, got " + formatNumber(request.tolerance));
  if (request.maxCells < 1000) throw badArgs("--max-cells: expected at least 1000, got " + std::to_string(request.maxCells));
  LoadedModel m = loadModel(request.model, true);
  if (m.dims != 3)
    throw badArgs("object '" + m.model.objectName + "' has " + std::to_string(m.dims) +
                  " coordinates; frep measure measures 3D solids (map a 4D object to 3D with -x X,Y,Z,T)");
  const Box box = request.bounds.empty() ? Box{} : parseBounds("-b/--bounds", request.bounds);
  const Interval ibox[3] = {{box.lo[0], box.hi[0]}, {box.lo[1], box.hi[1]}, {box.lo[2], box.hi[2]}};

  MeasureOptions options;
  options.tolerance = request.tolerance;
  options.threads = request.threads;
  options.maxBoundaryCells = uint64_t(request.maxCells);
  const bool bar = !request.json && !request.noProgress && ::isatty(2);
  gStop.store(false);
  const Interrupter stop(&gStop);
  options.interrupt = &stop;
  options.progress = [bar](const MeasureProgress& p) {
    if (bar) {
      char buf[200];
      std::snprintf(buf, sizeof buf, "measure: round %d, %llu boundary cells, volume width %.3g %%, area width %.3g %%",
                    p.round, static_cast<unsigned long long>(p.boundaryCells), 100.0 * p.volumeWidth,
                    100.0 * p.areaWidth);
      farm::StatusLine::instance().show(buf);
    }
    return true;
  };
  const auto t0 = std::chrono::steady_clock::now();
  MassProperties r;
  {
    SignalScope signals;
    try {
      r = measureMassProperties(m.field, ibox, options);
    } catch (const Interrupted&) {
      if (bar) farm::StatusLine::instance().finish();
      throw CliError(kExitInterrupted, "stopped by a signal during the first round: no bounds yet");
    }
  }
  if (bar) farm::StatusLine::instance().finish();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  if (r.cutFaces)
    spdlog::warn("the solid may reach the box's face{} {}: measured solid ∩ box (its area includes the cut faces, "
                 "cut area [{}, {}]); enlarge -b to measure the whole solid",
                 __builtin_popcount(r.cutFaces) > 1 ? "s" : "", faceNames(r.cutFaces), formatNumber(r.cutArea.lower),
                 formatNumber(r.cutArea.upper));
  if (!r.toleranceReached)
    spdlog::warn("the bounds are wider than --tolerance {} ({}): they hold, but are looser than asked",
                 formatNumber(request.tolerance), r.stopReason);
  if (!r.areaBounded)
    spdlog::warn("no upper bound on the area: some cells of the smallest size still have no gradient cone "
                 "(a cusp, a jump or a singular point of f on the surface); the lower bound holds");

  if (request.json) {
    nlohmann::json j;
    j["object"] = m.model.objectName;
    j["box"] = {{"lo", {box.lo[0], box.lo[1], box.lo[2]}}, {"hi", {box.hi[0], box.hi[1], box.hi[2]}}};
    j["tolerance"] = request.tolerance;
    j["volume"] = bound(r.volume);
    j["area"] = bound(r.area);
    j["cut_area"] = bound(r.cutArea);
    j["cut_faces"] = nlohmann::json::array();
    for (int b = 0; b < 6; ++b)
      if (r.cutFaces & (1u << b)) j["cut_faces"].push_back(std::string(1, "xyz"[b / 2]) + (b % 2 ? "-max" : "-min"));
    j["centroid"] = {bound(r.centroid[0]), bound(r.centroid[1]), bound(r.centroid[2])};
    j["inertia"] = tensor(r.inertia);
    j["inertia_about"] = "centroid";
    j["inertia_origin"] = tensor(r.inertiaOrigin);
    j["density"] = 1.0;
    j["certified"] = true;
    j["area_bounded"] = r.areaBounded;
    j["tolerance_reached"] = r.toleranceReached;
    j["stop_reason"] = r.stopReason;
    j["cells"] = {{"inside", r.insideCells}, {"boundary", r.boundaryCells}, {"first_order", r.firstOrderCells}};
    j["rounds"] = r.rounds;
    j["depth"] = r.depth;
    j["seconds"] = seconds;
    std::cout << j.dump() << std::endl;
  } else {
    std::cout << "object: " << m.model.objectName << ", box (" << formatNumber(box.lo[0]) << ", " << formatNumber(box.lo[1])
              << ", " << formatNumber(box.lo[2]) << ") to (" << formatNumber(box.hi[0]) << ", " << formatNumber(box.hi[1])
              << ", " << formatNumber(box.hi[2]) << "); certified bounds, density 1\n";
    std::cout << "volume:   " << boundText(r.volume, true) << "\n";
    std::cout << "area:     " << boundText(r.area, true) << (r.cutFaces ? "  (cut faces included)" : "") << "\n";
    const char* axes = "xyz";
    for (int i = 0; i < 3; ++i)
      std::cout << (i ? "          " : "centroid: ") << axes[i] << " " << boundText(r.centroid[size_t(i)]) << "\n";
    printTensor("inertia about the centroid (I_ii = integral of |y|^2 - y_i^2, I_ij = -integral of y_i y_j):", r.inertia);
    printTensor("inertia about the origin:", r.inertiaOrigin);
    std::cout << "cells: " << r.insideCells << " inside, " << r.boundaryCells << " on the boundary (" << r.firstOrderCells
              << " with a gradient enclosure), " << r.rounds << " rounds, depth " << r.depth << "; " << r.stopReason << "; "
              << formatNumber(std::round(seconds * 1000) / 1000) << " s\n";
  }
  if (r.stopped) throw CliError(kExitInterrupted, "stopped by a signal: the bounds above hold but are wider than --tolerance");
  return kExitOk;
}

}  // namespace frep::cli
