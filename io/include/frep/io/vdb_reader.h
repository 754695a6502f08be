// Reading back a FloatGrid written by `frep sample` (or any float level set: negative inside) as
// sampled values for the core's meshSamples (frep mesh input.vdb). OpenVDB stays inside
// vdb_reader.cpp.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "frep/meshing/mesh.h"
#include "frep/sampling/sample.h"

namespace frep::io {

struct SampledVdb {
  std::string gridName;
  // The grid's leaves with values in F-rep sign (f = -stored value, exactly), active masks as
  // stored, and 8^3 sign tiles for the blocks next to the leaves (from tiles or the background).
  // Index coordinates are shifted so that every leaf origin is >= 0 (no shift for frep sample's
  // files, whose index (0,0,0) is the box's minimum corner); grid.dims covers every leaf.
  SampleResult samples;
  // Empty when samples.grid (origin + index * voxel) already is the grid's transform (a uniform
  // scale and a translation, as frep sample writes); otherwise samples.grid is the (shifted)
  // index space and this maps a mesh to world coordinates (positions by the transform, normals
  // by its inverse transpose, the winding reversed by a mirroring transform).
  std::function<void(Mesh&)> toWorld;
  std::string transformDescription;  // e.g. "voxel 0.03 at (-1.1, -1.1, -1.1)"
  // FNV-1a 64 of every byte of the file but the header's UUID (16 hex digits): the file's content,
  // whatever its path is spelt (provenance in frep mesh's outputs). The UUID is left out, as
  // OpenVDB stamps a random one into every file it writes.
  std::string contentHash;
};

// Throws Error: kExitIoError when the file cannot be opened or read (missing, not a VDB file,
// truncated or corrupt), kExitModelError when it has no usable grid (no float grid; no grid
// named `gridName`, if given; the grid's type is not float). Messages name the file and list its
// grids.
SampledVdb readSampledVdb(const std::string& path, const std::string& gridName);

}  // namespace frep::io
