// Closed mesh ⊕ / ⊖ convex polytope without a search (mesh_convex_sum.h).
#include "frep/minkowski_algebra/mesh_convex_sum.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "frep/geometry/cell_lists.h"
#include "frep/geometry/distance_fields.h"
#include "frep/minkowski_algebra/convex_cover.h"
#include "frep/minkowski_algebra/convex_polytope.h"
#include "frep/minkowski_algebra/registry.h"
#include "frep/minkowski_algebra/star_pieces.h"
#include "convolution_pieces.h"
#include "mesh_operands.h"
#include "triangle_sum_cells.h"

namespace frep::minkowski {
namespace {

using namespace vec3;
using namespace mesh_operands;

// See mesh_convex_sum.h. complement: the field of A^c ⊕ B (for the difference, B = -B).
class MeshConvexSumField : public DistanceField {
 public:
  // B is the union of the convex pieces bs (one for a convex B; convex_cover.h or
  // star_pieces.h otherwise, B connected either way): A ⊕ B = (A + b0) ∪ ⋃_{T, i} (T ⊕ B_i), and the
  // boundary pieces of every A ⊕ B_i together cover its boundary.
  MeshConvexSumField(const Mesh& a, std::shared_ptr<const MeshField> aField, const std::vector<Convex>& bs,
                     bool complement, std::string name)
      : a_(std::move(aField)), complement_(complement), name_(std::move(name)) {
    // b0: the first piece's vertex centroid, an interior point; every cell T ⊕ B_0 then holds
    // the r-neighbourhood of T + b0 (r: b0's distance to B_0's facets), so a point in no cell is
    // at least r from ∂A + b0 and its class under f_A(x - b0) holds within r of it (sumClass).
    const Convex& b0Piece = bs.front();
    for (const V3& p : b0Piece.v) b0_ = {b0_[0] + p[0], b0_[1] + p[1], b0_[2] + p[2]};
    const double nb = double(b0Piece.v.size());
    b0_ = {b0_[0] / nb, b0_[1] / nb, b0_[2] / nb};
    memoRadius_ = INFINITY;
    for (const V3& n : b0Piece.faceN) memoRadius_ = std::min(memoRadius_, b0Piece.support(n) - dot(n, b0_));
    if (!(memoRadius_ > 0) || !std::isfinite(memoRadius_)) memoRadius_ = 0;
    memoRadius_ *= 0.5;  // half: rounding of the cells' tests cannot matter
    double scale = extentOf(a.v);
    for (const Convex& b : bs) scale = std::max(scale, extentOf(b.v));
    const double tol = 1e-9 * scale;
    std::vector<double> soup;
    std::vector<uint32_t> soupTris;
    auto tri = [&](const V3& p, const V3& q, const V3& r) {
      const uint32_t base = uint32_t(soup.size() / 3);
      for (const V3* x : {&p, &q, &r}) soup.insert(soup.end(), x->begin(), x->end());
      soupTris.insert(soupTris.end(), {base, base + 1, base + 2});
    };
    std::vector<std::vector<V3>> pieceDirs;
    for (const Convex& b : bs) {
      pieceDirs.push_back(edgeDirections(b));
      cellSet_.add(a, b, pieceDirs.back(), tol);
    }
    cellBvh_.build(cellSet_.boxes);
    // Lists for a lattice of 128 cells along the boxes' longest side: a point's query then
    // tests one short list instead of walking the many overlapping boxes of the hierarchy.
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (const Bvh::Box& x : cellSet_.boxes)
      for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], x.lo[k]), hi[k] = std::max(hi[k], x.hi[k]);
    lattice_ = CellLattice::over(lo, hi, 128, 0);
    // The rounding of a plane's value at a lattice cell's centre and of |p - c|, far above it.
    centreSlack_ = 1e-9 * lattice_.size + 1e-14 * (std::abs(lo[0]) + std::abs(lo[1]) + std::abs(lo[2]) +
                                                   std::abs(hi[0]) + std::abs(hi[1]) + std::abs(hi[2]));
    cellClasses_ = lattice_.size * std::sqrt(3.0) < 1.9 * memoRadius_;
    for (size_t i = 0; i < bs.size(); ++i) convolutionPieces(a, bs[i], pieceDirs[i], complement_, tol, tri);
    pruneInterior(soup, soupTris, tol);
    pieces_ = soupTris.size() / 3;
    soup_ = std::make_shared<MeshField>(std::move(soup), std::move(soupTris), "boundary pieces");
    uint64_t h = a_->contentHash() ^ (complement_ ? 0x9e3779b97f4a7c15ULL : 0);
    for (const Convex& b : bs)
      for (const V3& p : b.v)
        for (double d : p) {
          uint64_t bits;
          std::memcpy(&bits, &d, sizeof bits);
          h = (h ^ bits) * 0x100000001b3ULL;
        }
    hash_ = h;
  }

