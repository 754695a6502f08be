// Interval ray casting (see raycast.h).
//
// Recursion over cells = pixel rectangle x depth range, front to back. A cell's box covers its
// pixels' whole footprints (centre +- half a pixel), so it encloses both the centre rays and the
// footprint search. A cell is split along depth while its depth extent exceeds twice its lateral
// extent (roughly cubic cells), else into four pixel quadrants; a single pixel runs the 1D
// search. Pixels already hit are skipped by later (deeper) cells.
#include "frep/render/raycast.h"

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "frep/evaluators/eval.h"
#include "frep/expressions/tape.h"
#include "sampling/parallel_chunks.h"

namespace frep {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Depth search widths, in pixel footprints at the far end of the range: point checks start at
// kLeaf; intervals keep splitting to kMinWidth before a box they cannot exclude counts as a hit.
constexpr double kLeaf = 0.25, kMinWidth = 1.0 / 64, kRootWidth = 1e-4, kConfirm = 1.0 / 4;
constexpr int kConfirmBudget = 64;  // confirming evaluations per pixel

using vec3::cross;
using vec3::dot;
using vec3::normalized;
using vec3::sub;

// Model coordinates X(u, v, d) as expressions of vars 0, 1, 2 (see raycast.h).
std::vector<Expr> cameraMap(const Camera& cam, const std::vector<double>& fixed) {
  const Expr u = Expr::x(0), v = Expr::x(1), d = Expr::x(2);
  std::vector<Expr> X;
  for (int i = 0; i < 3; ++i) {
    if (cam.perspective)
      X.push_back(cam.eye[i] + d * (cam.forward[i] + u * cam.right[i] + v * cam.up[i]));
    else
      X.push_back(cam.eye[i] + u * cam.right[i] + v * cam.up[i] + d * cam.forward[i]);
  }
  for (double f : fixed) X.push_back(Expr(f));
  return X;
}

struct Worker {
  IntervalEvaluator interval;
  PointEvaluator point;
  GradientEvaluator gradient;
  RenderStats stats;
};

class Caster {
 public:
  Caster(const Camera& cam, const RenderOptions& opt, TapePtr view, const PixelRegion& region, std::vector<RayHit>& hits)
      : cam_(cam), opt_(opt), view_(std::move(view)), region_(region), hits_(hits),
        step_(2.0 * cam.halfWidth / opt.width), budget_(hits.size(), kConfirmBudget) {}

  void topTile(Worker& w, int c0, int c1, int r0, int r1) {
    cell(w, c0, c1, r0, r1, opt_.nearDepth, opt_.farDepth, view_);
  }

 private:
  double footprint(double d) const { return cam_.perspective ? std::abs(d) * step_ : step_; }
  double u(int c) const { return pixelU(cam_, opt_.width, c); }
  double v(int r) const { return pixelV(cam_, opt_.width, opt_.height, r); }
  size_t index(int c, int r) const {
    return size_t(r - region_.r0) * size_t(region_.c1 - region_.c0) + size_t(c - region_.c0);
  }
  RayHit& hit(int c, int r) { return hits_[index(c, r)]; }

  Interval evalBox(Worker& w, const Tape& tape, Interval bu, Interval bv, Interval bd) {
    const Interval box[3] = {bu, bv, bd};
    ++w.stats.intervalEvals;
    return w.interval.eval(tape, box);
  }
  double evalPoint(Worker& w, const Tape& tape, double pu, double pv, double d) {
    const double x[3] = {pu, pv, d};
    ++w.stats.pointEvals;
    return w.point.eval(tape, x);
  }

