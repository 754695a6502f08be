// The sampler's output as an in-memory OpenVDB grid: the one conversion that frep sample writes
// (vdb_writer.cpp) and that bench_mesh hands to openvdb::tools::volumeToMesh. This header
// includes OpenVDB: include it only where OpenVDB is needed (its headers compile slowly).
#pragma once

#include <openvdb/openvdb.h>

#include "frep/sampling/sample.h"

namespace frep::io {

// One FloatGrid of class level set holding -f (negative inside): the sampler's leaf voxels
// (active in the band), tiles and the background at +-band * voxel, pruned to the canonical
// tree, on the world lattice (a pure scale transform; the sampler's index shifted by its
// origin / voxel). No name and no metadata (writeLevelSet adds them). Calls openvdb::initialize().
openvdb::FloatGrid::Ptr levelSetGrid(const SampleResult& result);

// The true signed distance (class level set, band of bandVoxels either side) to the zero set
// of `raw` (a levelSetGrid), by tools::levelSetRebuild on the same transform.
openvdb::FloatGrid::Ptr signedDistanceGrid(const openvdb::FloatGrid& raw, int bandVoxels);

}  // namespace frep::io
