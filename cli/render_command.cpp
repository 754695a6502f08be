// frep render: a shaded picture of the solid by certified interval ray casting (frep/render),
// computed on the farm: each picture is a "render" job whose bricks are tiles of the image
// (worker/brick.h), so the bytes are the same for any worker count. The view fits the solid: its
// box is found by interval subdivision inside -b, then the camera (orbit or look-at) is placed
// and sized so that the box fills the image. Geometric types (geometric_types.h) make frames
// (T), a grid of small pictures (V, W) and unions of coloured sections (C, G).
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
#include "farm_job.h"
#include "frep/attributes/colour.h"
#include "frep/evaluators/eval.h"
#include "frep/io/atomic_output.h"
#include "frep/io/file_kind.h"
#include "frep/io/mesh_reader.h"
#include "frep/io/png_writer.h"
#include "frep/io/vdb_reader.h"
#include "frep/meshing/mesh_grid.h"
#include "frep/render/rasterize.h"
#include "frep/render/raycast.h"
#include "frep/render/shade.h"
#include "frep/worker/job_model.h"
#include "geometric_types.h"

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

constexpr int kGutter = 2;  // pixels between the cells of a V/W grid
const std::array<uint8_t, 3> kGutterColour{128, 128, 128};

void setVec(google::protobuf::RepeatedField<double>* field, const Vec3& v) {
  field->Clear();
  for (double c : v) field->Add(c);
}

void setCamera(farm::RenderSpec& spec, const View& view) {
  setVec(spec.mutable_eye(), view.camera.eye);
  setVec(spec.mutable_right(), view.camera.right);
  setVec(spec.mutable_up(), view.camera.up);
  setVec(spec.mutable_forward(), view.camera.forward);
  spec.set_perspective(view.camera.perspective);
  spec.set_half_width(view.camera.halfWidth);
  spec.set_near_depth(view.nearDepth);
  spec.set_far_depth(view.farDepth);
}

// One picture of a frame: a cell of the V/W grid (the whole picture without V and W).
struct Cell {
  farm::JobSpec job;
  bool found = false;  // the solid has a point in the box
  std::vector<TapePtr> sections;  // C/G: each section's field, to colour the hits
  std::shared_ptr<const ColourField> colour;  // the model's attributes s[1..3], if it has them
  double inset = 0;  // colours are read this far inside the hit (colour.h: f >= 0 tests)
};

// The model's colour (HyperFun's s[1..3], frep/attributes/colour.h) a little inside the hit,
// as the mesh writers read it at vertices: an hfA_SetColor(f, ...) test holds on the surface.
std::array<double, 3> attributeColour(const Cell& cell, const RayHit& h) {
  const Vec3 p{h.point[0] - cell.inset * h.normal[0], h.point[1] - cell.inset * h.normal[1],
               h.point[2] - cell.inset * h.normal[2]};
  const std::array<float, 3> c = cell.colour->at(p.data());
  return {c[0], c[1], c[2]};
}

// The section a hit belongs to: the one whose field is largest at the point (the union's max).
std::array<double, 3> sectionColour(const Cell& cell, size_t count, const RayHit& h) {
  thread_local PointEvaluator ev;
  size_t best = 0;
  double bestValue = -INFINITY;
  for (size_t k = 0; k < cell.sections.size(); ++k) {
    const double v = ev.eval(*cell.sections[k], h.point.data());
    if (v > bestValue) bestValue = v, best = k;
  }
  return spectralColour(count > 1 ? double(best) / double(count - 1) : 0.0);
}

}  // namespace