  double value(const double p[3]) const override {
    const double f = sumField(p, nullptr);
    return complement_ ? -f : f;
  }

 private:
 public:
  void signs(const double* u, const double* v, const double* w, double* out, size_t n) const override {
    for (size_t i = 0; i < n; ++i) {
      const double p[3] = {u[i], v[i], w[i]};
      const double f = sumClass(p);
      out[i] = complement_ ? -f : f;
    }
  }
  double gradient(const double p[3], double g[3]) const override {
    double q[3];
    const double f = sumField(p, q);
    if (f < 0) {  // outside the sum: the exact distance's gradient from the nearest point
      gradientFromNearest(f, p, q, g);
      if (complement_) g[0] = -g[0], g[1] = -g[1], g[2] = -g[2];
      return complement_ ? -f : f;
    }
    return DistanceField::gradient(p, g);
  }
  uint64_t contentHash() const override { return hash_; }
  std::string describe() const override { return name_; }
  double setErrorBound() const override { return a_->setErrorBound(); }
  bool exactOutside() const override { return !complement_; }
  bool exactInside() const override { return complement_; }
  size_t pieces() const { return pieces_; }

 private:
  std::shared_ptr<const MeshField> a_;
  bool complement_;
  std::string name_;
  V3 b0_{};
  double memoRadius_ = 0;
  uint64_t id_ = CellLists::newOwner();  // the memo's and lists' key (an address may be reused)
  struct SignMemo {
    uint64_t owner;
    double x[3];
    bool inside;
  };
  static constexpr int kSignMemos = 4;
  // The class of the points of a lattice cell that lie in no T ⊕ B, per thread (4096 cells,
  // direct-mapped): one class serves them all when the cell's diameter is below 2 memoRadius_
  // (cellClasses_). Such points are at least 2 memoRadius_ (less rounding) from ∂A + b0, so a
  // segment joining two of them, no longer than the diameter, cannot cross it.
  struct ClassOfCell {
    uint64_t owner, key;
    bool inside;
  };
  static thread_local ClassOfCell tClassOfCell[4096];
  bool cellClasses_ = false;
  static thread_local SignMemo tSignMemo[kSignMemos];
  static thread_local int tSignMemoNext;
  static constexpr uint32_t kNoLead = UINT32_MAX;
  using Cell = TriangleSumCells::Cell;
  TriangleSumCells cellSet_;  // the cells T ⊕ B: their planes and boxes
  Bvh cellBvh_;
  CellLattice lattice_;  // of the lists of cells whose boxes meet a lattice cell
  double centreSlack_ = 0;
  std::shared_ptr<const MeshField> soup_;
  size_t pieces_ = 0;
  uint64_t hash_ = 0;

