// Bounding volume hierarchy: median split along the longest axis of the centroids' extent,
// leaves of up to 4 primitives. Deterministic (same boxes, same tree).
#include <algorithm>
#include <cmath>

#include "frep/geometry/distance_fields.h"

namespace frep {

void Bvh::build(const std::vector<Box>& boxes) {
  nodes_.clear();
  order_.resize(boxes.size());
  for (uint32_t i = 0; i < order_.size(); ++i) order_[i] = i;
  if (boxes.empty()) return;
  std::vector<double> centres(boxes.size() * 3);
  for (size_t i = 0; i < boxes.size(); ++i)
    for (int k = 0; k < 3; ++k) centres[i * 3 + k] = 0.5 * (boxes[i].lo[k] + boxes[i].hi[k]);
  nodes_.reserve(2 * boxes.size() / 4 + 2);
  buildRange(boxes, centres, 0, uint32_t(boxes.size()));
}

uint32_t Bvh::buildRange(const std::vector<Box>& boxes, std::vector<double>& centres, uint32_t lo, uint32_t hi) {
  const uint32_t id = uint32_t(nodes_.size());
  nodes_.push_back({});
  Box b;
  double clo[3], chi[3];
  for (int k = 0; k < 3; ++k) {
    b.lo[k] = clo[k] = INFINITY;
    b.hi[k] = chi[k] = -INFINITY;
  }
  for (uint32_t i = lo; i < hi; ++i) {
    const Box& x = boxes[order_[i]];
    for (int k = 0; k < 3; ++k) {
      b.lo[k] = std::min(b.lo[k], x.lo[k]);
      b.hi[k] = std::max(b.hi[k], x.hi[k]);
      clo[k] = std::min(clo[k], centres[order_[i] * 3 + k]);
      chi[k] = std::max(chi[k], centres[order_[i] * 3 + k]);
    }
  }
  nodes_[id].box = b;
  if (hi - lo <= 4) {
    nodes_[id].first = lo;
    nodes_[id].count = hi - lo;
    return id;
  }
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (chi[k] - clo[k] > chi[axis] - clo[axis]) axis = k;
  const uint32_t mid = lo + (hi - lo) / 2;
  // Ties broken by index: the split does not depend on the library's nth_element.
  std::nth_element(order_.begin() + lo, order_.begin() + mid, order_.begin() + hi, [&](uint32_t a, uint32_t c) {
    const double ca = centres[a * 3 + axis], cc = centres[c * 3 + axis];
    return ca < cc || (ca == cc && a < c);
  });
  const uint32_t left = buildRange(boxes, centres, lo, mid);
  const uint32_t right = buildRange(boxes, centres, mid, hi);
  nodes_[id].first = 0;
  nodes_[id].count = 0;
  nodes_[id].left = left;
  nodes_[id].right = right;
  return id;
}

double Bvh::boxGap(const Box& q) const {
  double best2 = INFINITY;
  if (nodes_.empty()) return best2;
  auto gap2 = [&](const Box& b) {
    double s = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double d = std::max({0.0, b.lo[k] - q.hi[k], q.lo[k] - b.hi[k]});
      s += d * d;
    }
    return s;
  };
  uint32_t stack[128];
  int sp = 0;
  stack[sp++] = 0;
  while (sp > 0 && best2 > 0.0) {
    const NodeB& n = nodes_[stack[--sp]];
    const double g = gap2(n.box);
    if (g >= best2) continue;
    if (n.count > 0) {
      best2 = g;
      continue;
    }
    stack[sp++] = n.left;
    stack[sp++] = n.right;
  }
  // Rounded down: the square root and the squares may round either way.
  return std::sqrt(best2) * (1.0 - 1e-12);
}

}  // namespace frep