int runRender(const RenderRequest& r) {
  if (isMeshOrVdb(r.model.path)) return runRenderMesh(r);
  if (r.out.empty()) throw badArgs("-O/--out: the output PNG path is required");
  int w = 0, h = 0;
  parseSize(r.size, w, h);
  if (!std::isfinite(r.azimuth) || !std::isfinite(r.elevation)) throw badArgs("--azimuth/--elevation: expected finite numbers");
  if (!(r.zoom > 0) || !std::isfinite(r.zoom)) throw badArgs("--zoom: expected a positive number");
  if (!(r.fov > 0 && r.fov < 179)) throw badArgs("--fov: expected degrees in (0, 179)");
  if (r.distance < 0 || !std::isfinite(r.distance)) throw badArgs("--distance: expected a positive number");
  if (r.frames < 0 || r.frames > kMaxFrames || r.geometric.tFrames < 0 || r.geometric.tFrames > kMaxFrames)
    throw badArgs("--frames/--t-frames: expected 0.." + std::to_string(kMaxFrames));
  if (r.frames > 0 && r.geometric.tFrames > 0) throw badArgs("--frames and --t-frames: give one of them");
  if (r.frames > 0 && !r.eye.empty()) throw badArgs("--frames: the turntable turns the azimuth; give no --eye");
  ShadeOptions shade;
  shade.background = parseRgb("--background", r.background);
  const std::array<uint8_t, 3> colour = parseRgb("--colour", r.colour);
  for (size_t i = 0; i < 3; ++i) shade.colour[i] = colour[i] / 255.0;
  const Box box = r.bounds.empty() ? Box{} : parseBounds("-b/--bounds", r.bounds);
  if (r.farm.resume) throw badArgs("--resume: a render keeps no journal (its tiles are recomputed)");
  const int brick = r.farm.brick == -1 ? 2 * kRenderTile : r.farm.brick;  // not given: 64 pixels
  if (brick % kRenderTile != 0 || brick < kRenderTile)
    throw badArgs("--brick: a render's bricks are tiles of whole " + std::to_string(kRenderTile) +
                  "-pixel squares: expected a multiple of " + std::to_string(kRenderTile) + ", got " + std::to_string(brick));
  if (r.geometric.tFrames > 0 && r.model.mapping.empty() && loadModel(r.model, false).dims < 4)
    throw badArgs("--t-frames: the object has no x[4] to sweep");
  const GeometricTypes g = parseGeometricTypes(r.model.mapping, r.geometric, true);
  if (r.frames > 0 && g.has(GeometricTypes::T)) throw badArgs("--frames and --t-frames: give one of them");
  const int frames = std::max({r.frames, int(g.t.size()), 1});
  const std::vector<double> columns = g.v.empty() ? std::vector<double>{0} : g.v, rows = g.w.empty() ? std::vector<double>{0} : g.w;
  const std::vector<double> sections = g.sections.empty() ? std::vector<double>{0} : g.sections;
  if (uint64_t(w) * columns.size() > uint64_t(kMaxSide) || uint64_t(h) * rows.size() > uint64_t(kMaxSide))
    throw badArgs("--size/--v-cells/--w-cells: the grid of pictures exceeds " + std::to_string(kMaxSide) + " pixels a side");
  farm::FarmOptions options = farmOptions(r.farm, r.out, r.logLevel, r.threads);
  options.journalPath.clear();
  options.brickVoxels = brick;

  // Every picture's job and the box of the solid over all of them: the view stays put while
  // the t-sweep's solid changes (and a turntable's box does not depend on the azimuth).
  std::vector<std::vector<Cell>> cells(static_cast<size_t>(frames));
  Vec3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  GridSpec grid;
  grid.origin = {0, 0, 0}, grid.dims = {w, h, 1}, grid.voxel = 1;
  for (int k = 0; k < frames; ++k)
    for (double wv : rows)
      for (double vv : columns) {
        ModelRequest m = r.model;
        m.mapping = g.mapping(g.t.empty() ? 0.0 : g.t[size_t(k)], vv, wv, sections[0]);
        const LoadedModel lm = loadModel(m, true);
        if (lm.dims < 3)
          throw badArgs("render: the object is " + std::to_string(lm.dims) + "-dimensional; render draws 3D solids (use frep slice)");
        Cell cell;
        cell.job = makeJob(lm, r.model.path, grid, "render");
        if (!lm.colour.empty() && g.sections.empty()) {
          cell.colour = std::make_shared<const ColourField>(lm.colour, 3);
          double diagonal = 0;
          for (int a = 0; a < 3; ++a) diagonal += (box.hi[a] - box.lo[a]) * (box.hi[a] - box.lo[a]);
          cell.inset = 1e-4 * std::sqrt(diagonal);
        }
        farm::RenderSpec& spec = *cell.job.mutable_render();
        setVec(spec.mutable_clip_lo(), box.lo);
        setVec(spec.mutable_clip_hi(), box.hi);
        spec.set_no_footprint(r.noFootprint);
        if (!g.sections.empty()) {
          spec.set_section_coordinate(g.sectionCoordinate());
          for (double sv : g.sections) {
            farm::JobSpec one = cell.job;
            one.mutable_render()->add_section_values(sv);
            cell.sections.push_back(Tape::compile(farm::jobFieldOf(one), 3));
            spec.add_section_values(sv);
          }
        }
        Vec3 flo, fhi;
        cell.found = solidBounds(farm::jobFieldOf(cell.job), box.lo, box.hi, kBoundsLevels, flo, fhi);
        if (!cell.found) spdlog::warn("frame {}: the solid has no point in the box; its picture is empty", k);
        for (size_t i = 0; i < 3 && cell.found; ++i) lo[i] = std::min(lo[i], flo[i]), hi[i] = std::max(hi[i], fhi[i]);
        cells[size_t(k)].push_back(std::move(cell));
      }
  if (!(lo[0] <= hi[0])) lo = box.lo, hi = box.hi;
  for (size_t i = 0; i < 3; ++i) lo[i] = std::max(lo[i], box.lo[i]), hi[i] = std::min(hi[i], box.hi[i]);

  const int nv = int(columns.size()), nw = int(rows.size());
  const int W = nv * w + (nv - 1) * kGutter, H = nw * h + (nw - 1) * kGutter;
  uint64_t intervals = 0, points = 0, bricks = 0;
  size_t hitPixels = 0;
  int workersSeen = 0;
  farm::FarmReport checks;  // --verify's counters over every job
  double farmSeconds = 0, pixelStep = 0;
  for (int k = 0; k < frames; ++k) {
    const double azimuth = r.azimuth + (r.frames > 0 ? 360.0 * k / r.frames : 0.0);
    const View view = makeView(r, lo, hi, azimuth, w, h, r.frames > 1);
    pixelStep = 2 * view.camera.halfWidth / w;
    const std::string path = framePath(r.out, k, frames);
    io::AtomicOutput out("-O/--out", path);
    io::RgbImage img(W, H);
    for (size_t p = 0; p < img.rgb.size(); p += 3) std::copy(kGutterColour.begin(), kGutterColour.end(), &img.rgb[p]);
    for (int cw = 0; cw < nw; ++cw)
      for (int cv = 0; cv < nv; ++cv) {
        Cell& cell = cells[size_t(k)][size_t(cw * nv + cv)];
        DepthImage depth;
        if (cell.found) {
          setCamera(*cell.job.mutable_render(), view);
          farm::FarmOutcome outcome = runFarmJob(cell.job, options);
          requireComplete(outcome.report);
          depth = std::move(outcome.image);
          intervals += outcome.report.intervalEvals, points += outcome.report.pointEvals;
          bricks += outcome.report.bricks, farmSeconds += outcome.report.wallSeconds;
          workersSeen = std::max(workersSeen, outcome.report.workersSeen);
          checks.verifyFraction = outcome.report.verifyFraction;  // --verify: summed over the cells and frames
          checks.verifiedBricks += outcome.report.verifiedBricks;
          checks.verifyMismatches += outcome.report.verifyMismatches;
          checks.liarsBanned += outcome.report.liarsBanned;
          checks.bricksRedone += outcome.report.bricksRedone;
          if (checks.verifyUnavailable.empty()) checks.verifyUnavailable = outcome.report.verifyUnavailable;
        } else {
          depth.width = w, depth.height = h, depth.hits.assign(size_t(w) * size_t(h), RayHit{});
        }
        ShadeOptions cellShade = shade;
        if (!cell.sections.empty())
          cellShade.colourAt = [&cell, n = g.sections.size()](const RayHit& hit) { return sectionColour(cell, n, hit); };
        else if (cell.colour)
          cellShade.colourAt = [&cell](const RayHit& hit) { return attributeColour(cell, hit); };
        const std::vector<uint8_t> rgb = shadeImage(depth, view.camera, cellShade);
        for (int y = 0; y < h; ++y)
          std::copy(&rgb[size_t(y) * size_t(w) * 3], &rgb[size_t(y + 1) * size_t(w) * 3],
                    &img.rgb[(size_t(cw * (h + kGutter) + y) * size_t(W) + size_t(cv * (w + kGutter))) * 3]);
        for (const RayHit& hit : depth.hits) hitPixels += hit.kind != RayHit::kNone;
      }
    io::writePng(out.tempPath(), img);
    out.commit();
  }
  std::cout << "wrote " << (frames > 1 ? framePath(r.out, 0, frames) + " .. " + framePath(r.out, frames - 1, frames) : r.out)
            << ": " << W << "x" << H << " pixels" << (frames > 1 ? ", " + std::to_string(frames) + " frames" : "")
            << (nv * nw > 1 ? ", " + std::to_string(nv) + "x" + std::to_string(nw) + " cells" : "")
            << ", pixel " << formatNumber(pixelStep) << (r.perspective ? " (tangent units)" : "") << ", "
            << hitPixels << " on the solid; " << intervals << " interval and " << points << " point evaluations; "
            << bricks << " tiles on " << (options.workers == 0 && options.listen.empty() ? "the master (in-process)" : std::to_string(workersSeen) + (workersSeen == 1 ? " worker" : " workers"))
            << " in " << formatNumber(std::round(farmSeconds * 1000) / 1000) << " s" << verificationSummary(checks) << "\n";
  return kExitOk;
}

