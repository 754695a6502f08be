// Geometry files as model operands (frMesh, frVolume in docs/language.md): built once per process
// and cached by the content hash of their bytes, so a farm worker builds a mesh's hierarchy once
// for all the bricks and jobs that use it. The bytes come from the model's compilation (the disk
// next to the model, or the job's model_files on a worker: docs/farm.md). installGeometryLoader()
// makes the HyperFun front end use these readers (lang does not link OpenVDB).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "frep/geometry/field.h"

namespace frep::io {

struct LoadedGeometry {
  std::shared_ptr<const DistanceField> field;
  uint64_t fileHash = 0;              // FNV-1a of the file's bytes (the cache key)
  std::vector<std::string> warnings;  // e.g. a mesh's open edges and how its sign is then defined
};

// kind "mesh" (.stl/.obj/.ply: the signed distance to the triangles) or "volume" (.vdb: the grid
// named `grid`, "" for the file's first float grid), from the file's bytes; `path` (as written in
// the model) gives a mesh's format by its extension and names the file in messages. Throws Error
// naming the file.
LoadedGeometry loadGeometry(const std::string& path, const std::string& bytes, const std::string& kind,
                            const std::string& grid);
// The same, reading the file from disk.
LoadedGeometry loadGeometryFile(const std::string& path, const std::string& kind, const std::string& grid);

// A .vdb grid as a field (volume_field.cpp, the OpenVDB translation unit), from the file's bytes:
// trilinear interpolation of f = -value for level sets and frep sample's files (negative inside),
// of f = value - 0.5 for fog volumes; outside the active band the tree's tile or background value
// is used, so beyond the grid's extent f = -background (outside). Lipschitz bound from the
// largest voxel-to-voxel difference next to the active voxels.
std::shared_ptr<const DistanceField> readVolumeField(const std::string& path, const std::string& bytes,
                                                     const std::string& grid, uint64_t fileHash);

// lang::setFileFieldLoader(loadGeometry): call once in main() of programs that compile models.
void installGeometryLoader();

// 64-bit FNV-1a of bytes (the model files' hash: the farm's jobs carry it, workers check it).
uint64_t contentHash(const std::string& bytes);

}  // namespace frep::io
