// Sampler output -> OpenVDB level set file. This header does not include OpenVDB (its headers
// take ~25 s to compile); vdb_writer.cpp does, and vdb_grid.h exposes the grid it builds.
#pragma once

#include <cstdint>
#include <string>

#include "frep/sampling/sample.h"

namespace frep::io {

struct VdbMetadata {
  std::string gridName;     // the object's name
  std::string commandLine;  // as typed
  std::string params;       // -a as given ("" = none)
  uint64_t sourceHash = 0;  // lang::Model::sourceHash
  double iso = 0.0;
};

// Writes one FloatGrid of class level set holding -f (negative inside, as OpenVDB expects):
// leaf voxels from the sampler (active in the band), tiles and the background at ±band*voxel,
// the grid's transform (voxel size, translated to the grid origin) and metadata (frep_sign =
// "value = -f", frep_operation, frep_model_hash, frep_object, frep_command, frep_band_voxels,
// frep_band, frep_iso, frep_params, frep_version). Throws Error(kExitIoError).
void writeLevelSet(const std::string& path, const SampleResult& result, const VdbMetadata& meta);

}  // namespace frep::io
