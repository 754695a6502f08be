// Shading of a cast depth image (raycast.h) into 8-bit RGB: Lambert with a headlight (from the
// eye) and a key light (above, left, behind the eye) plus a little ambient. Pixels hit only in
// their footprint (a sub-pixel feature) are blended half with the background, so thin features
// show and silhouettes are lightly smoothed. A pure function of the depth image: deterministic.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "frep/render/raycast.h"

namespace frep {

struct ShadeOptions {
  std::array<uint8_t, 3> background{255, 255, 255};
  std::array<double, 3> colour{0.80, 0.62, 0.38};  // surface albedo, 0..1
  // Per-hit albedo (0..1) instead of `colour`, from the hit's model point: the section of a
  // geometric type C/G model, and later the model's attributes (HyperFun s[], hfA_*). Called
  // once per hit pixel, in pixel order; it must be a pure function of the hit for the picture
  // to stay deterministic.
  std::function<std::array<double, 3>(const RayHit&)> colourAt;
  double ambient = 0.12, headlight = 0.55, key = 0.45;
};

// width * height * 3 bytes, row-major from the top row.
std::vector<uint8_t> shadeImage(const DepthImage& image, const Camera& camera, const ShadeOptions& options = {});

}  // namespace frep
