// The colour of a model at a point: three fields (red, green, blue) over the same coordinates
// as the model's f, e.g. HyperFun's s[1..3] (lang::colourOf). Values are clamped to [0, 1]
// (NaN gives 0), as a picture or a mesh file stores them. Used by the mesh writers' per-vertex
// colours and by the renderer.
#pragma once

#include <array>
#include <vector>

#include "frep/expressions/expr.h"
#include "frep/expressions/tape.h"
#include "frep/meshing/mesh.h"

namespace frep {

class ColourField {
 public:
  // rgb: exactly three expressions over x[0..dims). Throws std::invalid_argument otherwise.
  ColourField(const std::vector<Expr>& rgb, uint32_t dims);
  uint32_t dims() const { return dims_; }
  // The colour at x (dims() coordinates). Thread-safe (each call has its own evaluator state).
  std::array<float, 3> at(const double* x) const;
  // The colours at n points given as xyz triples (dims() <= 3; missing coordinates are 0).
  std::vector<std::array<float, 3>> at(const std::vector<std::array<double, 3>>& points, int threads = 0) const;

 private:
  uint32_t dims_;
  std::array<TapePtr, 3> tapes_;
};

// A channel value as stored: clamped to [0, 1], NaN as 0.
float clampChannel(double v);

// Fills mesh.colours at the mesh's vertices moved `inset` inwards along their normals,
// p - inset·n (after merging and simplifying: the result depends only on the final positions
// and normals, so it is the same for any split or worker count). A surface's colour is the
// colour of the material just under it: hfA_SetColor(f, ...) tests f >= 0, which on the
// surface of f itself is decided by rounding (frep mesh uses half a voxel).
void colourMesh(Mesh& mesh, const ColourField& colour, double inset, int threads = 0);

}  // namespace frep