  void cell(Worker& w, int c0, int c1, int r0, int r1, double a, double b, const TapePtr& tape) {
    bool open = false;  // a pixel without a centre hit remains
    for (int r = r0; r < r1 && !open; ++r)
      for (int c = c0; c < c1 && !open; ++c) open = hit(c, r).kind != RayHit::kCentre;
    if (!open) return;
    const double half = 0.5 * step_;
    const Interval iv = evalBox(w, *tape, Interval(u(c0) - half, u(c1 - 1) + half),
                                Interval(v(r1 - 1) - half, v(r0) + half), Interval(a, b));
    if (iv.hi < 0) return;
    TapePtr pruned = w.interval.pruned(tape);
    const int side = std::max(c1 - c0, r1 - r0);
    if (b - a > 2.0 * side * footprint(b) && b - a > kLeaf * footprint(b)) {
      const double m = 0.5 * (a + b);
      cell(w, c0, c1, r0, r1, a, m, pruned);
      cell(w, c0, c1, r0, r1, m, b, pruned);
      return;
    }
    if (side == 1) {
      pixel(w, c0, r0, a, b, pruned);
      return;
    }
    const int cm = c1 - c0 > 1 ? c0 + (c1 - c0 + 1) / 2 : c1;
    const int rm = r1 - r0 > 1 ? r0 + (r1 - r0 + 1) / 2 : r1;
    cell(w, c0, cm, r0, rm, a, b, pruned);
    if (cm < c1) cell(w, cm, c1, r0, rm, a, b, pruned);
    if (rm < r1) cell(w, c0, cm, rm, r1, a, b, pruned);
    if (cm < c1 && rm < r1) cell(w, cm, c1, rm, r1, a, b, pruned);
  }

  void pixel(Worker& w, int c, int r, double a, double b, const TapePtr& tape) {
    RayHit& h = hit(c, r);
    const double pu = u(c), pv = v(r), fp = footprint(b);
    double d = centreSearch(w, *tape, pu, pv, a, b, fp);
    if (d < kInf) {
      finish(w, h, RayHit::kCentre, pu, pv, d);
      return;
    }
    if (!opt_.footprint || h.kind == RayHit::kFootprint) return;
    // The pixel's cell box is this footprint slab, and the caller found it ambiguous.
    d = footprintSearch(w, tape, pu, pv, a, b, fp, budget_[index(c, r)], true);
    if (d < kInf) finish(w, h, RayHit::kFootprint, pu, pv, d);
  }

  // First depth in [a, b] where the centre ray may be inside (kInf: none).
  double centreSearch(Worker& w, const Tape& tape, double pu, double pv, double a, double b, double fp) {
    const Interval iv = evalBox(w, tape, Interval(pu), Interval(pv), Interval(a, b));
    if (iv.hi < 0) return kInf;
    if (iv.lo >= 0) return a;
    if (b - a <= kLeaf * fp) {
      const double fa = evalPoint(w, tape, pu, pv, a);
      if (fa >= 0) return a;
      const double fb = evalPoint(w, tape, pu, pv, b);
      if (fb >= 0) return bisect(w, tape, pu, pv, a, b, fp);
      if (b - a <= kMinWidth * fp) return 0.5 * (a + b);  // intervals cannot exclude it: thin
    }
    const double m = 0.5 * (a + b);
    const double front = centreSearch(w, tape, pu, pv, a, m, fp);
    return front < kInf ? front : centreSearch(w, tape, pu, pv, m, b, fp);
  }

  // f(a) < 0 <= f(b): the crossing, to kRootWidth footprints.
  double bisect(Worker& w, const Tape& tape, double pu, double pv, double a, double b, double fp) {
    while (b - a > kRootWidth * fp) {
      const double m = 0.5 * (a + b);
      if (m <= a || m >= b) break;
      (evalPoint(w, tape, pu, pv, m) >= 0 ? b : a) = m;
    }
    return b;
  }

