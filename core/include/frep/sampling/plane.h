// Values of a model on a regular 2D lattice of a plane (a slice image), by quadtree interval
// subdivision with tape pruning per tile: each tile's pixels are evaluated with the tape its
// box decided, which is bit-identical to the full tape there, so the result does not depend on
// the pruning, the tile size or the thread count. With signOnly, tiles whose interval decides
// the sign are not evaluated at all (their pixels get +inf / -inf): the cost then follows the
// boundary, not the area; with floatSigns, the evaluated leaves run in float where the sign is
// certified, in double elsewhere.
#pragma once

#include <cstdint>
#include <vector>

#include "frep/expressions/tape.h"

namespace frep {

struct PlaneLattice {
  uint32_t u = 0, v = 1;  // model coordinates along the image's columns and rows
  int normal = -1;        // coordinate held at `at` (-1: none)
  double at = 0.0;
  std::vector<double> fixed;  // values of further coordinates (index 3, 4, ...), if any
  double origin[2] = {0, 0};  // (u, v) of the bottom-left pixel
  double step = 1.0;          // pixel spacing in model units
  int width = 0, height = 0;  // row 0 is the top row (v = origin[1] + (height - 1) * step)

  double colCoord(int c) const { return origin[0] + double(c) * step; }
  double rowCoord(int r) const { return origin[1] + double(height - 1 - r) * step; }
  // Value of coordinate `var` other than u and v.
  double held(uint32_t var) const {
    if (int(var) == normal) return at;
    if (var >= 3 && var - 3 < fixed.size()) return fixed[var - 3];
    return 0.0;
  }
};

struct PlaneStats {
  uint64_t pointEvals = 0;     // pixels evaluated
  uint64_t intervalEvals = 0;  // tiles classified
  uint64_t intervalInstrs = 0; // sum over classified tiles of their tape's length
  uint64_t tapeInstrs = 0;     // sum over evaluated batches of the pruned tape's length
  uint64_t tapeBatches = 0;
  uint64_t decidedPixels = 0;  // pixels whose sign a tile decided (signOnly: not evaluated)
  uint64_t floatPixels = 0;    // floatSigns: pixels whose float value's sign was certified
  uint64_t doublePixels = 0;   // floatSigns: pixels evaluated in double (|f_float| <= bound, or no bound)
};

struct PlaneOptions {
  bool signOnly = false;
  // With signOnly: leaves are evaluated in float, a pixel keeps its float value only where
  // |f_float| exceeds a certified bound on its distance to the double value
  // (frep/evaluators/float_error.h), the rest are recomputed in double. Every pixel then has
  // the sign of the double path (the sign image is the same, bit for bit); the values of
  // certified pixels are the float ones. Tapes the bound does not cover stay in double.
  bool floatSigns = false;
  int threads = 0;  // 0: TBB's default, 1: serial
  // Models of the arithmetic subset (DenseTape::supports: + - * neg abs sqrt square min max)
  // run on dense tapes, simplified per tile in one backward pass, four sibling tiles per
  // interval pass (frep/expressions/dense_tape.h); false: the general path for every model
  // (bench_slice's baseline). Same values and signs either way.
  bool denseTapes = true;
};

// width * height values, row-major from the top row.
std::vector<double> evaluatePlane(const TapePtr& tape, const PlaneLattice& lattice,
                                  const PlaneOptions& options = {}, PlaneStats* stats = nullptr);

}  // namespace frep
