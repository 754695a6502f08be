// The frep command: argument wiring, logging setup and the mapping of failures to exit codes.
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/cfg/env.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <iostream>

#include "commands.h"
#include "json_events.h"
#include "suggest.h"
#include "frep/master/status_line.h"
#include "exit_codes.h"
#include "frep/io/geometry_files.h"
#include "hfp_invocation.h"

#ifndef FREP_VERSION
#define FREP_VERSION "unknown"
#endif

namespace {

using namespace frep::cli;

void addModelOptions(CLI::App* sub, ModelRequest& m, bool withFieldOptions) {
  sub->add_option("model", m.path, "The HyperFun model (.hf)")->required();
  sub->add_option("-o,--object", m.object, "Object to use (as hfp: default my_model, else the first)");
  if (!withFieldOptions) return;
  sub->add_option("-a,--params", m.params, "Values of a[1..m], comma-separated (default all 0)");
  sub->add_option("-x,--map", m.mapping,
                  "Map x[1..n] to axes X, Y, Z or constants, e.g. X,Y,Z,0.5 (see docs/cli.md)");
  sub->add_option("-i,--iso", m.iso, "Isovalue: the solid is f >= iso (default 0)");
}

void addRegionOptions(CLI::App* sub, RegionRequest& r, const std::string& outHelp, int defaultRes) {
  sub->add_option("-b,--bounds", r.bounds, "Box: B | min,max | bx,by,bz | xmin,ymin,zmin,xmax,ymax,zmax (default 10)");
  sub->add_option("--res", r.res, "Points along the longest axis (default " + std::to_string(defaultRes) + ")");
  sub->add_option("-g,--grid", r.cells, "Cells per axis, hfp style: N or Nx,Ny,Nz (instead of --res)");
  sub->add_option("-O,--out", r.out, outHelp + " (required)");  // required: checked by the command, after -o
}

// Geometric types of -x (docs/cli.md, "Geometric types"): T frames, V/W grid, C/G sections.
void addGeometricOptions(CLI::App* sub, GeometricRequest& g) {
  sub->add_option("--t-frames", g.tFrames, "Frames over the T coordinate of -x (x[4] without -x): numbered pictures");
  sub->add_option("--t-range", g.tRange, "first,last value of T (default 0,1)");
  sub->add_option("--v-range", g.vRange, "first,last value of V, the grid's columns (default 0,1)");
  sub->add_option("--v-cells", g.vCells, "Columns of the V/W grid (default 4)");
  sub->add_option("--w-range", g.wRange, "first,last value of W, the grid's rows (default 0,1)");
  sub->add_option("--w-cells", g.wCells, "Rows of the V/W grid (default 4)");
  sub->add_option("--c-range", g.cRange, "first,last value of C, coloured along the spectrum (default 0,1)");
  sub->add_option("--c-levels", g.cLevels, "Sections of the C coordinate (default 8)");
  sub->add_option("--g-values", g.gValues, "Values of the G coordinate, v1,v2,...: their sections in one picture");
}

void addFarmOptions(CLI::App* sub, FarmRequest& f) {
  sub->add_flag("--strict", f.strict,
                "Fail (exit 8, no output) when an extremum search stops before certifying its tolerance "
                "(default: a warning with the widest gap reached, also in the report)");
  sub->add_option("--workers", f.workers, "Local worker processes (default: one per core; a grid of at most 64^3 points in-process; 0 computes in-process)");
  sub->add_option("--listen", f.listen,
                  "Cluster mode: bind here (e.g. tcp://*:5555), start no workers; they connect with "
                  "frep-worker --connect");
  sub->add_option("--expect-workers", f.expectWorkers,
                  "Cluster mode: workers expected; dispatch waits up to 5 s after the first one joins for the rest");
  sub->add_option("--brick", f.brick, "Brick edge in voxels, a multiple of 8 (default: 64, smaller so that every worker gets two; same output)");
  sub->add_option("--heartbeat-ms", f.heartbeatMs, "Heartbeat interval both ways (default 500)");
  sub->add_flag("--resume", f.resume, "Continue a stopped job from OUT.journal");
  sub->add_flag("--json", f.json, "JSON progress events on stdout (batch systems)");
  sub->add_flag("--no-progress", f.noProgress, "No progress bar");
  sub->add_option("--curve", f.curveDir, "Require CURVE keys from DIR (see frep keygen)");
  sub->add_flag("--insecure", f.insecure,
                "Allow --listen on a non-loopback address without --curve (anyone who reaches it can join)");
  sub->add_option("--verify", f.verify,
                  "Compute a fraction F (0 to 1) of the bricks, and every brick of a worker under suspicion, again "
                  "on another worker and merge them only if the bytes agree; a worker outvoted is banned and its "
                  "bricks recomputed (default: off)");
  sub->add_option("--replicate", f.replicate,
                  "2: every brick computed by two workers and merged only if they agree (= --verify 1); 1: once "
                  "(default)");
}

void checkObjectIsNotAFile(const ModelRequest& m) {
  if (m.object.find_first_of("./") != std::string::npos)
    throw badArgs("-o/--object: '" + m.object +
                  "' looks like a file name; -o selects the object (as in hfp), write files with -O/--out");
}

// --log-level if given, else $SPDLOG_LEVEL (spdlog's syntax: "debug", or "warn,frep=debug"), else
// info. Returns the level in effect, which local workers are started with.
std::string setUpLogging(const std::string& level, bool levelGiven) {
  // Through the status line: a log line erases the progress bar and the bar is drawn again below.
  auto sink = std::make_shared<frep::farm::LineSafeSink>(std::make_shared<spdlog::sinks::stderr_color_sink_mt>());
  auto logger = std::make_shared<spdlog::logger>("frep", sink);
  spdlog::register_logger(logger);  // so that $SPDLOG_LEVEL's "frep=..." finds it
  logger->set_pattern("frep: %^%l%$: %v");
  logger->set_level(spdlog::level::from_str(level));
  spdlog::set_default_logger(logger);
  if (!levelGiven) spdlog::cfg::load_env_levels();
  const auto name = spdlog::level::to_string_view(logger->level());
  return std::string(name.data(), name.size());
}

}  // namespace

