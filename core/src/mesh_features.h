// Sharp-feature vertices for the Kuhn mesher (mesh.cpp; see MeshOptions::sharpFeatures).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "frep/mesh.h"

namespace frep {

struct FeatureContext {
  const GridSpec& grid;
  const Tape& tape;
  const std::vector<double>& fixedCoords;
  double featureCos;
};

// Replaces, cell by cell, the patch of a feature cell by a fan around a QEF vertex where that is
// valid (see mesh_features.cpp). verts stay sorted by key; tris are re-indexed. Returns the
// number of cells changed. Depends only on each cell's own vertices, so it is split-invariant.
uint64_t placeFeatureVertices(const FeatureContext& ctx, std::vector<MeshVertex>& verts,
                              std::vector<std::array<uint32_t, 3>>& tris);

}  // namespace frep