  // Drops the pieces that lie in the interior of one convex T ⊕ B (all three corners strictly
  // inside it) or of A + b0 (a ball about the centroid holding the triangle inside A): they hold
  // no boundary point, so the rest still covers the boundary and the distance stays exact.
  // Each triangle's test is a pure function of it (the lists and caches only speed it up), so
  // the triangles are tested in parallel and the kept ones gathered in their order.
  void pruneInterior(std::vector<double>& soup, std::vector<uint32_t>& tris, double tol) const {
    auto depth = [&](uint32_t cell, const double* p) {
      const Cell& c = cellSet_.cells[cell];
      double m = INFINITY;
      for (uint32_t k = c.first; k < c.first + c.count && m > tol; ++k) {
        const auto& u = cellSet_.planes[k];
        m = std::min(m, u[3] - (u[0] * p[0] + u[1] * p[1] + u[2] * p[2]));
      }
      return m;
    };
    auto isInterior = [&](size_t t) {
      const double* v[3] = {&soup[3 * tris[t]], &soup[3 * tris[t + 1]], &soup[3 * tris[t + 2]]};
      double c[3], r2 = 0;
      for (int k = 0; k < 3; ++k) c[k] = (v[0][k] + v[1][k] + v[2][k]) / 3;
      for (const double* p : v)
        r2 =
            std::max(r2, (p[0] - c[0]) * (p[0] - c[0]) + (p[1] - c[1]) * (p[1] - c[1]) + (p[2] - c[2]) * (p[2] - c[2]));
      const double shifted[3] = {c[0] - b0_[0], c[1] - b0_[1], c[2] - b0_[2]};
      double inA = a_->value(shifted);
      if (complement_) inA = -inA;
      bool interior = inA > std::sqrt(r2) + tol;
      // A cell holding v[0] with a margin is in v[0]'s lattice list (or, without one, among the
      // boxes that hold it): either way the same cells decide, the list the fewer.
      auto inCell = [&](uint32_t cell) {
        interior = depth(cell, v[0]) > tol && depth(cell, v[1]) > tol && depth(cell, v[2]) > tol;
        return !interior;
      };
      uint32_t count = 0;
      double pc2;
      const uint32_t* list = interior ? nullptr : cellsNear(v[0], count, pc2);
      if (list)
        for (uint32_t j = 0; j < count && inCell(list[j]); j += kListWords) {}
      else if (!interior) cellBvh_.containing(v[0], inCell);
      return interior;
    };
    std::vector<char> interior(tris.size() / 3);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, interior.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i != r.end(); ++i) interior[i] = isInterior(3 * i);
    });
    std::vector<uint32_t> kept;
    for (size_t i = 0; i < interior.size(); ++i)
      if (!interior[i]) kept.insert(kept.end(), {tris[3 * i], tris[3 * i + 1], tris[3 * i + 2]});
    if (kept.empty() && !tris.empty()) kept.assign(tris.begin(), tris.begin() + 3);  // MeshField needs one
    tris.swap(kept);
  }

  // The field of (A or A^c) ⊕ B, q the nearest boundary point where it is negative.
  // In a T ⊕ B the largest c_T is returned alone (a lower bound of the depth, like the max with
  // f_A: the sign certificates need no more), which saves the query of A near the surface;
  // elsewhere f_A(x - b0) where it is >= 0, else (outside) the distance to the boundary pieces,
  // their search bounded by dist(x, sum) <= dist(x - b0, A) — or not at all where the lattice
  // cell's class says outside already (the pieces' own lists need no bound).
  double sumField(const double* p, double* q) const {
    const double g = cellsValue(p);
    if (g >= 0) return g;
    ClassOfCell* cached = cellClass(p);
    if (cached && cached->owner == id_ && !cached->inside) return -soup_->distance(p, q);
    const double inA = translateValue(p);
    if (cached && !std::isnan(inA)) *cached = {id_, cached->key, inA >= 0};
    if (inA >= 0) return inA;
    return -soup_->distance(p, q, -inA);
  }
  // sumField's class without the distance to the pieces: outside, its value is -dist <= 0,
  // which reads as outside except on a piece (-0, inside), where either class is right. A point
  // in no cell has the class its lattice cell recorded (cellClass), or that of a point within
  // memoRadius_ classified before (see the constructor).
  double sumClass(const double* p) const {
    const double g = cellsValue(p, true);
    if (g >= 0) return g;
    ClassOfCell* cached = cellClass(p);
    if (cached && cached->owner == id_) return cached->inside ? memoRadius_ : -INFINITY;
    if (memoRadius_ > 0)
      for (SignMemo& m : tSignMemo) {
        if (m.owner != id_) continue;
        const double dx = p[0] - m.x[0], dy = p[1] - m.x[1], dz = p[2] - m.x[2];
        if (dx * dx + dy * dy + dz * dz < memoRadius_ * memoRadius_) return m.inside ? memoRadius_ : -INFINITY;
      }
    const double inA = translateValue(p, true);
    if (std::isnan(inA)) return sumField(p, nullptr);
    if (memoRadius_ > 0) {
      tSignMemo[tSignMemoNext] = {id_, {p[0], p[1], p[2]}, inA >= 0};
      tSignMemoNext = (tSignMemoNext + 1) % kSignMemos;
    }
    if (cached) *cached = {id_, cached->key, inA >= 0};
    return inA >= 0 ? inA : -INFINITY;
  }
  // This thread's record of the class of p's lattice cell (for the points in no cell): this
  // field's when its owner is id_ and it holds the cell's key (else to be filled), or nothing
  // when cells are too large for one class (cellClasses_) or p is off the lattice.
  ClassOfCell* cellClass(const double* p) const {
    uint64_t key;
    int64_t ijk[3];
    if (!cellClasses_ || !lattice_.cellOf(p, key, ijk)) return nullptr;
    ClassOfCell* c = &tClassOfCell[(key * 0x9E3779B97F4A7C15ULL) >> 52];
    if (c->key != key) c->owner = 0, c->key = key;
    return c;
  }
  // f_A(p - b0), negated for the complement: the translate A + b0's field.
  // classOnly: a value of the same sign (MeshField::classValue) will do.
  double translateValue(const double* p, bool classOnly = false) const {
    const double shifted[3] = {p[0] - b0_[0], p[1] - b0_[1], p[2] - b0_[2]};
    const double f = classOnly ? a_->classValue(shifted) : a_->value(shifted);
    return complement_ ? -f : f;
  }
  // max_T c_T(p) over the cells whose box holds p (-inf: none). firstInside: any c_T >= 0 will
  // do (the class is all that is asked), so the first cell holding p ends the search.
  double cellsValue(const double* p, bool firstInside = false) const {
    double g = -INFINITY;
    // A cell's planes stop as soon as its c_T cannot raise g (or, for the class, is negative).
    const double floor = firstInside ? 0.0 : -INFINITY;
    // lead: a plane of the cell to try first (the one farthest below the lattice cell's centre,
    // which separates most points of the lattice cell outside the cell), or kNoLead. Its value
    // joins the facets' min: inside the cell it is no smaller (a supporting plane), outside
    // the min is negative either way.
    auto visit = [&](uint32_t i, uint32_t lead) {
      const Cell& c = cellSet_.cells[i];
      double m = INFINITY;
      if (lead != kNoLead) {
        const auto& u = cellSet_.planes[c.first + lead];
        m = u[3] - (u[0] * p[0] + u[1] * p[1] + u[2] * p[2]);
      }
      const double stop = std::max(g, floor);
      for (uint32_t k = c.first; k < c.first + c.count && m >= stop && (m > g || firstInside); ++k) {
        const auto& u = cellSet_.planes[k];
        m = std::min(m, u[3] - (u[0] * p[0] + u[1] * p[1] + u[2] * p[2]));
      }
      if (m >= floor) g = std::max(g, m);
      return !(firstInside && g >= 0);
    };
    uint32_t count = 0;
    double pc2 = 0;
    const uint32_t* list = cellsNear(p, count, pc2);
    if (!list) {
      cellBvh_.containing(p, [&](uint32_t i) { return visit(i, kNoLead); });
      return g;
    }
    // The class: c_T is 1-Lipschitz (unit normals), so the first cell's c_T at the centre
    // beyond |p - c| puts p inside it (the list is sorted by that value, the first is the
    // largest), with no plane tested. |p - c| (rounded up) only when that value is positive.
    if (firstInside && count > 0 && listDepth(list) >= centreSlack_) {
      const double depth = listDepth(list) - (std::sqrt(pc2) * (1 + 1e-9) + centreSlack_);
      if (depth >= 0) return depth;
    }
    // The list holds every cell that may hold a point of p's lattice cell; those that hold p
    // give the same max as the hierarchy's, the others have c_T < 0 at p, which no caller reads
    // (testing their boxes first, to pass them over, took 5% longer than the lead plane alone).
    for (uint32_t j = 0; j < count; j += kListWords)
      if (!visit(list[j], list[j + 1])) break;
    return g;
  }
  // The cells that can hold a point of the lattice cell holding p (at most 512), or nothing:
  // those whose boxes meet it, less those a plane of theirs separates from it, ordered by
  // their c_T at the cell's centre, largest first. A point's max c_T then often comes first
  // (the class search ends at it; the max prunes the rest), and a dropped cell has c_T < 0 at
  // every point of the lattice cell, which no caller reads (only g >= 0 counts). Per cell
  // kListWords: its index, its plane of least value at the centre (visit's lead) and that value
  // as a float rounded down (the first one's: listDepth); count: the words. pc2: |p - c|^2,
  // c the lattice cell's centre.
  static constexpr uint32_t kListWords = 3;
  static double listDepth(const uint32_t* list) { return double(floatOfBits(list[2])); }
  const uint32_t* cellsNear(const double* p, uint32_t& count, double& pc2) const {
    uint64_t key;
    int64_t ijk[3];
    if (!lattice_.cellOf(p, key, ijk)) return nullptr;
    double lo[3], hi[3];
    lattice_.cellBox(ijk, lo, hi);
    const double pc[3] = {p[0] - (lo[0] + hi[0]) / 2, p[1] - (lo[1] + hi[1]) / 2, p[2] - (lo[2] + hi[2]) / 2};
    pc2 = pc[0] * pc[0] + pc[1] * pc[1] + pc[2] * pc[2];
    return CellLists::get(id_, key, count, [&](std::vector<uint32_t>& out) {
      Bvh::Box q;
      for (int k = 0; k < 3; ++k) q.lo[k] = lo[k], q.hi[k] = hi[k];
      // A little beyond the cell: a point may be placed in it from a few ulps outside.
      const double eps = 1e-9 * lattice_.size;
      const double centre[3] = {(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2};
      struct Found {
        double atCentre;
        uint32_t cell, lead;
      };
      std::vector<Found> found;
      bool fits = true;
      cellBvh_.nearBox(q, eps, [&](uint32_t, uint32_t i) {
        const Bvh::Box& b = cellSet_.boxes[i];
        for (int k = 0; k < 3; ++k)
          if (b.lo[k] > q.hi[k] + eps || b.hi[k] < q.lo[k] - eps) return true;
        const Cell& c = cellSet_.cells[i];
        double atCentre = INFINITY;
        uint32_t lead = 0;
        for (uint32_t k = c.first; k < c.first + c.all; ++k) {
          const auto& u = cellSet_.planes[k];
          double least = 0;  // min of u . x over the cell grown by eps
          for (int a = 0; a < 3; ++a) least += u[size_t(a)] * (u[size_t(a)] > 0 ? lo[a] - eps : hi[a] + eps);
          if (least > u[3] + eps) return true;  // the plane separates them (eps: its rounding)
          const double v = u[3] - (u[0] * centre[0] + u[1] * centre[1] + u[2] * centre[2]);
          if (v < atCentre) atCentre = v, lead = k - c.first;
        }
        found.push_back({atCentre, i, lead});
        fits = found.size() <= 512;
        return fits;
      });
      if (!fits) return false;
      // Largest first; ties by index, so a list never depends on the hierarchy's visiting order.
      std::sort(found.begin(), found.end(), [](const Found& x, const Found& y) {
        return x.atCentre != y.atCentre ? x.atCentre > y.atCentre : x.cell < y.cell;
      });
      for (const Found& f : found) {
        out.insert(out.end(), {f.cell, f.lead, bitsOfFloat(floatBelow(f.atCentre - centreSlack_))});
      }
      return true;
    });
  }
  bool sameGeometry(const DistanceField& o) const override {
    const auto& m = static_cast<const MeshConvexSumField&>(o);
    return m.complement_ == complement_ && m.cellSet_.planes == cellSet_.planes && m.a_->sameContent(*a_);
  }
};

