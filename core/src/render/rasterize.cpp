// Z-buffer rasterisation of a mesh (see rasterize.h). Triangles are projected to the image plane
// (u, v) with view depth d; a pixel centre inside the projected triangle (edge functions, edges
// included) gets the depth of the plane there: linear in (u, v) for orthographic views, and for
// perspective views 1/d is linear in (u, v).
#include "frep/render/rasterize.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace frep {
namespace {

using vec3::dot;

}  // namespace

DepthImage rasterize(const Mesh& mesh, const Camera& cam, const RenderOptions& opt) {
  if (opt.width <= 0 || opt.height <= 0) throw std::invalid_argument("render: the image size must be positive");
  if (!(opt.farDepth > opt.nearDepth) || !std::isfinite(opt.nearDepth) || !std::isfinite(opt.farDepth))
    throw std::invalid_argument("render: the depth range must be finite and non-empty");
  if (!(cam.halfWidth > 0) || !std::isfinite(cam.halfWidth)) throw std::invalid_argument("render: the view width must be positive");
  DepthImage img;
  img.width = opt.width, img.height = opt.height;
  img.pixelStep = 2.0 * cam.halfWidth / opt.width;
  img.hits.assign(size_t(opt.width) * size_t(opt.height), RayHit{});
  const double step = img.pixelStep;
  for (const auto& t : mesh.triangles) {
    double u[3], v[3], d[3];
    bool behind = false;
    for (int k = 0; k < 3; ++k) {
      const auto& p = mesh.positions[t[size_t(k)]];
      const Vec3 rel{p[0] - cam.eye[0], p[1] - cam.eye[1], p[2] - cam.eye[2]};
      d[k] = dot(rel, cam.forward);
      u[k] = dot(rel, cam.right), v[k] = dot(rel, cam.up);
      if (cam.perspective) {
        behind = behind || !(d[k] > opt.nearDepth);
        u[k] /= d[k], v[k] /= d[k];
      }
    }
    if (behind) continue;
    const double area = (u[1] - u[0]) * (v[2] - v[0]) - (u[2] - u[0]) * (v[1] - v[0]);
    if (area == 0 || !std::isfinite(area)) continue;  // seen edge-on: covers no pixel centre
    // Pixel columns and rows whose centres may fall inside.
    const double umin = std::min({u[0], u[1], u[2]}), umax = std::max({u[0], u[1], u[2]});
    const double vmin = std::min({v[0], v[1], v[2]}), vmax = std::max({v[0], v[1], v[2]});
    const int c0 = std::max(0, int(std::ceil(umin / step + 0.5 * (opt.width - 1))));
    const int c1 = std::min(opt.width - 1, int(std::floor(umax / step + 0.5 * (opt.width - 1))));
    const int r0 = std::max(0, int(std::ceil(0.5 * (opt.height - 1) - vmax / step)));
    const int r1 = std::min(opt.height - 1, int(std::floor(0.5 * (opt.height - 1) - vmin / step)));
    Vec3 n;
    {
      const auto &a = mesh.positions[t[0]], &b = mesh.positions[t[1]], &c = mesh.positions[t[2]];
      const Vec3 e1{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
      n = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
      const double len = std::sqrt(dot(n, n));
      n = len > 0 ? Vec3{n[0] / len, n[1] / len, n[2] / len} : Vec3{0, 0, 0};
    }
    for (int r = r0; r <= r1; ++r)
      for (int c = c0; c <= c1; ++c) {
        const double pu = pixelU(cam, opt.width, c), pv = pixelV(cam, opt.width, opt.height, r);
        // Barycentric weights of the pixel centre (edges included).
        const double w0 = ((u[1] - pu) * (v[2] - pv) - (u[2] - pu) * (v[1] - pv)) / area;
        const double w1 = ((u[2] - pu) * (v[0] - pv) - (u[0] - pu) * (v[2] - pv)) / area;
        const double w2 = 1.0 - w0 - w1;
        if (w0 < 0 || w1 < 0 || w2 < 0) continue;
        const double depth = cam.perspective ? 1.0 / (w0 / d[0] + w1 / d[1] + w2 / d[2]) : w0 * d[0] + w1 * d[1] + w2 * d[2];
        if (!(depth >= opt.nearDepth && depth <= opt.farDepth)) continue;
        RayHit& h = img.hits[size_t(r) * size_t(opt.width) + size_t(c)];
        if (h.kind != RayHit::kNone && !(depth < h.depth)) continue;
        h.kind = RayHit::kCentre;
        h.depth = depth;
        for (int i = 0; i < 3; ++i)
          h.point[size_t(i)] = cam.perspective
                                   ? cam.eye[size_t(i)] + depth * (cam.forward[size_t(i)] + pu * cam.right[size_t(i)] + pv * cam.up[size_t(i)])
                                   : cam.eye[size_t(i)] + pu * cam.right[size_t(i)] + pv * cam.up[size_t(i)] + depth * cam.forward[size_t(i)];
        h.normal = n;
      }
  }
  return img;
}

}  // namespace frep
