// The frep verbs, one function each (one file each: check_command.cpp, ...). Each returns the
// exit code or throws CliError; main() wires them to the command line.
#pragma once

#include <string>
#include <vector>

#include "geometric_types.h"
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

// frep relate A B: intersection, inclusion, clearance and penetration depth certified over a
// box, point membership.
struct RelateRequest {
  ModelRequest a, b;
  std::string bounds;      // -b text; "" = hfp's ±10
  double minSize = 0;      // smallest box edge of the subdivision; 0 = 1e-4 of the box
  std::string at;          // --at X,Y,Z: also classify this point
  double tolerance = 1e-9; // |f| <= tolerance: on the surface
  double distanceTol = 0;  // width of the clearance / penetration bounds; 0 = 1e-3 of the box
  bool json = false;       // one JSON object on stdout
};
int runRelate(const RelateRequest& request);

// frep measure: certified volume, area, centroid and inertia (measure_command.cpp, docs/measure.md).
struct MeasureRequest {
  ModelRequest model;
  std::string bounds;        // -b text; "" = hfp's ±10
  double tolerance = 0.005;  // relative width of the volume and area bounds
  int threads = 0;           // 0: all cores (same numbers for any count)
  long long maxCells = 2000000;  // budget of boundary cells (about 1.5 KB each at the peak)
  bool json = false;         // one JSON object on stdout
  bool noProgress = false;
};
int runMeasure(const MeasureRequest& request);

struct SliceRequest {
  ModelRequest model;
  RegionRequest region;
  std::string axis;  // "" = z (3D objects); ignored for 2D objects
  double at = 0.0;   // position of the slicing plane on that axis
  bool mask = false; // inside/outside only (white/black): tiles an interval decides are not evaluated
  GeometricRequest geometric;  // T frames, V/W grid, C/G sections (geometric_types.h)
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
  bool strict = false;       // --strict: uncertified extremum searches fail the job (exit 8)
  std::string curveDir;
  bool insecure = false;     // --listen on the network without --curve
  std::string verify;        // --verify F: the fraction of bricks checked on a second worker ("" = off)
  int replicate = 1;         // --replicate 2: every brick checked (= --verify 1)
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
  bool openRim = false;    // --open-rim: no caps where the box cuts the solid (an open mesh there)
  std::string logLevel = "info";
  std::string format;      // --format: the format of -O whatever its extension ("" = from it)
  std::string up;          // --up z|y: the file's up axis ("" = the format's: y for .glb, else z)
  // More files of the same mesh (hfp's -wrl, -stl, -stlb, -pov, -cli): a format name and a path.
  struct Extra {
    std::string format, path;
  };
  std::vector<Extra> extraOutputs;
  std::string sliceStep;   // -gs: CLI layer thickness, hfp style D | Dxy,Dz | Dx,Dy,Dz ("" = one voxel)
  bool timing = false;     // hfp's -t (the times are always printed)
};
int runMesh(const MeshRequest& request);

// frep render: a shaded PNG of the solid by certified interval ray casting (frep/render), in
// process on threads; turntable (--frames) and x[4] sweep (--t-frames) write numbered frames.
struct RenderRequest {
  ModelRequest model;
  std::string bounds;      // -b: the region drawn (hfp's default ±10); the view fits the solid in it
  std::string out;         // -O: PNG path (frames: NAME_0000.png, ...)
  std::string size = "512x512";
  double azimuth = -60, elevation = 25;  // degrees
  double distance = 0;     // 0: fit the solid
  double zoom = 1;         // > 1 magnifies
  std::string eye, target, up;  // look-at camera (eye given: azimuth/elevation ignored)
  bool perspective = false;
  double fov = 30;         // perspective: horizontal field of view, degrees
  std::string background = "255,255,255", colour = "204,158,97";
  int frames = 0;          // turntable: N frames over 360 degrees of azimuth
  GeometricRequest geometric;  // T frames, V/W grid, C/G sections (geometric_types.h)
  FarmRequest farm;
  int threads = 0;         // threads of the in-process run (--workers 0)
  bool noFootprint = false;
  std::string logLevel = "info";
};
int runRender(const RenderRequest& request);
// frep render of a mesh (.ply, .obj, .stl) or a sampled .vdb: its triangles drawn by the
// z-buffer (render_mesh_command.cpp), with the same cameras and shading.
bool isMeshOrVdb(const std::string& path);
int runRenderMesh(const RenderRequest& request);

// frep view: a local web page showing the model in 3D with slices and frep mesh's report,
// recomputed on every save of the file (view_command.cpp, docs/view.md).
struct ViewRequest {
  ModelRequest model;
  std::string bounds;            // -b, passed to frep mesh and frep slice ("" = hfp's ±10)
  int res = 0;                   // --res of frep mesh (0: its default)
  std::string cells;             // -g of frep mesh
  int workers = -1;              // --workers of frep mesh (-1: its default, one per core)
  std::string host = "127.0.0.1";
  int port = 8080;               // 0: any free port (printed)
  std::string logLevel = "info"; // passed to the frep mesh children
};
int runView(const ViewRequest& request);

int runKeygen(const std::string& dir, bool force);  // force: replace existing keys

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
