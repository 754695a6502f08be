// Certified ray casting (frep/render): exact answers from spheres and plates.
#include <gtest/gtest.h>

#include <cmath>

#include "frep/render/rasterize.h"
#include "frep/render/raycast.h"
#include "frep/render/shade.h"

namespace frep {
namespace {

Expr sphere(double r) {
  const Expr x = Expr::x(0), y = Expr::x(1), z = Expr::x(2);
  return r * r - x * x - y * y - z * z;
}

RenderOptions options(int w, int h, double nearD, double farD, int threads = 1) {
  RenderOptions o;
  o.width = w, o.height = h, o.nearDepth = nearD, o.farDepth = farD, o.threads = threads;
  return o;
}

size_t countKind(const DepthImage& img, RayHit::Kind kind) {
  size_t n = 0;
  for (const RayHit& h : img.hits) n += h.kind == kind;
  return n;
}

TEST(Render, SphereSilhouetteMatchesTheAnalyticDisc) {
  const double R = 1.0;
  for (bool perspective : {false, true}) {
    const double D = 4.0;
    // Perspective: the silhouette is the cone tangent to the sphere, tan = R / sqrt(D^2 - R^2).
    const double discRadius = perspective ? R / std::sqrt(D * D - R * R) : R;
    Camera cam = orbitCamera({0, 0, 0}, -90, 0, D, perspective, 1.3 * discRadius);
    const int W = 301, H = 301;
    DepthImage img = castRays(sphere(R), cam, options(W, H, 0.5, 8.0));
    size_t lattice = 0;  // pixel centres strictly inside the disc
    for (int r = 0; r < H; ++r)
      for (int c = 0; c < W; ++c) {
        const double u = pixelU(cam, W, c), v = pixelV(cam, W, H, r);
        lattice += u * u + v * v < discRadius * discRadius;
      }
    const size_t hits = countKind(img, RayHit::kCentre);
    const double area = M_PI * discRadius * discRadius / (img.pixelStep * img.pixelStep);
    EXPECT_NEAR(double(hits), area, 0.005 * area) << "perspective " << perspective;
    EXPECT_NEAR(double(hits), double(lattice), 0.0005 * double(lattice)) << "perspective " << perspective;
    // Depth at the centre pixel: the analytic distance D - R, to half a pixel footprint (the
    // caster's root is far tighter; check that too).
    const RayHit& mid = img.at(W / 2, H / 2);
    ASSERT_EQ(mid.kind, RayHit::kCentre);
    const double footprint = perspective ? (D - R) * img.pixelStep : img.pixelStep;
    EXPECT_NEAR(mid.depth, D - R, 0.5 * footprint);
    EXPECT_NEAR(mid.depth, D - R, 1e-3 * footprint);
    EXPECT_NEAR(mid.normal[1], -1.0, 1e-9);
  }
}

// Every centre hit lies on the sphere, with the sphere's normal.
TEST(Render, HitsLieOnTheSurface) {
  Camera cam = orbitCamera({0, 0, 0}, 30, 20, 5, true, 0.3);
  DepthImage img = castRays(sphere(1.0), cam, options(64, 48, 1.0, 9.0));
  size_t n = 0;
  for (const RayHit& h : img.hits) {
    if (h.kind != RayHit::kCentre) continue;
    ++n;
    const double r = std::sqrt(h.point[0] * h.point[0] + h.point[1] * h.point[1] + h.point[2] * h.point[2]);
    const double footprint = h.depth * img.pixelStep;
    EXPECT_NEAR(r, 1.0, footprint * 0.05);  // grazing rays: a depth error of 1e-4 footprints along the ray
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(h.normal[size_t(i)], h.point[size_t(i)] / r, 1e-6);
  }
  EXPECT_GT(n, 1000u);
}

// A plate 0.1 pixel thick seen edge-on, placed between two rows of pixel centres: no centre ray
// meets it, so a point-sampling caster shows nothing; the footprint search finds it in every
// column it spans.
TEST(Render, PlateThinnerThanAPixelSeenEdgeOnIsNotMissed) {
  const int W = 64, H = 64;
  Camera cam = orbitCamera({0, 0, 0}, -90, 0, 4, false, 1.0);
  const double step = 2.0 / W;
  const double z0 = pixelV(cam, W, H, 20) - 0.5 * step;  // between rows 20 and 21
  const Expr x = Expr::x(0), z = Expr::x(2), y = Expr::x(1);
  const Expr plate = min(min(0.05 * step - abs(z - z0), 0.5 - abs(x)), 0.5 - abs(y));
  DepthImage img = castRays(plate, cam, options(W, H, 1.0, 7.0));
  EXPECT_EQ(countKind(img, RayHit::kCentre), 0u);
  for (int c = 0; c < W; ++c) {
    const double u = pixelU(cam, W, c);
    if (std::abs(u) > 0.5 + step) continue;
    bool seen = false;
    for (int r = 0; r < H; ++r) {
      const RayHit& h = img.at(c, r);
      if (h.kind == RayHit::kNone) continue;
      EXPECT_TRUE(r == 20 || r == 21) << "row " << r;
      EXPECT_NEAR(h.depth, 3.5, 0.5 * step);
      seen = true;
    }
    EXPECT_TRUE(seen) << "column " << c;
  }
  // Centre rays alone see nothing: the footprint search is what finds the plate.
  RenderOptions centreOnly = options(W, H, 1.0, 7.0);
  centreOnly.footprint = false;
  EXPECT_EQ(countKind(castRays(plate, cam, centreOnly), RayHit::kNone), size_t(W) * H);
}

// The same through a perspective frustum: a rod 0.1 pixel footprint thick (at its depth)
// between two columns of pixel centres.
TEST(Render, RodThinnerThanAPixelInPerspectiveIsNotMissed) {
  const int W = 64, H = 48;
  Camera cam = orbitCamera({0, 0, 0}, -90, 0, 4, true, 0.25);
  const double step = 2 * 0.25 / W;            // tangent units
  const double x0 = 4 * (pixelU(cam, W, 40) + 0.5 * step);  // between columns 40 and 41 at depth 4
  const Expr x = Expr::x(0), y = Expr::x(1), z = Expr::x(2);
  const Expr dx = x - x0;
  const Expr rod = min(square(0.05 * 4 * step) - dx * dx - y * y, 0.5 - abs(z));
  DepthImage img = castRays(rod, cam, options(W, H, 1.0, 8.0));
  EXPECT_EQ(countKind(img, RayHit::kCentre), 0u);
  for (int r = 0; r < H; ++r) {
    if (std::abs(pixelV(cam, W, H, r)) * 4 > 0.45) continue;
    EXPECT_TRUE(img.at(40, r).kind == RayHit::kFootprint || img.at(41, r).kind == RayHit::kFootprint) << "row " << r;
  }
}

// A plate 0.01 pixel thick seen face-on: every centre ray crosses it within a distance far
// shorter than any marching step; the interval search finds each crossing.
TEST(Render, PlateThinnerThanAPixelSeenFaceOnIsHitEverywhere) {
  const int W = 48, H = 48;
  Camera cam = orbitCamera({0, 0, 0}, -90, 0, 4, false, 1.0);
  const double step = 2.0 / W;
  const Expr x = Expr::x(0), y = Expr::x(1), z = Expr::x(2);
  const Expr plate = min(min(0.005 * step - abs(y - 0.1234), 0.6 - abs(x)), 0.6 - abs(z));
  DepthImage img = castRays(plate, cam, options(W, H, 0.0, 8.0));
  for (int r = 0; r < H; ++r)
    for (int c = 0; c < W; ++c) {
      const double u = pixelU(cam, W, c), v = pixelV(cam, W, H, r);
      if (std::abs(u) > 0.6 - step || std::abs(v) > 0.6 - step) continue;
      const RayHit& h = img.at(c, r);
      ASSERT_EQ(h.kind, RayHit::kCentre) << c << "," << r;
      EXPECT_NEAR(h.depth, 4.0 + 0.1234 - 0.005 * step, 0.5 * step * 0.05);
    }
}

TEST(Render, IdenticalForAnyThreadCount) {
  const Expr x = Expr::x(0), y = Expr::x(1), z = Expr::x(2);
  const Expr model = max(sphere(1.0), min(0.3 - abs(z), 1.4 - x * x - y * y));
  Camera cam = orbitCamera({0, 0, 0}, -50, 30, 5, true, 0.35);
  ShadeOptions shade;
  DepthImage one = castRays(model, cam, options(150, 100, 1.0, 10.0, 1));
  const std::vector<uint8_t> ref = shadeImage(one, cam, shade);
  for (int threads : {2, 3, 0}) {
    DepthImage many = castRays(model, cam, options(150, 100, 1.0, 10.0, threads));
    ASSERT_EQ(many.hits.size(), one.hits.size());
    for (size_t i = 0; i < one.hits.size(); ++i) {
      ASSERT_EQ(many.hits[i].kind, one.hits[i].kind);
      ASSERT_EQ(many.hits[i].depth, one.hits[i].depth);
    }
    EXPECT_EQ(shadeImage(many, cam, shade), ref) << threads << " threads";
  }
}

// Regions of whole tiles (the farm's bricks) give exactly the whole image's hits, for any split;
// a region that cuts a tile is refused.
TEST(Render, RegionsOfWholeTilesGiveTheWholeImage) {
  const Expr x = Expr::x(0), y = Expr::x(1), z = Expr::x(2);
  const Expr model = max(sphere(1.0), min(0.3 - abs(z), 1.4 - x * x - y * y));
  Camera cam = orbitCamera({0, 0, 0}, -50, 30, 5, true, 0.35);
  const RenderOptions opt = options(150, 100, 1.0, 10.0, 1);
  const DepthImage whole = castRays(model, cam, opt);
  const TapePtr view = viewTape(model, cam);
  for (int tile : {32, 64, 96}) {
    for (int r0 = 0; r0 < opt.height; r0 += tile)
      for (int c0 = 0; c0 < opt.width; c0 += tile) {
        const PixelRegion g{c0, r0, std::min(c0 + tile, opt.width), std::min(r0 + tile, opt.height)};
        const std::vector<RayHit> hits = castRegion(view, cam, opt, g);
        for (int r = g.r0; r < g.r1; ++r)
          for (int c = g.c0; c < g.c1; ++c) {
            const RayHit& a = hits[size_t(r - g.r0) * size_t(g.c1 - g.c0) + size_t(c - g.c0)];
            const RayHit& b = whole.at(c, r);
            ASSERT_EQ(a.kind, b.kind) << c << "," << r;
            ASSERT_EQ(a.depth, b.depth);
            ASSERT_EQ(a.normal, b.normal);
          }
      }
  }
  EXPECT_THROW(castRegion(view, cam, opt, PixelRegion{16, 0, 48, 32}), std::invalid_argument);
  EXPECT_THROW(castRegion(view, cam, opt, PixelRegion{0, 0, 40, 32}), std::invalid_argument);
  EXPECT_THROW(castRegion(view, cam, opt, PixelRegion{128, 96, 160, 100}), std::invalid_argument);
}

// The z-buffer on a unit cube of 12 outward triangles, seen along +y: the pixels are exactly
// the centres inside the square (none lies on an edge), the depth is the front face's and the
// normal its outward one; perspective: the near face's square seen from distance 3.5.
TEST(Render, RasterizedCubeIsTheExactSquare) {
  Mesh cube;
  for (int k = 0; k < 8; ++k) cube.positions.push_back({k & 1 ? 0.5 : -0.5, k & 2 ? 0.5 : -0.5, k & 4 ? 0.5 : -0.5});
  // Faces as corner quads, counter-clockwise seen from outside.
  const uint32_t quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& q : quads) cube.triangles.push_back({q[0], q[1], q[2]}), cube.triangles.push_back({q[0], q[2], q[3]});
  for (bool perspective : {false, true}) {
    const Camera cam = orbitCamera({0, 0, 0}, -90, 0, 4, perspective, perspective ? 0.3 : 1.0);
    const int W = 64, H = 48;
    const DepthImage img = rasterize(cube, cam, options(W, H, 1.0, 8.0));
    const double half = perspective ? 0.5 / 3.5 : 0.5;  // the front face's square on the image plane
    size_t inside = 0, hits = 0;
    for (int r = 0; r < H; ++r)
      for (int c = 0; c < W; ++c) {
        const double u = pixelU(cam, W, c), v = pixelV(cam, W, H, r);
        const bool in = std::abs(u) < half && std::abs(v) < half;
        inside += in;
        const RayHit& h = img.at(c, r);
        hits += h.kind == RayHit::kCentre;
        ASSERT_EQ(h.kind == RayHit::kCentre, in) << c << "," << r << " perspective " << perspective;
        if (!in) continue;
        EXPECT_NEAR(h.point[1], -0.5, 1e-12);
        EXPECT_EQ(h.normal, (Vec3{0, -1, 0}));
      }
    EXPECT_GT(inside, 100u);
    EXPECT_EQ(hits, inside);
    EXPECT_NEAR(img.at(W / 2, H / 2).depth, 3.5, 1e-12);
  }
}

// The shaded bytes of a sphere against the same Lambert formula evaluated on the analytic hit
// point and normal of each pixel's centre ray (orthographic, view along +y).
TEST(Render, ShadedSphereMatchesTheAnalyticImage) {
  const int W = 40, H = 30;
  Camera cam = orbitCamera({0, 0, 0}, -90, 0, 3, false, 1.25);
  ShadeOptions shade;
  shade.background = {10, 20, 30};
  DepthImage img = castRays(sphere(1.0), cam, options(W, H, 0.5, 6.0));
  const std::vector<uint8_t> rgb = shadeImage(img, cam, shade);
  Vec3 key;
  for (int i = 0; i < 3; ++i) key[size_t(i)] = 0.6 * cam.up[size_t(i)] - 0.45 * cam.right[size_t(i)] - 0.66 * cam.forward[size_t(i)];
  const double kn = std::sqrt(key[0] * key[0] + key[1] * key[1] + key[2] * key[2]);
  size_t inside = 0, background = 0;
  for (int r = 0; r < H; ++r)
    for (int c = 0; c < W; ++c) {
      const double u = pixelU(cam, W, c), v = pixelV(cam, W, H, r), s = u * u + v * v;
      const uint8_t* px = &rgb[(size_t(r) * W + size_t(c)) * 3];
      if (s < 0.97) {  // clearly inside the disc: n = (u, -sqrt(1 - s), v) in (x, y, z)
        const Vec3 n{u, -std::sqrt(1 - s), v};
        const double head = -n[1];  // toEye = -forward = (0, -1, 0)
        const double k = std::max(0.0, (n[0] * key[0] + n[1] * key[1] + n[2] * key[2]) / kn);
        const double light = shade.ambient + shade.headlight * head + shade.key * k;
        for (int i = 0; i < 3; ++i)
          EXPECT_NEAR(double(px[i]), std::clamp(shade.colour[size_t(i)] * light, 0.0, 1.0) * 255, 0.51) << c << "," << r;
        ++inside;
      } else if (std::sqrt(s) > 1.0 + 1.5 * img.pixelStep) {
        for (int i = 0; i < 3; ++i) EXPECT_EQ(px[i], shade.background[size_t(i)]) << c << "," << r;
        ++background;
      }
    }
  EXPECT_GT(inside, 300u);
  EXPECT_GT(background, 300u);
}

TEST(Render, SolidBoundsEncloseTheSolidTightly) {
  Vec3 lo, hi;
  const Expr x = Expr::x(0);
  ASSERT_TRUE(solidBounds(sphere(1.0), {-10, -10, -10}, {10, 10, 10}, 7, lo, hi));
  for (int i = 0; i < 3; ++i) {
    EXPECT_LE(lo[size_t(i)], -1.0);
    EXPECT_GE(lo[size_t(i)], -1.0 - 20.0 / 128);
    EXPECT_GE(hi[size_t(i)], 1.0);
    EXPECT_LE(hi[size_t(i)], 1.0 + 20.0 / 128);
  }
  EXPECT_FALSE(solidBounds(-1.0 - x * x, {-1, -1, -1}, {1, 1, 1}, 4, lo, hi));
}

TEST(Render, BadArgumentsThrow) {
  Camera cam;
  EXPECT_THROW(castRays(sphere(1), cam, options(0, 10, 0, 1)), std::invalid_argument);
  EXPECT_THROW(castRays(sphere(1), cam, options(10, 10, 1, 1)), std::invalid_argument);
  EXPECT_THROW(lookAtCamera({0, 0, 0}, {0, 0, 0}, {0, 0, 1}, false, 1), std::invalid_argument);
  EXPECT_THROW(lookAtCamera({0, 0, 0}, {0, 0, 1}, {0, 0, 1}, false, 1), std::invalid_argument);
}

}  // namespace
}  // namespace frep
