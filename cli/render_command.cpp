// frep render: a shaded picture of the solid by certified interval ray casting (frep/render).
// The view fits the solid: its box is found by interval subdivision inside -b, then the camera
// (orbit or look-at) is placed and sized so that the box fills the image.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <stdexcept>

#include "arg_parse.h"
#include "commands.h"
#include "exit_codes.h"
#include "frep/io/atomic_output.h"
#include "frep/io/png_writer.h"
#include "frep/render/raycast.h"
#include "frep/render/shade.h"

namespace frep::cli {
namespace {

constexpr int kMaxSide = 16384;
constexpr int kBoundsLevels = 6;  // octree depth of the solid's box search
constexpr int kMaxFrames = 100000;

void parseSize(const std::string& text, int& w, int& h) {
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X') || w < 1 || h < 1 ||
      w > kMaxSide || h > kMaxSide)
    throw badArgs("--size: expected WxH with 1..." + std::to_string(kMaxSide) + " pixels per side, got '" + text + "'");
}

std::array<uint8_t, 3> parseRgb(const std::string& field, const std::string& text) {
  std::array<uint8_t, 3> c{};
  if (text.size() == 7 && text[0] == '#') {
    unsigned v = 0;
    char extra = 0;
    if (std::sscanf(text.c_str() + 1, "%6x%c", &v, &extra) == 1) return {uint8_t(v >> 16), uint8_t(v >> 8), uint8_t(v)};
  }
  std::vector<double> n = parseNumbers(field, text, "3 (0-255 each) or #rrggbb");
  if (n.size() != 3) throw badArgs(field + ": expected r,g,b (0-255 each) or #rrggbb, got '" + text + "'");
  for (size_t i = 0; i < 3; ++i) {
    if (n[i] < 0 || n[i] > 255) throw badArgs(field + ": each of r,g,b must be in 0..255, got '" + text + "'");
    c[i] = uint8_t(std::lround(n[i]));
  }
  return c;
}

Vec3 parseVec(const std::string& field, const std::string& text) {
  std::vector<double> n = parseNumbers(field, text, "3");
  if (n.size() != 3) throw badArgs(field + ": expected x,y,z, got '" + text + "'");
  return {n[0], n[1], n[2]};
}

// The frame's file name: NAME.png -> NAME_0007.png (single pictures keep the name).
std::string framePath(const std::string& out, int frame, int frames) {
  if (frames <= 1) return out;
  const size_t dot = out.find_last_of('.'), slash = out.find_last_of('/');
  const bool hasExt = dot != std::string::npos && (slash == std::string::npos || dot > slash);
  char num[16];
  std::snprintf(num, sizeof num, "_%04d", frame);
  return hasExt ? out.substr(0, dot) + num + out.substr(dot) : out + num;
}

// f restricted to the box (the region drawn, as hfp draws only inside -b).
Expr clipToBox(const Expr& f, const Box& box) {
  Expr e = f;
  for (uint32_t i = 0; i < 3; ++i) {
    e = min(e, Expr::x(i) - box.lo[i]);
    e = min(e, box.hi[i] - Expr::x(i));
  }
  return e;
}

struct View {
  Camera camera;
  double nearDepth = 0, farDepth = 1;
};

// Places the camera and fits the solid's box `lo..hi` into the image; the depth range covers
// the box. Turntables fit the box's bounding sphere so that the scale stays put across frames.
View makeView(const RenderRequest& r, const Vec3& lo, const Vec3& hi, double azimuth, int w, int h, bool sphereFit) {
  const Vec3 centre{0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])};
  double radius = 0;
  for (int i = 0; i < 3; ++i) radius += 0.25 * (hi[size_t(i)] - lo[size_t(i)]) * (hi[size_t(i)] - lo[size_t(i)]);
  radius = std::max(std::sqrt(radius), 1e-9);
  const double aspect = double(w) / double(h);
  const double tanHalf = std::tan(0.5 * r.fov * M_PI / 180);
  const Vec3 target = r.target.empty() ? centre : parseVec("--target", r.target);
  const Vec3 up = r.up.empty() ? Vec3{0, 0, 1} : parseVec("--up", r.up);
  const double distance = r.distance > 0 ? r.distance : r.perspective
      ? 1.05 * radius / std::sin(std::atan(tanHalf / std::max(1.0, aspect)))  // the sphere fills the narrower side
      : 3 * radius;
  View v;
  try {
    if (!r.eye.empty())
      v.camera = lookAtCamera(parseVec("--eye", r.eye), target, up, r.perspective, 1.0);
    else
      v.camera = orbitCamera(target, azimuth, r.elevation, distance, r.perspective, 1.0);
  } catch (const std::invalid_argument& e) {
    throw badArgs(std::string(r.eye.empty() ? "--azimuth/--elevation: " : "--eye/--target: ") + e.what());
  }
  Camera& cam = v.camera;
  double nearD = INFINITY, farD = -INFINITY, extent = 0;  // extent: half-size needed on the image plane
  for (int k = 0; k < 8; ++k) {
    Vec3 p{k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]}, rel;
    for (int i = 0; i < 3; ++i) rel[size_t(i)] = p[size_t(i)] - cam.eye[size_t(i)];
    const double d = rel[0] * cam.forward[0] + rel[1] * cam.forward[1] + rel[2] * cam.forward[2];
    double pu = rel[0] * cam.right[0] + rel[1] * cam.right[1] + rel[2] * cam.right[2];
    double pv = rel[0] * cam.up[0] + rel[1] * cam.up[1] + rel[2] * cam.up[2];
    if (!r.perspective) {  // around the target's projection
      const Vec3 t{target[0] - cam.eye[0], target[1] - cam.eye[1], target[2] - cam.eye[2]};
      pu -= t[0] * cam.right[0] + t[1] * cam.right[1] + t[2] * cam.right[2];
      pv -= t[0] * cam.up[0] + t[1] * cam.up[1] + t[2] * cam.up[2];
      extent = std::max({extent, std::abs(pu), std::abs(pv) * aspect});
    }
    nearD = std::min(nearD, d), farD = std::max(farD, d);
  }
  if (r.perspective) {
    cam.halfWidth = tanHalf / r.zoom;
    nearD = std::max(nearD, 1e-6 * radius);
    if (!(farD > nearD)) throw badArgs("--eye/--distance: the solid is behind the camera");
  } else {
    cam.halfWidth = (sphereFit ? radius * std::max(1.0, aspect) : extent) * 1.04 / r.zoom;
    if (!r.eye.empty() || r.distance > 0) {
      // An orthographic camera draws what lies in front of it only.
      nearD = std::max(nearD, 0.0);
      if (!(farD > nearD)) throw badArgs("--eye/--distance: the solid is behind the camera");
    }
  }
  const double pad = 1e-3 * radius;
  v.nearDepth = r.perspective ? nearD : nearD - pad;
  v.farDepth = farD + pad;
  return v;
}

}  // namespace