int main(int argc, char** argv) {
  frep::io::installGeometryLoader();  // frMesh / frVolume read files through frep_io
  // hfp's command line (no verb): `frep model.hf -g 60 -stl out.stl` runs frep mesh.
  std::vector<std::string> hfpArgs;
  std::vector<char*> hfpArgv;
  if (isHfpInvocation(argc, argv)) {
    try {
      HfpTranslation t = translateHfp(argc, argv);
      if (t.help) {
        std::cout << hfpHelp();
        return kExitOk;
      }
      for (const auto& note : t.notes) std::cerr << "frep: note: " << note << "\n";
      hfpArgs.push_back(argv[0]);
      hfpArgs.insert(hfpArgs.end(), t.args.begin(), t.args.end());
      for (auto& a : hfpArgs) hfpArgv.push_back(a.data());
      argc = int(hfpArgv.size());
      argv = hfpArgv.data();
    } catch (const CliError& e) {
      std::cerr << "frep: error: " << e.what() << "\nRun 'frep MODEL.hf -h' for hfp-style usage.\n";
      return e.code;
    }
  }
  CLI::App app{"frep " FREP_VERSION ": evaluate, slice and sample F-rep models written in HyperFun (.hf)."};
  app.footer(std::string(exitCodeHelp()) + "\nOptions -o (object), -a, -b, -g, -i, -x follow hfp; "
             "output files are -O/--out. See docs/cli.md.");
  app.require_subcommand(1);
  app.set_version_flag("--version", FREP_VERSION);
  std::string logLevel = "info";
  CLI::Option* logLevelOption = app.add_option("--log-level", logLevel,
                                               "trace, debug, info, warn, error, critical or off (default info, or $SPDLOG_LEVEL)")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}));

  ModelRequest checkModel;
  CLI::App* check = app.add_subcommand("check", "Compile a model: print diagnostics and list its objects");
  addModelOptions(check, checkModel, false);
  std::string checkBounds;
  check->add_option("-b,--bounds", checkBounds, "Box sampled for the empty-model warnings (default 10)");

  EvalRequest eval;
  CLI::App* evalCmd = app.add_subcommand("eval", "Value, in/on/out and gradient of f at one point");
  addModelOptions(evalCmd, eval.model, true);
  evalCmd->add_option("--at", eval.at, "The point: one value per coordinate, e.g. 1,0,0")->required();
  evalCmd->add_option("--tolerance", eval.tolerance, "|f| <= tolerance is 'on' (default 1e-9)");

  SliceRequest slice;
  CLI::App* sliceCmd = app.add_subcommand("slice", "Heat map PNG of f on a plane, zero contour in black");
  addModelOptions(sliceCmd, slice.model, true);
  addRegionOptions(sliceCmd, slice.region, "Output PNG file", 512);
  sliceCmd->add_option("--axis", slice.axis, "Axis normal to the plane: x, y or z (default z; not for 2D objects)");
  sliceCmd->add_option("--at", slice.at, "Position of the plane on that axis (default 0)");
  sliceCmd->add_flag("--mask", slice.mask, "Inside white, outside black: only pixels near the boundary are evaluated");
  addGeometricOptions(sliceCmd, slice.geometric);

  SampleRequest sample;
  CLI::App* sampleCmd = app.add_subcommand("sample", "Narrow-band OpenVDB level set (signed distance; -f or fog by --store) of a model");
  addModelOptions(sampleCmd, sample.model, true);
  addRegionOptions(sampleCmd, sample.region, "Output .vdb file", 128);
  sampleCmd->add_option("--band", sample.band, "Band half-width in voxels (default 3)");
  sampleCmd->add_option("--store", sample.store,
                        "What the grid holds: sdf (signed distance, estimated per brick; default), sdf-exact (the exact "
                        "distance to the samples' piecewise-linear surface, per brick), raw (-f) or fog (density grid)")
      ->check(CLI::IsMember({"sdf", "sdf-exact", "raw", "fog"}));
  sampleCmd->add_option("--threads", sample.threads, "Threads of the in-process run, --workers 0 (default 0: all cores)");
  addFarmOptions(sampleCmd, sample.farm);

  MeshRequest mesh;
  CLI::App* meshCmd = app.add_subcommand("mesh", "Watertight triangle mesh of a model's surface (on the farm), or of the "
                                               "float grid of a .vdb written by frep sample (-o names the grid)");
  addModelOptions(meshCmd, mesh.model, true);
  addRegionOptions(meshCmd, mesh.region,
                   "Output mesh: .ply (binary), .obj, .stl (binary), .wrl (VRML 2.0), .inc/.pov (POV-Ray mesh2), "
                   ".3mf, .glb (glTF 2.0 binary) or .cli (layer slices)", 128);
  meshCmd->add_option("--format", mesh.format,
                      "Format of -O whatever its extension: ply, obj, stl, stl-ascii, wrl, pov, 3mf, glb, cli, cli-binary");
  meshCmd->add_option("--up", mesh.up,
                      "Up axis of the file: z (the model's axes) or y ((x, y, z) written as (x, z, -y)); default y for "
                      ".glb (glTF is Y-up), z for the others");
  std::string wrlOut, stlOut, stlbOut, povOut, cliOut;
  meshCmd->add_option("--wrl", wrlOut, "Also write VRML 2.0 with normals and colours (hfp's -wrl)");
  meshCmd->add_option("--stl", stlOut, "Also write ASCII STL (hfp's -stl)");
  meshCmd->add_option("--stlb", stlbOut, "Also write binary STL (hfp's -stlb)");
  meshCmd->add_option("--pov", povOut, "Also write a POV-Ray mesh2 (hfp's -pov)");
  meshCmd->add_option("--cli", cliOut, "Also write layer slices in the Common Layer Interface format, ASCII (hfp's -cli)");
  meshCmd->add_option("--gs", mesh.sliceStep, "CLI layer thickness, hfp's -gs: D | Dxy,Dz | Dx,Dy,Dz (the z step; default one voxel)");
  meshCmd->add_flag("--timing", mesh.timing, "hfp's -t (the times are always printed)");
  meshCmd->add_option("--threads", mesh.threads,
                      "Threads of the in-process run (--workers 0) and of the master's simplification (default 0: all cores; same output)");
  addFarmOptions(meshCmd, mesh.farm);
  meshCmd->add_option("--tolerance", mesh.tolerance,
                      "Adaptive simplification: the largest distance from the surface it may add, in voxels "
                      "(default 0.1; 0 keeps every triangle of the marching tetrahedra)");
  meshCmd->add_flag("--no-sharp", mesh.noSharp,
                    "Keep merged vertices on the mesher's vertices instead of the model's edges and corners");
  meshCmd->add_flag("--open-rim", mesh.openRim,
                    "Where the box cuts the solid, leave the mesh open on the box's faces instead of capping it "
                    "(default: the closed mesh of solid ∩ box)");

  PovRequest pov;
  CLI::App* povCmd = app.add_subcommand("pov", "POV-Ray scene of Minkowski terms: $ ... <+> ... $ in a scene, or a .hf "
                                             "model built from the basic set (docs/pov.md)");
  povCmd->add_option("input", pov.input, "Scene text with $ ... $ terms, or a .hf model")->required();
  povCmd->add_option("-o,--object", pov.object, "Object of a .hf model (as hfp: default my_model, else the first)");
  povCmd->add_option("-O,--out", pov.out, "Output POV-Ray file (required)");
  povCmd->add_option("--thin", pov.thin, "Thickness of pieces without interior: segments, discs (default 0.01)");
  RelateRequest relate;
  CLI::App* relateCmd = app.add_subcommand("relate", "Certified relations of two models: intersection, inclusion, clearance, penetration depth, point membership");
  relateCmd->add_option("a", relate.a.path, "Model A (.hf)")->required();
  relateCmd->add_option("b", relate.b.path, "Model B (.hf)")->required();
  relateCmd->add_option("--object-a", relate.a.object, "Object of A (default my_model, else the first)");
  relateCmd->add_option("--object-b", relate.b.object, "Object of B");
  relateCmd->add_option("-b,--bounds", relate.bounds, "Box searched (default 10)");
  relateCmd->add_option("--min-size", relate.minSize, "Smallest box edge of the subdivision (default 1e-4 of the box)");
  relateCmd->add_option("--at", relate.at, "Also classify the point X,Y,Z against both");
  relateCmd->add_option("--distance-tol", relate.distanceTol,
                        "Width of the clearance and penetration bounds (default 1e-3 of the box)");
  relateCmd->add_flag("--json", relate.json, "One JSON object on stdout");
  MeasureRequest measure;
  CLI::App* measureCmd = app.add_subcommand("measure", "Certified volume, surface area, centroid and inertia tensor of a model "
                                                       "(lower and upper bounds; docs/measure.md)");
  addModelOptions(measureCmd, measure.model, true);
  measureCmd->add_option("-b,--bounds", measure.bounds,
                         "Box measured (solid ∩ box): B | min,max | bx,by,bz | xmin,ymin,zmin,xmax,ymax,zmax (default 10)");
  measureCmd->add_option("--tolerance", measure.tolerance,
                         "Refine until (upper - lower) <= T * lower for the volume and the area (default 0.005)");
  measureCmd->add_option("--threads", measure.threads, "Threads (default 0: all cores; same numbers for any count)");
  measureCmd->add_option("--max-cells", measure.maxCells,
                         "Budget of boundary cells (about 1.5 KB of memory each); refinement stops there with a warning (default 2000000)");
  measureCmd->add_flag("--json", measure.json, "The result as one JSON object on stdout");
  measureCmd->add_flag("--no-progress", measure.noProgress, "No progress line");
  RenderRequest render;
  CLI::App* renderCmd = app.add_subcommand("render", "Shaded PNG of a model by certified interval ray casting");
  addModelOptions(renderCmd, render.model, true);
  renderCmd->add_option("-b,--bounds", render.bounds, "Region drawn: B | min,max | bx,by,bz | xmin,ymin,zmin,xmax,ymax,zmax (default 10)");
  renderCmd->add_option("-O,--out", render.out, "Output PNG file (required); frames add _0000, _0001, ...");
  renderCmd->add_option("--size", render.size, "Image size WxH in pixels (default 512x512)");
  renderCmd->add_option("--azimuth", render.azimuth, "Camera azimuth in degrees, from +x towards +y (default -60)");
  renderCmd->add_option("--elevation", render.elevation, "Camera elevation in degrees above the xy plane (default 25)");
  renderCmd->add_option("--distance", render.distance, "Camera distance from the target (default: fit the solid)");
  renderCmd->add_option("--zoom", render.zoom, "Magnification of the fitted view (default 1)");
  renderCmd->add_option("--eye", render.eye, "Look-at camera: eye position x,y,z (instead of azimuth/elevation)");
  renderCmd->add_option("--target", render.target, "Point looked at, x,y,z (default: the centre of the solid's box)");
  renderCmd->add_option("--up", render.up, "Up direction of the image, x,y,z (default 0,0,1)");
  renderCmd->add_flag("--perspective", render.perspective, "Perspective projection (default orthographic)");
  renderCmd->add_option("--fov", render.fov, "Perspective: horizontal field of view in degrees (default 30)");
  renderCmd->add_option("--background", render.background, "Background r,g,b (0-255) or #rrggbb (default white)");
  renderCmd->add_option("--colour,--color", render.colour, "Surface colour r,g,b (0-255) or #rrggbb");
  renderCmd->add_option("--frames", render.frames, "Turntable: N frames turning the azimuth through 360 degrees");
  addGeometricOptions(renderCmd, render.geometric);
  addFarmOptions(renderCmd, render.farm);
  // render also draws meshes and grids, and its bricks are squares of pixels, not voxels.
  renderCmd->get_option("model")->description("The HyperFun model (.hf), or a mesh (.ply, .obj, .stl) or OpenVDB grid (.vdb)");
  renderCmd->get_option("--brick")->description("Tile edge in pixels, a multiple of 32 (default 64; same output)");
  renderCmd->add_option("--threads", render.threads, "Threads of the in-process run, --workers 0 (default 0: all cores; same output)");
  renderCmd->add_flag("--no-footprint", render.noFootprint,
                      "Cast centre rays only (sub-pixel features between pixel centres are then not drawn)");

  ViewRequest view;
  CLI::App* viewCmd = app.add_subcommand("view", "Local web page showing the model in 3D with slices and the mesh "
                                                 "report, updated on every save (docs/view.md)");
  addModelOptions(viewCmd, view.model, true);
  viewCmd->add_option("-b,--bounds", view.bounds, "Box: B | min,max | bx,by,bz | xmin,ymin,zmin,xmax,ymax,zmax (default 10)");
  viewCmd->add_option("--res", view.res, "Points of frep mesh along the longest axis (default 128)");
  viewCmd->add_option("-g,--grid", view.cells, "Cells per axis of frep mesh, hfp style: N or Nx,Ny,Nz (instead of --res)");
  viewCmd->add_option("--workers", view.workers, "Local workers of frep mesh (default: one per core; 0 in-process)");
  viewCmd->add_option("--host", view.host, "Address to serve on (default 127.0.0.1: this machine only)");
  viewCmd->add_option("--port", view.port, "Port to serve on (default 8080; 0: any free port, printed)");

  std::string keygenDir;
  CLI::App* keygenCmd = app.add_subcommand("keygen", "Write CURVE keys for a farm on a shared network");
  keygenCmd->add_option("dir", keygenDir, "Directory for the keys")->required();
  bool keygenForce = false;
  keygenCmd->add_flag("--force", keygenForce, "Replace the keys DIR already has (workers holding the old ones are locked out)");

  for (CLI::App* sub : {check, evalCmd, sliceCmd, sampleCmd, meshCmd, povCmd, renderCmd, measureCmd, viewCmd}) sub->fallthrough();

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    // An unknown verb or option with its closest name; a JSON error event when --json was given.
    const std::string message = parseErrorMessage(app, e.what(), argc, argv);
    std::cerr << "frep: error: " << message << "\nRun 'frep --help' for usage.\n";
    if (std::find_if(argv + 1, argv + argc, [](const char* a) { return std::string(a) == "--json"; }) != argv + argc)
      enableJsonEvents();
    jsonError(kExitBadArgs, message);
    return kExitBadArgs;
  }

  logLevel = setUpLogging(logLevel, logLevelOption->count() > 0);
  if ((sampleCmd->parsed() && sample.farm.json) || (meshCmd->parsed() && mesh.farm.json) ||
      (measureCmd->parsed() && measure.json))
    enableJsonEvents();
  try {
    if (check->parsed()) {
      checkObjectIsNotAFile(checkModel);
      return runCheck(checkModel, checkBounds);
    }
    if (evalCmd->parsed()) {
      checkObjectIsNotAFile(eval.model);
      return runEval(eval);
    }
    if (sliceCmd->parsed()) {
      checkObjectIsNotAFile(slice.model);
      return runSlice(slice);
    }
    if (viewCmd->parsed()) {
      checkObjectIsNotAFile(view.model);
      view.logLevel = logLevel;
      return runView(view);
    }
    if (keygenCmd->parsed()) return runKeygen(keygenDir, keygenForce);
    if (povCmd->parsed()) return runPov(pov);
    if (relateCmd->parsed()) return runRelate(relate);
    if (measureCmd->parsed()) {
      checkObjectIsNotAFile(measure.model);
      return runMeasure(measure);
    }
    if (renderCmd->parsed()) {
      checkObjectIsNotAFile(render.model);
      render.logLevel = logLevel;
      return runRender(render);
    }
    if (meshCmd->parsed()) {
      checkObjectIsNotAFile(mesh.model);
      const std::pair<const char*, std::string*> extras[] = {
          {"wrl", &wrlOut}, {"stl-ascii", &stlOut}, {"stl", &stlbOut}, {"pov", &povOut}, {"cli", &cliOut}};
      for (const auto& [format, path] : extras)
        if (!path->empty()) mesh.extraOutputs.push_back({format, *path});
      if (mesh.region.out.empty() && !mesh.extraOutputs.empty()) {  // the first of them is the main output
        mesh.region.out = mesh.extraOutputs.front().path;
        if (mesh.format.empty()) mesh.format = mesh.extraOutputs.front().format;
        mesh.extraOutputs.erase(mesh.extraOutputs.begin());
      }
      mesh.logLevel = logLevel;
      return runMesh(mesh);
    }
    checkObjectIsNotAFile(sample.model);
    sample.logLevel = logLevel;
    return runSample(sample);
  } catch (const CliError& e) {
    std::cerr << "frep: error: " << e.what() << "\n";
    jsonError(e.code, e.what());
    return e.code;
  } catch (const std::exception& e) {
    std::cerr << "frep: internal error: " << e.what() << "\n";
    jsonError(kExitInternal, std::string("internal error: ") + e.what());
    return kExitInternal;
  }
}