thread_local MeshConvexSumField::SignMemo MeshConvexSumField::tSignMemo[MeshConvexSumField::kSignMemos] = {};
thread_local int MeshConvexSumField::tSignMemoNext = 0;
thread_local MeshConvexSumField::ClassOfCell MeshConvexSumField::tClassOfCell[4096] = {};

// A tool cut into more pieces than this is left to the search: each piece adds a copy of A's
// cells; so is a path of more segments.
constexpr size_t kMaxPieces = 64;

// The field of A ⊕ B (difference: of A^c ⊕ B, the pieces of B already negated) for the closed
// mesh a read from aExpr (scaled by scaleA) and B the union of the convex pieces bs, registered:
// "<name> as the union of the mesh's translate and N boundary pieces of triangle ⊕ <kind> sums".
Expr assemble(const Mesh& a, const Expr& aExpr, double scaleA, const std::vector<Convex>& bs, bool difference,
              const std::string& name, const char* kind) {
  std::vector<double> xyz;
  for (const V3& p : a.v) xyz.insert(xyz.end(), p.begin(), p.end());
  std::vector<uint32_t> tris;
  for (const auto& t : a.t) tris.insert(tris.end(), t.begin(), t.end());
  auto aField = std::make_shared<MeshField>(std::move(xyz), std::move(tris), a.what);
  if (aExpr.op() == Op::Field) aField->setSetErrorBound(aExpr.node().fn->setErrorBound() * scaleA);
  auto field = std::make_shared<MeshConvexSumField>(a, aField, bs, difference, name);
  Expr out = fieldExpr(field, Expr::x(0), Expr::x(1), Expr::x(2));
  ExactTerm t;
  t.kind = ExactTerm::Kind::MeshPolytope;
  t.operand = name + " as the union of the mesh's translate and " + std::to_string(field->pieces()) +
              " boundary pieces of triangle ⊕ " + kind + " sums";
  t.erosion = difference;
  t.exactOutside = !difference;
  t.exactInside = difference;
  t.errorBound = field->setErrorBound();
  registerExact(out, t);
  return out;
}

