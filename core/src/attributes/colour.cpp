// Colour fields evaluated in batches (see colour.h). Each vertex is evaluated on its own, so the
// result does not depend on the order, the batch boundaries or the number of threads.
#include "frep/attributes/colour.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <stdexcept>

#include "frep/evaluators/eval.h"

namespace frep {

float clampChannel(double v) {
  if (!(v > 0)) return 0.0f;  // also NaN
  return v >= 1 ? 1.0f : float(v);
}

ColourField::ColourField(const std::vector<Expr>& rgb, uint32_t dims) : dims_(dims) {
  if (rgb.size() != 3) throw std::invalid_argument("a colour field needs three expressions (red, green, blue)");
  for (size_t c = 0; c < 3; ++c) tapes_[c] = Tape::compile(rgb[c], dims);
}

std::array<float, 3> ColourField::at(const double* x) const {
  PointEvaluator ev;
  std::array<float, 3> rgb;
  for (size_t c = 0; c < 3; ++c) rgb[c] = clampChannel(ev.eval(*tapes_[c], x));
  return rgb;
}

std::vector<std::array<float, 3>> ColourField::at(const std::vector<std::array<double, 3>>& points, int threads) const {
  std::vector<std::array<float, 3>> out(points.size());
  constexpr size_t kBatch = BatchEvaluator<double>::kBatch;
  const uint32_t used = std::min<uint32_t>(dims_, 3);
  auto run = [&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, points.size(), kBatch), [&](const tbb::blocked_range<size_t>& r) {
      BatchEvaluator<double> ev;
      for (size_t begin = r.begin(); begin < r.end(); begin += kBatch) {
        const size_t n = std::min(kBatch, r.end() - begin);
        for (size_t c = 0; c < 3; ++c) {
          const Tape& tape = *tapes_[c];
          ev.reserve(tape);
          for (uint32_t d = 0; d < dims_; ++d) {
            double* in = ev.in(d);
            for (size_t k = 0; k < n; ++k) in[k] = d < used ? points[begin + k][d] : 0.0;
          }
          const double* v = ev.eval(tape, n);
          for (size_t k = 0; k < n; ++k) out[begin + k][c] = clampChannel(v[k]);
        }
      }
    });
  };
  if (threads > 0) {
    tbb::task_arena arena(threads);
    arena.execute(run);
  } else {
    run();
  }
  return out;
}

void colourMesh(Mesh& mesh, const ColourField& colour, double inset, int threads) {
  std::vector<std::array<double, 3>> at(mesh.positions.size());
  for (size_t i = 0; i < at.size(); ++i)
    for (int c = 0; c < 3; ++c) at[i][c] = mesh.positions[i][c] - inset * mesh.normals[i][c];
  mesh.colours = colour.at(at, threads);
}

}  // namespace frep
