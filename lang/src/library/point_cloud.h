// Scattered points for volume splines: `x y z value` / `x y z nx ny nz` text and PLY point
// clouds (ascii or binary little-endian; vertex x, y, z with optional nx, ny, nz and value).
#pragma once

#include <array>
#include <stdexcept>
#include <string>
#include <vector>

namespace frep::lang {

struct PointCloud {
  std::vector<std::array<double, 3>> points, normals;  // normals empty when the file has none
  std::vector<double> values;                          // empty when the file has none
};

// Throws std::runtime_error naming `name` and the line (text) or vertex (PLY) at fault.
PointCloud parsePointCloud(const std::string& contents, const std::string& name);

}  // namespace frep::lang
