// Signed distance to a closed polygon (Choporov-Hybrid eq. 1-3 with the polyline distance of
// eq. 5-6: the minimum over the edges of the point-segment distance) through a BVH, sign from the
// pseudonormal of the closest feature instead of the parity test (eq. 7). tessellateBezierLoop
// below is the paper's nonuniform-curve-mesh, which gives eq. 5's polyline for a Bezier curve.
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "frep/geometry/distance_fields.h"

namespace frep {

namespace {
uint64_t hashDoubles(uint64_t h, const std::vector<double>& v) {
  for (double d : v) {
    uint64_t b;
    std::memcpy(&b, &d, sizeof b);
    h = (h ^ b) * 0x100000001b3ULL;
  }
  return h;
}

// Closest point of segment a-b to p; region: 0 at a, 1 at b, 2 inside.
double segmentDist2(const double* p, const double* a, const double* b, double* q, int& region) {
  const double ex = b[0] - a[0], ey = b[1] - a[1];
  const double t = (p[0] - a[0]) * ex + (p[1] - a[1]) * ey;
  const double len2 = ex * ex + ey * ey;
  if (t <= 0.0) {
    q[0] = a[0], q[1] = a[1], region = 0;
  } else if (t >= len2) {
    q[0] = b[0], q[1] = b[1], region = 1;
  } else {
    const double s = t / len2;
    q[0] = a[0] + s * ex, q[1] = a[1] + s * ey, region = 2;
  }
  const double dx = p[0] - q[0], dy = p[1] - q[1];
  return dx * dx + dy * dy;
}
}  // namespace

PolygonField::PolygonField(std::vector<double> xy, std::string name) : name_(std::move(name)) {
  if (xy.size() % 2 != 0) throw std::invalid_argument("the vertex array needs 2 numbers per vertex");
  for (size_t i = 0; i + 1 < xy.size(); i += 2) {
    const size_t m = xy_.size();
    if (m >= 2 && xy_[m - 2] == xy[i] && xy_[m - 1] == xy[i + 1]) continue;  // repeated vertex
    xy_.push_back(xy[i]);
    xy_.push_back(xy[i + 1]);
  }
  while (xy_.size() >= 4 && xy_[0] == xy_[xy_.size() - 2] && xy_[1] == xy_.back()) xy_.resize(xy_.size() - 2);
  const size_t n = xy_.size() / 2;
  if (n < 3) throw std::invalid_argument("a polygon needs at least 3 distinct vertices");
  for (size_t i = 0; i < n; ++i) {
    const size_t j = (i + 1) % n;
    area_ += 0.5 * (xy_[2 * i] * xy_[2 * j + 1] - xy_[2 * j] * xy_[2 * i + 1]);
  }
  if (!(std::fabs(area_) > 0.0)) throw std::invalid_argument("the polygon has zero area (degenerate)");
  if (area_ < 0.0) {  // clockwise: reverse to counter-clockwise
    for (size_t i = 0, k = n - 1; i < k; ++i, --k) {
      std::swap(xy_[2 * i], xy_[2 * k]);
      std::swap(xy_[2 * i + 1], xy_[2 * k + 1]);
    }
    area_ = -area_;
  }
  edgeN_.resize(2 * n);
  vertN_.assign(2 * n, 0.0);
  std::vector<Bvh::Box> boxes(n);
  for (size_t i = 0; i < n; ++i) {
    const size_t j = (i + 1) % n;
    const double ex = xy_[2 * j] - xy_[2 * i], ey = xy_[2 * j + 1] - xy_[2 * i + 1];
    const double len = std::hypot(ex, ey);
    edgeN_[2 * i] = ey / len;  // outward for a counter-clockwise loop
    edgeN_[2 * i + 1] = -ex / len;
    for (int k = 0; k < 2; ++k) {
      boxes[i].lo[k] = std::min(xy_[2 * i + k], xy_[2 * j + k]);
      boxes[i].hi[k] = std::max(xy_[2 * i + k], xy_[2 * j + k]);
    }
    boxes[i].lo[2] = boxes[i].hi[2] = 0.0;
  }
  for (size_t i = 0; i < n; ++i) {
    const size_t prev = (i + n - 1) % n;  // a vertex's pseudonormal: the sum of its edges' normals
    vertN_[2 * i] = edgeN_[2 * prev] + edgeN_[2 * i];
    vertN_[2 * i + 1] = edgeN_[2 * prev + 1] + edgeN_[2 * i + 1];
  }
  bvh_.build(boxes);
  hash_ = hashDoubles(0xcbf29ce484222325ULL ^ 0x2d, xy_);
}

double PolygonField::signedDistance(const double* p, double* q) const {
  const size_t n = size();
  const double pp[3] = {p[0], p[1], 0.0};
  double best2 = INFINITY, bq[2] = {0, 0};
  int bestRegion = 2;
  int64_t e = bvh_.nearest(pp, [&](uint32_t i, double cur) {
    double qq[2];
    int region;
    const double d2 = segmentDist2(pp, &xy_[2 * i], &xy_[2 * ((i + 1) % n)], qq, region);
    if (d2 < cur) bq[0] = qq[0], bq[1] = qq[1], bestRegion = region;
    return d2;
  }, best2);
  if (q) q[0] = bq[0], q[1] = bq[1];
  const double d = std::sqrt(best2);
  if (d == 0.0) return 0.0;
  const double* nrm = bestRegion == 2 ? &edgeN_[2 * e] : &vertN_[2 * ((e + bestRegion) % n)];
  const double s = (p[0] - bq[0]) * nrm[0] + (p[1] - bq[1]) * nrm[1];
  return s < 0.0 ? d : -d;
}

double PolygonField::value(const double* p) const { return signedDistance(p, nullptr); }

double PolygonField::distance(double x, double y, double* q) const {
  const double p[2] = {x, y};
  double qq[2];
  return std::fabs(signedDistance(p, q ? q : qq));
}

double PolygonField::gradient(const double* p, double* g) const {
  double q[2];
  return gradientFromNearest(signedDistance(p, q), p, q, g);
}

void bezierPoint(const double* ctrl, int degree, int dims, double t, double* out) {
  double tmp[3 * 64];
  for (int i = 0; i <= degree; ++i)
    for (int k = 0; k < dims; ++k) tmp[i * dims + k] = ctrl[i * dims + k];
  for (int r = 1; r <= degree; ++r)
    for (int i = 0; i <= degree - r; ++i)
      for (int k = 0; k < dims; ++k)
        tmp[i * dims + k] = (1.0 - t) * tmp[i * dims + k] + t * tmp[(i + 1) * dims + k];
  for (int k = 0; k < dims; ++k) out[k] = tmp[k];
}

std::vector<double> tessellateBezierLoop(const std::vector<double>& ctrl, int degree, int n, double delta) {
  if (degree < 1 || degree > 63) throw std::invalid_argument("the degree must be 1 to 63");
  if (n < 2) throw std::invalid_argument("n (initial points per arc) must be at least 2");
  if (!(delta > 0.0)) throw std::invalid_argument("delta (chord deviation) must be positive");
  const size_t pts = ctrl.size() / 2;
  if (ctrl.size() % 2 != 0 || pts < size_t(degree) + 1 || (pts - 1) % size_t(degree) != 0)
    throw std::invalid_argument("the control array must hold arcs * degree + 1 points (2 numbers each); got " +
                                std::to_string(pts) + " points for degree " + std::to_string(degree));
  if (ctrl[0] != ctrl[2 * (pts - 1)] || ctrl[1] != ctrl[2 * (pts - 1) + 1])
    throw std::invalid_argument("the curve is not closed: the last control point must equal the first");
  const size_t arcs = (pts - 1) / size_t(degree);
  std::vector<double> out;
  for (size_t a = 0; a < arcs; ++a) {
    const double* c = &ctrl[2 * a * size_t(degree)];
    bool allSame = true;
    for (int i = 1; i <= degree; ++i) allSame = allSame && c[2 * i] == c[0] && c[2 * i + 1] == c[1];
    if (allSame) throw std::invalid_argument("arc " + std::to_string(a + 1) + " is degenerate: all its control points are equal");
    auto at = [&](double t, double* o) { bezierPoint(c, degree, 2, t, o); };
    // Deviation of the chord c(t0)-c(t1) from the arc, at the parameter's quarter points.
    auto deviation = [&](double t0, double t1) {
      double p0[2], p1[2], m[2], worst = 0.0;
      at(t0, p0);
      at(t1, p1);
      for (int k = 1; k <= 3; ++k) {
        at(t0 + (t1 - t0) * k / 4.0, m);
        const double ex = p1[0] - p0[0], ey = p1[1] - p0[1], len2 = ex * ex + ey * ey;
        double s = len2 > 0 ? ((m[0] - p0[0]) * ex + (m[1] - p0[1]) * ey) / len2 : 0.0;
        s = std::max(0.0, std::min(1.0, s));
        worst = std::max(worst, std::hypot(m[0] - p0[0] - s * ex, m[1] - p0[1] - s * ey));
      }
      return worst;
    };
    for (int i = 0; i + 1 < n; ++i) {
      // Depth-first splitting keeps the points in parameter order.
      struct Span { double t0, t1; int depth; };
      std::vector<Span> stack{{double(i) / (n - 1), double(i + 1) / (n - 1), 0}};
      while (!stack.empty()) {
        Span s = stack.back();
        stack.pop_back();
        if (s.depth < 30 && deviation(s.t0, s.t1) > delta) {
          const double mid = 0.5 * (s.t0 + s.t1);
          stack.push_back({mid, s.t1, s.depth + 1});
          stack.push_back({s.t0, mid, s.depth + 1});
          continue;
        }
        double p[2];
        at(s.t0, p);
        out.push_back(p[0]);
        out.push_back(p[1]);
      }
    }
  }
  return out;
}

}  // namespace frep
