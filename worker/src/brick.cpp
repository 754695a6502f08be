// Computing one brick: sample, mesh (and simplify) or cast rays over its region of the job's grid.
// The model was compiled by job_model.cpp; this is the only code the in-process mode adds to the
// master.
#include "frep/worker/brick.h"

#include "frep/extremum/extremum.h"
#include "frep/meshing/mesh_simplify.h"
#include "frep/sampling/band_distance.h"
#include "frep/sampling/exact_band_distance.h"

namespace frep::farm {

namespace {
uint64_t meshPointEvals(const MeshStats& s) { return s.samplePointEvals + s.rootEvals + s.gradientEvals; }

BrickOutput computeBrickOnce(const TapePtr& tape, const JobSpec& job, const std::array<int32_t, 3>& lo,
                             const std::array<int32_t, 3>& hi, int threads);
}  // namespace

BrickOutput computeBrick(const TapePtr& tape, const JobSpec& job, const std::array<int32_t, 3>& lo,
                         const std::array<int32_t, 3>& hi, int threads) {
  // A process computes one brick at a time, so the change of the process-wide extremum
  // counters over the call is this brick's.
  ExtremumCounters& c = extremumCounters();
  const uint64_t searches = c.searches, uncertified = c.uncertified, signDecided = c.signDecided;
  c.widestGap = 0.0;
  BrickOutput out = computeBrickOnce(tape, job, lo, hi, threads);
  out.extremumSearches = c.searches - searches;
  out.extremumUncertified = c.uncertified - uncertified;
  out.extremumSignDecided = c.signDecided - signDecided;
  out.extremumWidestGap = c.widestGap;
  return out;
}

namespace {
BrickOutput computeBrickOnce(const TapePtr& tape, const JobSpec& job, const std::array<int32_t, 3>& lo,
                             const std::array<int32_t, 3>& hi, int threads) {
  if (operationOf(job) == Operation::Render) {
    RenderOptions opt = renderOptionsOf(job);
    opt.threads = threads;
    RenderStats stats;
    BrickOutput out;
    out.hits = castRegion(tape, cameraOf(job), opt, PixelRegion{lo[0], lo[1], hi[0], hi[1]}, &stats);
    out.tileLo = lo, out.tileHi = hi;
    out.stats.pointEvals = stats.pointEvals;
    out.stats.intervalEvals = stats.intervalEvals;
    return out;
  }
  if (operationOf(job) == Operation::Mesh) {
    MeshOptions mo;
    mo.threads = threads;
    BrickOutput out;
    const GridSpec grid = gridOf(job);
    out.piece = meshRegion(tape, grid, lo, hi, mo);
    out.stats.pointEvals = meshPointEvals(out.piece.stats);
    out.stats.intervalEvals = out.piece.stats.sampleIntervalEvals;
    out.stats.nanValues = out.piece.stats.nanValues;
    out.stats.domainErrors = out.piece.stats.domainErrors;
    if (job.mesh().tolerance() > 0) {
      SimplifyOptions so;
      so.tolerance = job.mesh().tolerance();
      so.sharpFeatures = !job.mesh().no_sharp();
      so.threads = threads;
      simplifyRegion(out.piece, tape, grid, so, lo, hi);
    }
    return out;
  }
  SampleOptions opt;
  opt.bandVoxels = job.band();
  opt.regionLo = lo;
  opt.regionHi = hi;
  opt.threads = threads;
  // The distance reads values from the neighbouring bricks' halo: extremum values must then be
  // functions of their point alone (cold searches), or the split would show in the output.
  if (job.distance() && !tape->extrema().empty()) opt.pointwiseSearches = true;
  // The distance stores keep a voxel active only where its distance is in the band, so the
  // leaves are classified in 4^3 blocks (SampleOptions::leafBlock); raw keeps every evaluated
  // voxel, so there 2^3 blocks keep the evaluated ones near a possible zero.
  if (job.distance()) opt.leafBlock = 4;
  const GridSpec grid = gridOf(job);
  SampleResult r = sample(tape, grid, opt);
  if (job.distance()) {
    BandDistanceStats halo;
    if (job.distance_exact()) exactBandDistance(tape, grid, opt, r, &halo);
    else bandDistance(tape, grid, opt, r, &halo);
    r.stats.pointEvals += halo.haloPointEvals;
    r.stats.intervalEvals += halo.haloIntervalEvals;
  }
  BrickOutput out;
  out.leaves = std::move(r.leaves);
  out.tiles = std::move(r.tiles);
  out.stats = r.stats;
  return out;
}
}  // namespace

}  // namespace frep::farm