  // First depth slab of width <= kLeaf footprints in which the pixel's footprint may hold a
  // point of the solid, confirmed by `confirm`.
  double footprintSearch(Worker& w, const TapePtr& tape, double pu, double pv, double a, double b, double fp,
                         int& budget, bool knownAmbiguous = false) {
    const double half = 0.5 * step_;
    if (!knownAmbiguous &&
        evalBox(w, *tape, Interval(pu - half, pu + half), Interval(pv - half, pv + half), Interval(a, b)).hi < 0)
      return kInf;
    if (b - a <= kLeaf * fp) {
      // Known ambiguous: `tape` was pruned to this very box by the caller.
      TapePtr pruned = knownAmbiguous ? tape : w.interval.pruned(tape);
      return confirm(w, pruned, pu - half, pu + half, pv - half, pv + half, a, b, fp, budget) ? 0.5 * (a + b) : kInf;
    }
    const double m = 0.5 * (a + b);
    const double front = footprintSearch(w, tape, pu, pv, a, m, fp, budget);
    return front < kInf ? front : footprintSearch(w, tape, pu, pv, m, b, fp, budget);
  }

  // Whether some sub-box of the footprint slab, kConfirm footprints wide, is not excluded by
  // intervals: the over-estimate of interval bounds shrinks with the box, so loose bounds of
  // a big box do not show as ghost features, while a real sub-pixel feature always keeps one.
  // When the pixel's budget of evaluations runs out the slab counts as a hit (never miss a feature).
  bool confirm(Worker& w, const TapePtr& tape, double u0, double u1, double v0, double v1, double a, double b,
               double fp, int& budget) {
    if (--budget < 0) return true;
    const Interval iv = evalBox(w, *tape, Interval(u0, u1), Interval(v0, v1), Interval(a, b));
    if (iv.hi < 0) return false;
    if (u1 - u0 <= kConfirm * step_ || iv.lo >= 0) return true;
    TapePtr pruned = w.interval.pruned(tape);
    const double um = 0.5 * (u0 + u1), vm = 0.5 * (v0 + v1), dm = b - a > kConfirm * fp ? 0.5 * (a + b) : b;
    for (int k = 0; k < 8; ++k) {
      if ((k & 4) && dm == b) break;
      if (confirm(w, pruned, k & 1 ? um : u0, k & 1 ? u1 : um, k & 2 ? vm : v0, k & 2 ? v1 : vm, k & 4 ? dm : a,
                  k & 4 ? b : dm, fp, budget))
        return true;
    }
    return false;
  }

  // The hit's point and normal. The gradient comes from the view tape in (u, v, d) by the chain
  // rule, so a worker needs the one tape: orthographic X = eye + uR + vU + dF gives
  // f_u = g.R, f_v = g.U, f_d = g.F; perspective X = eye + d(F + uR + vU) gives f_u = d g.R,
  // f_v = d g.U, f_d = g.(F + uR + vU).
  void finish(Worker& w, RayHit& h, RayHit::Kind kind, double pu, double pv, double d) {
    h.kind = kind;
    h.depth = d;
    for (int i = 0; i < 3; ++i)
      h.point[i] = cam_.perspective ? cam_.eye[i] + d * (cam_.forward[i] + pu * cam_.right[i] + pv * cam_.up[i])
                                    : cam_.eye[i] + pu * cam_.right[i] + pv * cam_.up[i] + d * cam_.forward[i];
    const double x[3] = {pu, pv, d};
    double g[3] = {0, 0, 0};
    w.gradient.eval(*view_, x, g);
    double gr = g[0], gu = g[1], gf = g[2];
    if (cam_.perspective) {
      gr /= d, gu /= d;
      gf -= pu * gr + pv * gu;
    }
    Vec3 grad;
    for (int i = 0; i < 3; ++i) grad[size_t(i)] = gr * cam_.right[size_t(i)] + gu * cam_.up[size_t(i)] + gf * cam_.forward[size_t(i)];
    const double n = std::sqrt(dot(grad, grad));
    h.normal = n > 0 && std::isfinite(n) ? Vec3{-grad[0] / n, -grad[1] / n, -grad[2] / n} : Vec3{0, 0, 0};
  }

  const Camera& cam_;
  const RenderOptions& opt_;
  TapePtr view_;
  PixelRegion region_;
  std::vector<RayHit>& hits_;
  double step_;              // pixel spacing on the image plane
  std::vector<int> budget_;  // per pixel: confirming evaluations left (tiles own their pixels)
};
}  // namespace

