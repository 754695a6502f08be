// Sampler output -> OpenVDB level set file. This header does not include OpenVDB (its headers
// take ~25 s to compile); vdb_writer.cpp does, and vdb_grid.h exposes the grid it builds.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "frep/sampling/sample.h"

namespace frep::io {

namespace detail {
class LevelSetTree;
}

// What the grid holds: a true signed distance (default), the sampler's -f, or a fog volume.
enum class VdbStore { Sdf, Raw, Fog };
const char* storeName(VdbStore store);  // "sdf", "raw", "fog" (the --store values)

struct VdbMetadata {
  std::string gridName;  // the object's name
  std::string job;       // canonical job description (frepJobDescription): stable provenance
  std::string source;    // the model file's name without its directories
  std::string params;    // -a as given ("" = none)
  uint64_t sourceHash = 0;  // lang::Model::sourceHash
  double iso = 0.0;
  VdbStore store = VdbStore::Sdf;
  // Sdf and Fog: the leaves already hold the band's signed distance (the workers' estimate,
  // core sampling/band_distance.h), stored as it is, with its bound in frep_distance; false:
  // the distance is computed here from -f by the mesh round trip below.
  bool distanceValues = false;
  // With distanceValues: the workers' exact distance to the samples' piecewise-linear zero set
  // (core sampling/exact_band_distance.h, --store sdf-exact), not the estimate: frep_distance.
  bool exactDistance = false;
};

// Writes one FloatGrid on the world lattice (index (i, j, k) at world (i, j, k) * voxel: a pure
// scale transform). Sdf: class level set, the signed distance in a band of bandVoxels either
// side, background band * voxel, negative inside: the leaves' own (distanceValues) or the exact
// distance to the zero set of f meshed from the samples (tools::levelSetRebuild).
// Raw: the sampler's -f (active in its band, tiles and background at +-band * voxel). Fog:
// the Sdf grid through tools::sdfToFogVolume, named "density". Metadata: frep_sign, frep_store,
// frep_operation, frep_model_hash, frep_source, frep_object, frep_job, frep_units, frep_voxel,
// frep_box_index_min/max, frep_box_min/max (world), frep_band_voxels, frep_band, frep_iso,
// frep_params, frep_version, and with distanceValues frep_distance (the value's bound). Throws
// Error(kExitIoError).
void writeLevelSet(const std::string& path, const SampleResult& result, const VdbMetadata& meta);

// The same file built from a sample as it streams in (farm::SampleSink): tiles and leaves in any
// number of calls, each tile before the leaves it covers (farm::SampleSink hands each slab's
// tiles before its leaves), then write(): the bytes writeLevelSet writes for a SampleResult
// holding those tiles and leaves. Each call copies its leaves into the tree, so the caller can
// free or reuse them: the sampler's leaves and the tree are never held whole at once. A call's
// leaves lie at or past (in x) every leaf of the calls before (the farm's slabs, sorted), so
// what lies before them is final: tiles are filled in only as far as the leaves reach, and the
// leaves there without an active voxel are pruned at once, as the final prune would (the dense
// leaves a tile's faces make on a lattice off OpenVDB's 8-grid held ~0.9 GB at 1024^3). The
// file is written in place, not built in memory first.
class LevelSetBuilder {
 public:
  // spillLeaves: the final leaves that stay in the output are written out as they come too, to
  // an unlinked temporary file (tmpfile(), in /tmp), and the tree keeps their value masks only
  // (~0.1 KB a leaf instead of ~2.2 KB): the memory no longer grows with the output's leaves.
  // write() then takes only the stores that write the values as they are (raw, and sdf with
  // distanceValues), else std::logic_error; the bytes are the same.
  LevelSetBuilder(const GridSpec& grid, int bandVoxels, bool spillLeaves = false);
  ~LevelSetBuilder();
  LevelSetBuilder(const LevelSetBuilder&) = delete;
  LevelSetBuilder& operator=(const LevelSetBuilder&) = delete;
  // Before the leaves they cover (a tile overwrites what it covers): a tile below the end in x
  // of the leaves added so far is std::logic_error.
  void addTiles(const std::vector<Tile>& tiles);
  // A leaf below (in x) a leaf of an earlier call is std::logic_error (its place was pruned).
  void addLeaves(const std::vector<LeafBlock>& leaves);
  uint64_t leaves() const { return leaves_; }  // added so far
  uint64_t leavesWrittenOut() const;           // spillLeaves: the tree's leaves in the temporary file so far
  // Once, at the end; throws Error(kExitIoError) as writeLevelSet does.
  void write(const std::string& path, const VdbMetadata& meta);

 private:
  std::unique_ptr<detail::LevelSetTree> tree_;  // the OpenVDB grid being built (vdb_writer.cpp)
  uint64_t leaves_ = 0;
  int64_t leavesEndX_ = 0;  // past the largest x of the leaves added (addTiles' check)
};

}  // namespace frep::io
