// Z-buffer drawing of a triangle mesh into a depth image with castRays' cameras and pixel
// centres (frep render of .ply/.obj/.stl meshes and of sampled .vdb grids). Each pixel centre's
// ray takes the nearest triangle it meets within the depth range: depth, point, and the
// triangle's geometric normal by its winding (outward for frepfarm's meshes). Triangles are
// drawn in order and only a strictly nearer one replaces a hit: the image is deterministic.
#pragma once

#include "frep/meshing/mesh.h"
#include "frep/render/raycast.h"

namespace frep {

// Throws std::invalid_argument for a bad size, view or depth range. Perspective triangles that
// reach the eye's side of nearDepth are left out (the fitted views keep the mesh in front).
DepthImage rasterize(const Mesh& mesh, const Camera& camera, const RenderOptions& options);

}  // namespace frep