// pieces: a B that is not convex may be covered by convex pieces (convex_cover.h), each of which
// adds a copy of A's cells, so the callers try the convex forms first.
bool construct(const Expr& aExpr, const Expr& bExpr, bool difference, bool pieces, Expr* out, double scaleA,
               double scaleB) {
  bool aPoly = false, bPoly = false;
  std::optional<Mesh> b = closedMeshOf(bExpr, &bPoly);
  // A union of polytopes (a difference of blocks, say) is its own cover (convex_polytope.h);
  // the construction's one translate A + b0 needs the tool connected.
  std::optional<PolytopeUnion> bUnion;
  if (!b && pieces && scaleB == 1 && (bUnion = polytopeUnionOf(bExpr)) && bUnion->corners.size() == bUnion->pieces &&
      bUnion->pieces <= kMaxPieces && bUnion->connected())
    b = Mesh{};
  else bUnion.reset();
  if (!b) return false;
  std::optional<Mesh> a = closedMeshOf(aExpr, &aPoly);
  if (!a) return false;
  scaleMesh(*a, scaleA);
  scaleMesh(*b, scaleB);
  if (bUnion)
    for (const auto& c : bUnion->corners) b->v.insert(b->v.end(), c.begin(), c.end());  // for the scale
  const double scale = std::max(extentOf(a->v), extentOf(b->v));
  std::vector<Convex> bs;
  std::string bWhat = bUnion ? bUnion->describe() : b->what;
  if (bUnion) {
    for (const auto& c : bUnion->corners) {
      std::optional<PieceMesh> hull = convexHullMesh(c, 1e-9 * scale);
      std::optional<Convex> k = hull ? convexOf(Mesh{hull->v, hull->t, ""}, scale) : std::nullopt;
      if (!k) return false;
      bs.push_back(std::move(*k));
    }
  } else if (std::optional<Convex> cb = convexOf(*b, scale)) {
    if (pieces) return false;  // the convex form was tried first
    bs.push_back(std::move(*cb));
  } else {
    if (!pieces || b->t.size() > 4096) return false;
    // A cover by overlapping convex pieces (convex_cover.h: fewer and fuller, any tool), else
    // the pyramids from a kernel point.
    auto star = convexCover(b->v, b->t, kMaxPieces);
    if (!star) star = starConvexPieces(b->v, b->t, 1e-6 * scale, kMaxPieces);
    if (!star) return false;
    for (const PieceMesh& pm : *star) {
      std::optional<Convex> c = convexOf(Mesh{pm.v, pm.t, ""}, scale);
      if (!c) return false;
      bs.push_back(std::move(*c));
    }
    bWhat += " as " + std::to_string(bs.size()) + " convex pieces";
  }
  if (difference)
    for (Convex& cb : bs) {
      for (V3& p : cb.v) p = {-p[0], -p[1], -p[2]};
      for (auto& f : cb.faces)
        for (V3& p : f) p = {-p[0], -p[1], -p[2]};
      for (V3& n : cb.faceN) n = {-n[0], -n[1], -n[2]};
    }
  *out = assemble(*a, aExpr, scaleA, bs, difference, a->what + (difference ? " ⊖ " : " ⊕ ") + bWhat, "polytope");
  return true;
}

