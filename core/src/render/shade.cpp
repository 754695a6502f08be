// Lambert shading of a depth image (see shade.h).
#include "frep/render/shade.h"

#include <algorithm>
#include <cmath>

namespace frep {
namespace {

using vec3::dot;

uint8_t toByte(double x) { return uint8_t(std::lround(std::clamp(x, 0.0, 1.0) * 255.0)); }

}  // namespace

std::vector<uint8_t> shadeImage(const DepthImage& img, const Camera& cam, const ShadeOptions& opt) {
  std::vector<uint8_t> rgb(size_t(img.width) * size_t(img.height) * 3);
  // Key light: up and to the left of the eye, a little behind it (in the view frame).
  Vec3 key;
  for (int i = 0; i < 3; ++i) key[size_t(i)] = 0.6 * cam.up[size_t(i)] - 0.45 * cam.right[size_t(i)] - 0.66 * cam.forward[size_t(i)];
  const double kn = std::sqrt(dot(key, key));
  for (double& k : key) k /= kn;
  for (int r = 0; r < img.height; ++r)
    for (int c = 0; c < img.width; ++c) {
      const RayHit& h = img.at(c, r);
      uint8_t* out = &rgb[(size_t(r) * size_t(img.width) + size_t(c)) * 3];
      if (h.kind == RayHit::kNone) {
        std::copy(opt.background.begin(), opt.background.end(), out);
        continue;
      }
      Vec3 toEye;  // unit vector from the hit to the eye
      if (cam.perspective) {
        for (int i = 0; i < 3; ++i) toEye[size_t(i)] = cam.eye[size_t(i)] - h.point[size_t(i)];
        const double n = std::sqrt(dot(toEye, toEye));
        for (double& t : toEye) t = n > 0 ? t / n : 0;
      } else {
        for (int i = 0; i < 3; ++i) toEye[size_t(i)] = -cam.forward[size_t(i)];
      }
      Vec3 n = h.normal;
      if (dot(n, n) == 0) n = toEye;      // no gradient there: face the viewer
      if (dot(n, toEye) < 0) n = {-n[0], -n[1], -n[2]};  // seen from inside (near plane cut)
      const double light = opt.ambient + opt.headlight * std::max(0.0, dot(n, toEye)) +
                           opt.key * std::max(0.0, dot(n, key));
      const std::array<double, 3> albedo = opt.colourAt ? opt.colourAt(h) : opt.colour;
      for (int i = 0; i < 3; ++i) {
        double value = albedo[size_t(i)] * light;
        if (h.kind == RayHit::kFootprint) value = 0.5 * value + 0.5 * opt.background[size_t(i)] / 255.0;
        out[i] = toByte(value);
      }
    }
  return rgb;
}

}  // namespace frep
