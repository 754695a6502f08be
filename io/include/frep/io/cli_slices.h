// Layer slices of a closed mesh in the Common Layer Interface format (CLI, version 2.0; the
// format of hfp's -cli with -gs), for layer-based manufacturing. Each layer is the mesh's cross
// section at the middle of the layer, written as closed polylines: counter-clockwise (direction
// 1) around material, clockwise (0) around holes, seen from +z; open polylines (2) where the
// mesh is open (a surface cut by the box).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "frep/meshing/mesh.h"

namespace frep::io {

struct SliceContour {
  std::vector<std::array<double, 2>> points;  // closed contours repeat their first point at the end
  int direction = 1;                           // 0 clockwise (hole), 1 counter-clockwise, 2 open
};

struct SliceLayer {
  double top = 0;   // the layer's upper height ($$LAYER value)
  double cut = 0;   // where it was cut: top - thickness/2
  std::vector<SliceContour> contours;
};

// Layers of `thickness` from zMin up to zMax (the last whole layer below zMax). Deterministic:
// contours start at their smallest crossing edge and are sorted by it.
std::vector<SliceLayer> sliceMesh(const Mesh& mesh, double zMin, double zMax, double thickness);

struct CliOptions {
  bool binary = false;  // $$BINARY with long-form commands (127 layer, 130 polyline), else $$ASCII
  double units = 1.0;   // $$UNITS: millimetres per model unit
  std::array<double, 6> dimension{};  // $$DIMENSION x1,y1,z1,x2,y2,z2 (the box)
  std::string label;    // $$LABEL text (the object name)
};

// Writes the layers to `path` (the caller's temporary file). Throws Error(kExitIoError).
void writeCli(const std::string& path, const std::vector<SliceLayer>& layers, const CliOptions& options);

}  // namespace frep::io
