// The frep verbs, one function each (one file each: check_command.cpp, ...). Each returns the
// exit code or throws CliError; main() wires them to the command line.
#pragma once

#include <string>

#include "model_loader.h"

namespace frep::cli {

// frep check: diagnostics and the list of objects; warnings when the model is NaN or a domain
// error at every point of a small grid over `bounds` (-b text, "" = hfp's ±10).
int runCheck(const ModelRequest& model, const std::string& bounds = "");

struct EvalRequest {
  ModelRequest model;
  std::string at;           // --at: one value per coordinate
  double tolerance = 1e-9;  // |f| <= tolerance counts as on the surface
};
int runEval(const EvalRequest& request);

// Shared by the verbs that sample a region.
struct RegionRequest {
  std::string bounds;  // -b/--bounds text; "" = hfp's default ±10
  int res = 0;         // --res; 0 = not given
  std::string cells;   // -g/--grid text; "" = not given
  std::string out;     // -O/--out
};

// frep relate A B: intersection and inclusion certified over a box, point membership.
struct RelateRequest {
  ModelRequest a, b;
  std::string bounds;      // -b text; "" = hfp's ±10
  double minSize = 0;      // smallest box edge of the subdivision; 0 = 1e-4 of the box
  std::string at;          // --at X,Y,Z: also classify this point
  double tolerance = 1e-9; // |f| <= tolerance: on the surface
};
int runRelate(const RelateRequest& request);

struct SliceRequest {
  ModelRequest model;
  RegionRequest region;
  std::string axis;  // "" = z (3D objects); ignored for 2D objects
  double at = 0.0;   // position of the slicing plane on that axis
  bool mask = false; // inside/outside only (white/black): tiles an interval decides are not evaluated
};
int runSlice(const SliceRequest& request);

// How a job runs: the farm's options (docs/farm.md). None of them changes the output.
struct FarmRequest {
  int workers = -1;          // local workers; -1 one per core, 0 in-process
  std::string listen;        // cluster mode endpoint
  int expectWorkers = 0;
  int brick = -1;            // brick edge in voxels; -1 (not given): chooseBrick (grid and workers)
  int heartbeatMs = 500;
  bool resume = false;
  bool json = false;         // JSON progress events on stdout
  bool noProgress = false;
  std::string curveDir;
  bool insecure = false;     // --listen on the network without --curve
};

struct SampleRequest {
  ModelRequest model;
  RegionRequest region;
  FarmRequest farm;
  int band = 3;     // narrow band half-width in voxels
  int threads = 0;  // threads of the in-process run (--workers 0); 0: all cores
  std::string store = "sdf";  // --store: sdf, raw or fog (VdbStore)
  std::string logLevel = "info";
};
int runSample(const SampleRequest& request);

// frep mesh: on the farm like frep sample (bricks meshed by workers, pieces stitched by the
// master); --workers, --brick and --threads never change the output file.
struct MeshRequest {
  ModelRequest model;
  RegionRequest region;
  FarmRequest farm;
  int threads = 0;         // threads of the in-process run (--workers 0); 0: all cores
  double tolerance = -1;   // --tolerance, voxels (SimplifyOptions); < 0: the default (0.1, 0 for a .vdb)
  bool noSharp = false;    // --no-sharp: SimplifyOptions::sharpFeatures = false
  std::string logLevel = "info";
};
int runMesh(const MeshRequest& request);

int runKeygen(const std::string& dir);

// frep pov: a scene with `$ ... <+> ... $` Minkowski terms, or a .hf model built from the basic
// set, as POV-Ray text (Roerdink's preprocessor; docs/pov.md).
struct PovRequest {
  std::string input;   // scene text (any extension) or .hf model
  std::string object;  // -o for a .hf model
  std::string out;     // -O
  double thin = 0.01;  // thickness of pieces without interior (segments, discs, rectangles)
};
int runPov(const PovRequest& request);

}  // namespace frep::cli
