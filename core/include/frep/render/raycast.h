// Certified ray casting of an F-rep solid (f >= 0 inside) into a depth + normal image.
//
// Interval ray casting (Vyatkin-Perturbation, interval ray tracing; Pasko-Survey, ray tracing):
// the model is composed with the camera map (u, v, d) -> X, so a tile of pixels times a depth
// slab is an axis-aligned box in (u, v, d) and one interval evaluation bounds f over every ray
// segment in it. Orthographic: X = eye + u right + v up + d forward (affine). Perspective:
// X = eye + d (forward + u right + v up), u and v in tangent units; the products d*u, d*v are
// evaluated as interval products, a sound enclosure of the frustum slab. Slabs are classified
// front to back with tape pruning (as frep/sampling/plane.h), split down to single pixels, then
// each pixel's centre ray is searched by 1D interval bisection on depth and its root refined by
// point bisection; nothing the intervals cannot exclude is skipped, so a surface the centre ray
// crosses is found however thin it is. Where the centre ray finds nothing, the pixel's whole
// footprint (its square of rays) is searched too: a feature thinner than a pixel between two
// pixel centres is reported as a sub-pixel hit (RayHit::kFootprint).
//
// The image is cut into fixed kRenderTile-pixel tiles independent of the thread count, and every
// pixel's result depends only on its tile's subdivision, so the output is identical for any
// thread count and for any split of the image into regions of whole tiles (the farm's bricks).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "frep/expressions/expr.h"
#include "frep/expressions/tape.h"
#include "frep/geometry/vec3.h"
#include "frep/interrupt/interrupter.h"

namespace frep {

struct Camera {
  Vec3 eye{0, 0, 0};
  Vec3 right{1, 0, 0}, up{0, 0, 1}, forward{0, 1, 0};  // orthonormal, right-handed view frame
  bool perspective = false;
  // Half the image width on the image plane: model units (orthographic) or tan(fov/2)
  // (perspective). Pixels are square; the height follows from the aspect ratio.
  double halfWidth = 1.0;
};

// Camera on a sphere around target: azimuth from +x towards +y, elevation above the xy plane
// (degrees), z up. halfWidth as in Camera.
Camera orbitCamera(const Vec3& target, double azimuthDeg, double elevationDeg, double distance, bool perspective,
                   double halfWidth);
// Camera at eye looking at target, with `upHint` giving the image's up direction (z if zero).
// Throws std::invalid_argument if eye == target or the view is parallel to upHint.
Camera lookAtCamera(const Vec3& eye, const Vec3& target, const Vec3& upHint, bool perspective, double halfWidth);

struct RayHit {
  enum Kind : uint8_t { kNone = 0, kCentre = 1, kFootprint = 2 };
  Kind kind = kNone;
  double depth = 0.0;   // d of the hit (orthographic: distance from the eye plane)
  Vec3 point{0, 0, 0};  // model coordinates of the hit
  Vec3 normal{0, 0, 0}; // outward unit normal, -grad f / |grad f| (zero if the gradient is)
};

struct RenderOptions {
  int width = 256, height = 256;
  double nearDepth = 0.0, farDepth = 1.0;  // depth range searched (d in Camera's frame)
  int threads = 0;                          // 0: TBB's default, 1: serial
  bool footprint = true;                    // search pixel footprints where the centre ray misses
  // Cancel and progress ("render": tiles done of total); null: the caller's.
  const Interrupter* interrupt = nullptr;
};

struct RenderStats {
  uint64_t intervalEvals = 0, pointEvals = 0;
};

struct DepthImage {
  int width = 0, height = 0;
  double pixelStep = 0.0;     // pixel spacing on the image plane (model units or tangent units)
  std::vector<RayHit> hits;   // row-major from the top row
  const RayHit& at(int col, int row) const { return hits[size_t(row) * size_t(width) + size_t(col)]; }
};

// Image-plane coordinate of a pixel centre (col from the left, row from the top).
double pixelU(const Camera& cam, int width, int col);
double pixelV(const Camera& cam, int width, int height, int row);

// The image's tile edge in pixels: castRegion's regions are made of whole tiles.
constexpr int kRenderTile = 32;

// Pixels [c0, c1) x [r0, r1) of the image (columns from the left, rows from the top).
struct PixelRegion {
  int c0 = 0, r0 = 0, c1 = 0, r1 = 0;
};
// Whether the region lies in a width x height image and is made of whole tiles: c0, r0
// multiples of kRenderTile, c1, r1 multiples of it or the image's edge.
bool isTileRegion(const PixelRegion& region, int width, int height);

// The tape castRegion casts: `field` (x, y, z = vars 0..2, further vars fixed to `fixed`)
// composed with the camera map, over (u, v, d).
TapePtr viewTape(const Expr& field, const Camera& camera, const std::vector<double>& fixed = {});

// The hits of the region's pixels (row-major within the region), exactly as castRays finds them
// for the whole image. Throws std::invalid_argument for a bad view or a region not of whole tiles.
std::vector<RayHit> castRegion(const TapePtr& view, const Camera& camera, const RenderOptions& options,
                               const PixelRegion& region, RenderStats* stats = nullptr);

// Casts every pixel's ray against `field` (coordinates x, y, z = vars 0..2; further vars get
// `fixed` values in order). Throws std::invalid_argument for a bad size or depth range.
DepthImage castRays(const Expr& field, const Camera& camera, const RenderOptions& options,
                    const std::vector<double>& fixed = {}, RenderStats* stats = nullptr);

// A box enclosing the solid's part of [lo, hi], by octree interval subdivision (`levels`
// halvings per axis): cells the interval proves outside are dropped. Returns false when the
// solid has no point in the box.
bool solidBounds(const Expr& field, const Vec3& lo, const Vec3& hi, int levels, Vec3& outLo, Vec3& outHi,
                 const std::vector<double>& fixed = {});

}  // namespace frep