// ---- meshes and sampled grids -----------------------------------------------------------------


bool isMeshOrVdb(const std::string& path) {
  const std::string ext = io::lowerExtension(path);
  const io::FileKind kind = io::sniffFile(path);  // by its bytes too: a grid or mesh named otherwise
  return ext == "ply" || ext == "obj" || ext == "stl" || ext == "vdb" || kind == io::FileKind::Vdb ||
         io::isMeshKind(kind);
}

int runRenderMesh(const RenderRequest& r) {
  if (r.out.empty()) throw badArgs("-O/--out: the output PNG path is required");
  int w = 0, h = 0;
  parseSize(r.size, w, h);
  const std::string input = "'" + r.model.path + "' is a mesh or grid, drawn as stored";
  if (!r.model.params.empty() || !r.model.mapping.empty() || r.model.iso != 0.0) throw badArgs("-a/-x/-i: " + input);
  if (!r.bounds.empty()) throw badArgs("-b/--bounds: " + input + " (the view fits its triangles)");
  if (r.geometric.tFrames != 0 || !r.geometric.gValues.empty()) throw badArgs("--t-frames/--g-values: " + input);
  if (!r.farm.listen.empty() || r.farm.expectWorkers != 0 || r.farm.resume || !r.farm.curveDir.empty() || r.farm.workers != -1)
    throw badArgs("--workers/--listen/--expect-workers/--resume/--curve: " + input + " in-process");
  if (r.noFootprint) throw badArgs("--no-footprint: " + input + " (triangles have no sub-pixel search)");
  if (!std::isfinite(r.azimuth) || !std::isfinite(r.elevation)) throw badArgs("--azimuth/--elevation: expected finite numbers");
  if (!(r.zoom > 0) || !std::isfinite(r.zoom)) throw badArgs("--zoom: expected a positive number");
  if (!(r.fov > 0 && r.fov < 179)) throw badArgs("--fov: expected degrees in (0, 179)");
  if (r.distance < 0 || !std::isfinite(r.distance)) throw badArgs("--distance: expected a positive number");
  if (r.frames < 0 || r.frames > kMaxFrames) throw badArgs("--frames: expected 0.." + std::to_string(kMaxFrames));
  if (r.frames > 0 && !r.eye.empty()) throw badArgs("--frames: the turntable turns the azimuth; give no --eye");
  ShadeOptions shade;
  shade.background = parseRgb("--background", r.background);
  const std::array<uint8_t, 3> colour = parseRgb("--colour", r.colour);
  for (size_t i = 0; i < 3; ++i) shade.colour[i] = colour[i] / 255.0;

  const auto t0 = std::chrono::steady_clock::now();
  Mesh mesh;
  const io::FileKind kind = io::sniffFile(r.model.path);  // by its bytes first, then its name
  if (kind == io::FileKind::Vdb || (io::lowerExtension(r.model.path) == "vdb" && !io::isMeshKind(kind))) {
    // the grid's zero level set, meshed as frep mesh does
    io::SampledVdb vdb = io::readSampledVdb(r.model.path, r.model.object);
    SampledMeshOptions mo;
    mo.threads = r.threads;
    mesh = meshSamples(vdb.samples, mo).mesh;
    if (vdb.toWorld) vdb.toWorld(mesh);
    if (mesh.triangles.empty()) throw CliError(kExitModelError, r.model.path + ": the grid's level set has no surface");
  } else {
    if (!r.model.object.empty()) throw badArgs("-o/--object: " + input);
    mesh = io::readMesh(r.model.path);
  }
  Vec3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  for (const auto& p : mesh.positions)
    for (size_t i = 0; i < 3; ++i) lo[i] = std::min(lo[i], p[i]), hi[i] = std::max(hi[i], p[i]);
  const int frames = std::max(r.frames, 1);
  size_t hitPixels = 0;
  double pixelStep = 0;
  for (int k = 0; k < frames; ++k) {
    const View view = makeView(r, lo, hi, r.azimuth + (r.frames > 0 ? 360.0 * k / r.frames : 0.0), w, h, r.frames > 1);
    RenderOptions opt;
    opt.width = w, opt.height = h, opt.nearDepth = view.nearDepth, opt.farDepth = view.farDepth;
    const std::string path = framePath(r.out, k, frames);
    io::AtomicOutput out("-O/--out", path);
    const DepthImage depth = rasterize(mesh, view.camera, opt);
    io::RgbImage img(w, h);
    img.rgb = shadeImage(depth, view.camera, shade);
    io::writePng(out.tempPath(), img);
    out.commit();
    pixelStep = depth.pixelStep;
    for (const RayHit& hit : depth.hits) hitPixels += hit.kind != RayHit::kNone;
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::cout << "wrote " << (frames > 1 ? framePath(r.out, 0, frames) + " .. " + framePath(r.out, frames - 1, frames) : r.out)
            << ": " << w << "x" << h << " pixels" << (frames > 1 ? ", " + std::to_string(frames) + " frames" : "")
            << ", pixel " << formatNumber(pixelStep) << (r.perspective ? " (tangent units)" : "") << ", " << hitPixels
            << " on the surface; " << mesh.triangles.size() << " triangles in " << formatNumber(std::round(seconds * 1000) / 1000)
            << " s\n";
  return kExitOk;
}

}  // namespace frep::cli