// A ⊕ P for the polyline P through path: P is connected and the union of its segments, each a
// convex piece with no facets (support max(u · p, u · q), one edge), so the construction above
// applies as it is, the flat cells aside (TriangleSumCells::add). Repeated points are dropped; a single point
// is the segment [p, p] (A moved there).
bool constructPath(const Expr& aExpr, const std::vector<V3>& path, Expr* out) {
  bool aPoly = false;
  std::optional<Mesh> a = closedMeshOf(aExpr, &aPoly);
  if (!a || path.empty()) return false;
  std::vector<V3> pts;
  for (const V3& p : path)
    if (pts.empty() || p != pts.back()) pts.push_back(p);
  if (pts.size() == 1) pts.push_back(pts[0]);
  if (pts.size() - 1 > kMaxPieces) return false;
  std::vector<Convex> bs;
  for (size_t i = 0; i + 1 < pts.size(); ++i) {
    Convex c;
    c.v = {pts[i], pts[i + 1]};
    if (pts[i] != pts[i + 1]) c.edges.push_back({0, 1});
    bs.push_back(std::move(c));
  }
  const std::string name = "sweep of " + a->what + " along a path of " + std::to_string(path.size()) + " points (" +
                           std::to_string(bs.size()) + (bs.size() == 1 ? " segment)" : " segments)");
  *out = assemble(*a, aExpr, 1, bs, false, name, "segment");
  return true;
}