Camera lookAtCamera(const Vec3& eye, const Vec3& target, const Vec3& upHint, bool perspective, double halfWidth) {
  const Vec3 dir = sub(target, eye);
  if (!(dot(dir, dir) > 0)) throw std::invalid_argument("camera: the eye and the target coincide");
  Vec3 upv = dot(upHint, upHint) > 0 ? upHint : Vec3{0, 0, 1};
  Camera cam;
  cam.eye = eye;
  cam.forward = normalized(dir);
  const Vec3 r = cross(cam.forward, upv);
  if (!(dot(r, r) > 1e-20)) throw std::invalid_argument("camera: the view direction is parallel to the up direction");
  cam.right = normalized(r);
  cam.up = cross(cam.right, cam.forward);
  cam.perspective = perspective;
  cam.halfWidth = halfWidth;
  return cam;
}

Camera orbitCamera(const Vec3& target, double azimuthDeg, double elevationDeg, double distance, bool perspective,
                   double halfWidth) {
  const double az = azimuthDeg * M_PI / 180, el = elevationDeg * M_PI / 180;
  const Vec3 dir{std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
  const Vec3 eye{target[0] + distance * dir[0], target[1] + distance * dir[1], target[2] + distance * dir[2]};
  // Straight above or below: the image's up is the azimuth's direction in the xy plane.
  const Vec3 upHint = std::abs(std::cos(el)) < 1e-9 ? Vec3{-std::cos(az) * std::sin(el), -std::sin(az) * std::sin(el), 0}
                                                   : Vec3{0, 0, 1};
  return lookAtCamera(eye, target, upHint, perspective, halfWidth);
}

double pixelU(const Camera& cam, int width, int col) {
  const double step = 2.0 * cam.halfWidth / width;
  return (double(col) - 0.5 * double(width - 1)) * step;
}
double pixelV(const Camera& cam, int width, int height, int row) {
  const double step = 2.0 * cam.halfWidth / width;
  return (0.5 * double(height - 1) - double(row)) * step;
}

namespace {
void checkView(const Camera& camera, const RenderOptions& opt) {
  if (opt.width <= 0 || opt.height <= 0) throw std::invalid_argument("render: the image size must be positive");
  if (!(opt.farDepth > opt.nearDepth) || !std::isfinite(opt.nearDepth) || !std::isfinite(opt.farDepth))
    throw std::invalid_argument("render: the depth range must be finite and non-empty");
  if (!(camera.halfWidth > 0) || !std::isfinite(camera.halfWidth))
    throw std::invalid_argument("render: the view width must be positive");
}
}  // namespace

TapePtr viewTape(const Expr& field, const Camera& camera, const std::vector<double>& fixed) {
  return Tape::compile(remap(field, cameraMap(camera, fixed)), 3);
}

bool isTileRegion(const PixelRegion& g, int width, int height) {
  auto ok = [](int lo, int hi, int size) {
    return 0 <= lo && lo < hi && hi <= size && lo % kRenderTile == 0 && (hi % kRenderTile == 0 || hi == size);
  };
  return ok(g.c0, g.c1, width) && ok(g.r0, g.r1, height);
}

std::vector<RayHit> castRegion(const TapePtr& view, const Camera& camera, const RenderOptions& opt,
                               const PixelRegion& region, RenderStats* stats) {
  checkView(camera, opt);
  if (!isTileRegion(region, opt.width, opt.height))
    throw std::invalid_argument("render: the region [" + std::to_string(region.c0) + "," + std::to_string(region.c1) +
                                ")x[" + std::to_string(region.r0) + "," + std::to_string(region.r1) +
                                ") is not made of whole " + std::to_string(kRenderTile) + "-pixel tiles of the image");
  InterruptScope scope(InterruptScope::choose(opt.interrupt));
  std::vector<RayHit> hits(size_t(region.c1 - region.c0) * size_t(region.r1 - region.r0));
  Caster caster(camera, opt, view, region, hits);
  const int tx0 = region.c0 / kRenderTile, ty0 = region.r0 / kRenderTile;
  const int tilesX = (region.c1 - 1) / kRenderTile + 1 - tx0, tilesY = (region.r1 - 1) / kRenderTile + 1 - ty0;
  tbb::enumerable_thread_specific<Worker> workers;
  std::atomic<uint64_t> tilesDone{0};
  parallelChunks(size_t(tilesX) * size_t(tilesY), 1, opt.threads, [&](size_t b, size_t e) {
    Worker& w = workers.local();
    for (size_t t = b; t < e; ++t) {
      const int c0 = (tx0 + int(t % size_t(tilesX))) * kRenderTile, r0 = (ty0 + int(t / size_t(tilesX))) * kRenderTile;
      caster.topTile(w, c0, std::min(c0 + kRenderTile, region.c1), r0, std::min(r0 + kRenderTile, region.r1));
      reportProgress("render", ++tilesDone, size_t(tilesX) * size_t(tilesY));
    }
  });
  if (stats) {
    *stats = {};
    for (const Worker& w : workers) {
      stats->intervalEvals += w.stats.intervalEvals;
      stats->pointEvals += w.stats.pointEvals;
    }
  }
  return hits;
}

DepthImage castRays(const Expr& field, const Camera& camera, const RenderOptions& opt, const std::vector<double>& fixed,
                    RenderStats* stats) {
  checkView(camera, opt);
  DepthImage img;
  img.width = opt.width, img.height = opt.height;
  img.pixelStep = 2.0 * camera.halfWidth / opt.width;
  img.hits = castRegion(viewTape(field, camera, fixed), camera, opt, PixelRegion{0, 0, opt.width, opt.height}, stats);
  return img;
}

bool solidBounds(const Expr& field, const Vec3& lo, const Vec3& hi, int levels, Vec3& outLo, Vec3& outHi,
                 const std::vector<double>& fixed) {
  TapePtr tape = Tape::compile(field, uint32_t(3 + fixed.size()));
  IntervalEvaluator ev;
  std::vector<Interval> box(tape->numVars());
  for (size_t i = 3; i < box.size(); ++i) box[i] = Interval(i - 3 < fixed.size() ? fixed[i - 3] : 0.0);
  bool any = false;
  Vec3 blo{kInf, kInf, kInf}, bhi{-kInf, -kInf, -kInf};
  // Depth-first over the octree; a cell is kept when its interval may reach f >= 0.
  struct Cell { Vec3 lo, hi; int level; TapePtr tape; };
  std::vector<Cell> stack{{lo, hi, 0, tape}};
  while (!stack.empty()) {
    Cell cl = stack.back();
    stack.pop_back();
    for (int i = 0; i < 3; ++i) box[size_t(i)] = Interval(cl.lo[size_t(i)], cl.hi[size_t(i)]);
    const Interval iv = ev.eval(*cl.tape, box.data());
    if (iv.hi < 0) continue;
    bool inside = true;  // the cell lies within the bounds found so far: nothing to learn
    for (int i = 0; i < 3; ++i) inside = inside && cl.lo[size_t(i)] >= blo[size_t(i)] && cl.hi[size_t(i)] <= bhi[size_t(i)];
    if (inside) continue;
    if (cl.level == levels || iv.lo >= 0) {
      any = true;
      for (int i = 0; i < 3; ++i) {
        blo[size_t(i)] = std::min(blo[size_t(i)], cl.lo[size_t(i)]);
        bhi[size_t(i)] = std::max(bhi[size_t(i)], cl.hi[size_t(i)]);
      }
      continue;
    }
    TapePtr pruned = ev.pruned(cl.tape);
    for (int k = 0; k < 8; ++k) {
      Cell ch{cl.lo, cl.hi, cl.level + 1, pruned};
      for (int i = 0; i < 3; ++i) {
        const double m = 0.5 * (cl.lo[size_t(i)] + cl.hi[size_t(i)]);
        (k >> i & 1 ? ch.lo : ch.hi)[size_t(i)] = m;
      }
      stack.push_back(ch);
    }
  }
  if (any) outLo = blo, outHi = bhi;
  return any;
}

}  // namespace frep
