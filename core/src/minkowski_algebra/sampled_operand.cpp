// A sampled operand: the closed mesh of an operand's surface (sampled_operand.h).
#include "frep/minkowski_algebra/sampled_operand.h"

#include <algorithm>
#include <deque>
#include <mutex>
#include <cstdio>
#include <memory>
#include <stdexcept>

#include "frep/geometry/distance_fields.h"
#include "frep/meshing/mesh.h"
#include "frep/meshing/mesh_simplify.h"

namespace frep::minkowski {

namespace {

std::optional<SampledOperand> sample(const Expr& a, const Bounds& box, int res, const std::string& name) {
  if (box.lo.size() < 3 || box.hi.size() < 3) return std::nullopt;
  std::array<double, 3> lo, hi;
  double extent = 0;
  for (int k = 0; k < 3; ++k) extent = std::max(extent, box.hi[size_t(k)] - box.lo[size_t(k)]);
  if (!(extent > 0)) return std::nullopt;
  const double margin = 2.0 * extent / (res - 5);  // two voxels on each side
  for (int k = 0; k < 3; ++k) lo[size_t(k)] = box.lo[size_t(k)] - margin, hi[size_t(k)] = box.hi[size_t(k)] + margin;
  const GridSpec grid = GridSpec::fromBounds(lo, hi, res);
  TapePtr tape = Tape::compile(a, 3);
  Mesh m = meshGrid(tape, grid);
  if (m.triangles.empty() || !closureDefect(m.triangles, m.positions.size()).empty()) return std::nullopt;
  SampledOperand out;
  // Simplified within half a voxel (its certified bound), so the exact paths query fewer triangles.
  const double raw = rawMeshErrorBound(m, *tape, grid);
  SimplifyOptions so;
  so.tolerance = 0.5;
  const SimplifyStats ss = simplifyMesh(m, tape, grid, so);
  if (m.triangles.empty() || !closureDefect(m.triangles, m.positions.size()).empty()) return std::nullopt;
  out.errorBound = std::max(raw, ss.errorBound);
  out.triangles = m.triangles.size();
  out.res = res;
  std::vector<double> xyz;
  xyz.reserve(3 * m.positions.size());
  for (const auto& p : m.positions) xyz.insert(xyz.end(), p.begin(), p.end());
  std::vector<uint32_t> tris;
  tris.reserve(3 * m.triangles.size());
  for (const auto& t : m.triangles) tris.insert(tris.end(), t.begin(), t.end());
  char what[200];
  std::snprintf(what, sizeof what, "%s sampled on %d^3 points (%zu triangles, within %.3g of its surface)",
                name.c_str(), res, out.triangles, out.errorBound);
  auto field = std::make_shared<MeshField>(std::move(xyz), std::move(tris), what);
  if (!field->check().closed()) return std::nullopt;
  field->setSetErrorBound(out.errorBound);
  out.field = fieldExpr(field, Expr::x(0), Expr::x(1), Expr::x(2));
  return out;
}

// A process compiles one model several times (the CLI, the report, an in-process run), and
// meshing the operand is the costly part: the last few results are kept, each with its operand
// (hash-consed: the same model's operand is the same node while it lives).
struct Sampled {
  Expr a;
  std::vector<double> lo, hi;
  int res;
  std::string name;
  std::optional<SampledOperand> result;
};
std::mutex gMutex;
// Most recent first; never destroyed (its nodes outliving the intern table at exit would crash).
std::deque<Sampled>& gSampled = *new std::deque<Sampled>;
constexpr size_t kKept = 4;

}  // namespace

std::optional<SampledOperand> sampleOperand(const Expr& a, const Bounds& box, int res, const std::string& name) {
  if (res < 8 || res > 1024) throw std::invalid_argument("the sampling grid must have 8 to 1024 points a side");
  {
    std::lock_guard<std::mutex> lock(gMutex);
    for (const Sampled& s : gSampled)
      if (&s.a.node() == &a.node() && s.lo == box.lo && s.hi == box.hi && s.res == res && s.name == name)
        return s.result;
  }
  std::optional<SampledOperand> r = sample(a, box, res, name);
  std::lock_guard<std::mutex> lock(gMutex);
  gSampled.push_front(Sampled{a, box.lo, box.hi, res, name, r});
  if (gSampled.size() > kKept) gSampled.pop_back();
  return r;
}

}  // namespace frep::minkowski