// A process compiles one model several times (the CLI for its bounds and its report, an
// in-process run for itself), and constructing the field (cells, lattice lists, pruned pieces)
// costs seconds for a large mesh: the results, failures too, are kept for the last few operand
// pairs (or operand and path). Operands are hash-consed (a mesh read again is the same node while
// one is alive), and an entry holds its operands, so the same model finds its entry.
struct BuildKey {
  const Node *a, *b;  // b: none for a path
  bool difference, pieces;
  double scaleA, scaleB;
  std::vector<V3> path;
  bool operator==(const BuildKey& o) const {
    return a == o.a && b == o.b && difference == o.difference && pieces == o.pieces && scaleA == o.scaleA &&
           scaleB == o.scaleB && path == o.path;
  }
};
struct BuildEntry {
  BuildKey key;
  Expr a, b;  // keep the operands' nodes alive (and so the key's pointers unique)
  std::optional<Expr> result;
};
std::mutex gBuildMutex;
// Most recent first; never destroyed (its nodes outliving the intern table at exit would crash).
std::deque<BuildEntry>& gBuilt = *new std::deque<BuildEntry>;
constexpr size_t kBuildsKept = 8;

template <typename Construct>
bool cached(const BuildKey& key, const Expr& aExpr, const Expr& bExpr, Construct&& construct, Expr* out) {
  {
    std::lock_guard<std::mutex> lock(gBuildMutex);
    for (const BuildEntry& e : gBuilt)
      if (e.key == key) {
        if (e.result) *out = *e.result;
        return e.result.has_value();
      }
  }
  Expr r;
  const bool ok = construct(&r);
  std::lock_guard<std::mutex> lock(gBuildMutex);
  gBuilt.push_front(BuildEntry{key, aExpr, bExpr, ok ? std::optional<Expr>(r) : std::nullopt});
  if (gBuilt.size() > kBuildsKept) gBuilt.pop_back();
  if (ok) *out = r;
  return ok;
}

bool build(const Expr& aExpr, const Expr& bExpr, bool difference, bool pieces, Expr* out, double scaleA = 1,
           double scaleB = 1) {
  const BuildKey key{&aExpr.node(), &bExpr.node(), difference, pieces, scaleA, scaleB, {}};
  return cached(
      key, aExpr, bExpr, [&](Expr* r) { return construct(aExpr, bExpr, difference, pieces, r, scaleA, scaleB); }, out);
}

}  // namespace

bool meshConvexSum(const Expr& a, const Expr& b, uint32_t dims, Expr* out) {
  if (dims != 3) return false;
  for (bool pieces : {false, true})
    if (build(a, b, false, pieces, out) || build(b, a, false, pieces, out)) return true;
  return false;
}

bool meshConvexMorph(const Expr& a, const Expr& b, double t, Expr* out) {
  if (!(t > 0 && t < 1)) return false;
  for (bool pieces : {false, true})
    if (build(a, b, false, pieces, out, 1 - t, t) || build(b, a, false, pieces, out, t, 1 - t)) return true;
  return false;
}

bool meshConvexDifference(const Expr& a, const Expr& b, uint32_t dims, Expr* out) {
  if (dims != 3) return false;
  return build(a, b, true, false, out) || build(a, b, true, true, out);
}

bool meshPathSum(const Expr& a, const std::vector<Vec3>& path, Expr* out) {
  const BuildKey key{&a.node(), nullptr, false, false, 1, 1, path};
  return cached(
      key, a, Expr(), [&](Expr* r) { return constructPath(a, path, r); }, out);
}

}  // namespace frep::minkowski