int runRender(const RenderRequest& r) {
  if (r.out.empty()) throw badArgs("-O/--out: the output PNG path is required");
  int w = 0, h = 0;
  parseSize(r.size, w, h);
  if (!std::isfinite(r.azimuth) || !std::isfinite(r.elevation)) throw badArgs("--azimuth/--elevation: expected finite numbers");
  if (!(r.zoom > 0) || !std::isfinite(r.zoom)) throw badArgs("--zoom: expected a positive number");
  if (!(r.fov > 0 && r.fov < 179)) throw badArgs("--fov: expected degrees in (0, 179)");
  if (r.distance < 0 || !std::isfinite(r.distance)) throw badArgs("--distance: expected a positive number");
  if (r.frames < 0 || r.frames > kMaxFrames || r.tFrames < 0 || r.tFrames > kMaxFrames)
    throw badArgs("--frames/--t-frames: expected 0.." + std::to_string(kMaxFrames));
  if (r.frames > 0 && r.tFrames > 0) throw badArgs("--frames and --t-frames: give one of them");
  if (r.frames > 0 && !r.eye.empty()) throw badArgs("--frames: the turntable turns the azimuth; give no --eye");
  ShadeOptions shade;
  shade.background = parseRgb("--background", r.background);
  const std::array<uint8_t, 3> colour = parseRgb("--colour", r.colour);
  for (size_t i = 0; i < 3; ++i) shade.colour[i] = colour[i] / 255.0;
  const Box box = r.bounds.empty() ? Box{} : parseBounds("-b/--bounds", r.bounds);
  std::vector<double> tValues;
  if (r.tFrames > 0) {
    if (!r.model.mapping.empty()) throw badArgs("--t-frames: sweeps x[4] with x[1..3] as X,Y,Z; give no -x");
    std::vector<double> t = parseNumbers("--t-range", r.tRange, "2");
    if (t.size() != 2) throw badArgs("--t-range: expected first,last, got '" + r.tRange + "'");
    for (int k = 0; k < r.tFrames; ++k) tValues.push_back(r.tFrames == 1 ? t[0] : t[0] + (t[1] - t[0]) * k / (r.tFrames - 1));
  }
  const int frames = std::max({r.frames, r.tFrames, 1});

  LoadedModel first = loadModel(r.model, true);
  if (first.dims < 3) throw badArgs("render: the object is " + std::to_string(first.dims) + "-dimensional; render draws 3D solids (use frep slice)");
  if (r.tFrames > 0 && loadModel(r.model, false).dims < 4)
    throw badArgs("--t-frames: the object has no x[4] to sweep");

  double totalMs = 0;
  uint64_t intervals = 0, points = 0;
  size_t hitPixels = 0;
  double pixelStep = 0;  // of the last frame
  // Every frame's field and the box of the solid over all frames: the view stays put while
  // the t-sweep's solid changes (and a turntable's box does not depend on the azimuth).
  std::vector<Expr> fields;
  std::vector<bool> found;
  Vec3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  for (int k = 0; k < frames; ++k) {
    Expr field = first.field;
    if (r.tFrames > 0) {
      ModelRequest m = r.model;
      m.mapping = "X,Y,Z," + formatNumber(tValues[size_t(k)]);
      field = loadModel(m, true).field;
    }
    Vec3 flo, fhi;
    found.push_back(solidBounds(field, box.lo, box.hi, kBoundsLevels, flo, fhi));
    if (!found.back()) spdlog::warn("frame {}: the solid has no point in the box; the picture is empty", k);
    for (size_t i = 0; i < 3 && found.back(); ++i) lo[i] = std::min(lo[i], flo[i]), hi[i] = std::max(hi[i], fhi[i]);
    fields.push_back(field);
  }
  if (!(lo[0] <= hi[0])) lo = box.lo, hi = box.hi;
  for (size_t i = 0; i < 3; ++i) lo[i] = std::max(lo[i], box.lo[i]), hi[i] = std::min(hi[i], box.hi[i]);
  for (int k = 0; k < frames; ++k) {
    const double azimuth = r.azimuth + (r.frames > 0 ? 360.0 * k / r.frames : 0.0);
    const View view = makeView(r, lo, hi, azimuth, w, h, r.frames > 1);
    RenderOptions opt;
    opt.width = w, opt.height = h, opt.threads = r.threads, opt.footprint = !r.noFootprint;
    opt.nearDepth = view.nearDepth, opt.farDepth = view.farDepth;
    const std::string path = framePath(r.out, k, frames);
    io::AtomicOutput out("-O/--out", path);
    RenderStats stats;
    const auto t0 = std::chrono::steady_clock::now();
    DepthImage depth = found[size_t(k)] ? castRays(clipToBox(fields[size_t(k)], box), view.camera, opt, {}, &stats) : DepthImage{};
    if (!found[size_t(k)]) depth.width = w, depth.height = h, depth.hits.assign(size_t(w) * size_t(h), RayHit{});
    io::RgbImage img(w, h);
    img.rgb = shadeImage(depth, view.camera, shade);
    totalMs += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    io::writePng(out.tempPath(), img);
    out.commit();
    pixelStep = 2 * view.camera.halfWidth / w;
    intervals += stats.intervalEvals, points += stats.pointEvals;
    for (const RayHit& hit : depth.hits) hitPixels += hit.kind != RayHit::kNone;
  }
  std::cout << "wrote " << (frames > 1 ? framePath(r.out, 0, frames) + " .. " + framePath(r.out, frames - 1, frames) : r.out)
            << ": " << w << "x" << h << " pixels" << (frames > 1 ? ", " + std::to_string(frames) + " frames" : "")
            << ", pixel " << formatNumber(pixelStep) << (r.perspective ? " (tangent units)" : "") << ", "
            << hitPixels << " on the solid; " << intervals << " interval and " << points
            << " point evaluations in " << formatNumber(std::round(totalMs * 10) / 10) << " ms\n";
  return kExitOk;
}

}  // namespace frep::cli
