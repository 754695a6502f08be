// POV-Ray text of the Minkowski algebra's primitives and the `$ … $` scene preprocessor.
#include "frep/io/pov_scene.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <map>
#include <vector>

#include "frep/expressions/tape.h"
#include "frep/io/mesh_writer.h"
#include "frep/meshing/mesh.h"
#include "frep/minkowski_algebra/bidisc.h"
#include "frep/minkowski_algebra/disc_sum_distance.h"
#include "frep/minkowski_algebra/registry.h"

namespace frep::io {
namespace {

using minkowski::Piece;
using minkowski::PieceKind;
using minkowski::Reduction;
using minkowski::Shape;
using minkowski::ShapeKind;
using minkowski::Sum;
using minkowski::Vec3;

std::string num(double v) {
  if (!std::isfinite(v))
    throw PovNonFinite("a size or placement is not a finite number once the terms are summed (" +
                       std::string(std::isnan(v) ? "nan" : "inf") + "): POV-Ray cannot read it; use smaller values");
  char b[40];
  std::snprintf(b, sizeof b, "%.12g", std::fabs(v) < 1e-15 ? 0.0 : v);
  return b;
}
std::string vec(const Vec3& v) { return "<" + num(v[0]) + ", " + num(v[1]) + ", " + num(v[2]) + ">"; }

// The POV name of a tridiscsphere's mesh2 (one per distinct size).
std::string tridiscsphereName(const Piece& p) {
  const uint64_t h = minkowski::DiscSumField({0, 0, 0}, p.discs, p.ball).contentHash();
  char b[48];
  std::snprintf(b, sizeof b, "frep_tridiscsphere_%016llx", static_cast<unsigned long long>(h));
  return b;
}

std::string pieceText(const Piece& p, double thin) {
  switch (p.kind) {
    case PieceKind::Block: {
      Vec3 lo = p.lo, hi = p.hi;
      for (int i = 0; i < 3; ++i)
        if (hi[i] - lo[i] < thin) {
          double m = 0.5 * (lo[i] + hi[i]);
          lo[i] = m - thin / 2;
          hi[i] = m + thin / 2;
        }
      return "box { " + vec(lo) + ", " + vec(hi) + " }";
    }
    case PieceKind::Cylinder: {
      Vec3 a = p.base, b = p.base;
      double len = p.length;
      if (len < thin) {
        a[p.axis] += 0.5 * len - thin / 2;
        len = thin;
      }
      b = a;
      b[p.axis] += len;
      return "cylinder { " + vec(a) + ", " + vec(b) + ", " + num(std::max(p.radius, thin / 2)) + " }";
    }
    case PieceKind::Sphere:
      return "sphere { " + vec(p.base) + ", " + num(std::max(p.radius, thin / 2)) + " }";
    case PieceKind::Torus: {
      // POV's torus lies in the xz plane around y: turn y onto the axis.
      const char* turn = p.axis == 0 ? " rotate <0, 0, 90>" : p.axis == 2 ? " rotate <90, 0, 0>" : "";
      return "torus { " + num(p.radius) + ", " + num(std::max(p.minor, thin / 2)) + turn + " translate " +
             vec(p.base) + " }";
    }
    case PieceKind::Bicircle: {
      // POV has no bicircle: its quartic, exactly (inside where it is < 0), in the canonical
      // frame of bidisc.h, turned onto the piece's axes (matrix rows: where x, y, z go).
      const double a = p.radius, b = p.minor;
      std::string t = "polynomial { 4";
      for (const minkowski::QuarticTerm& q : minkowski::bicircleTerms(a, b))
        t += ", xyz(" + std::to_string(q.i) + "," + std::to_string(q.j) + "," + std::to_string(q.k) + "): " + num(q.c);
      t += " sturm bounded_by { box { " + vec({-b, -a, -a - b}) + ", " + vec({b, a, a + b}) + " } } matrix <";
      const int rows[3] = {p.axis, p.axis2, 3 - p.axis - p.axis2};
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) t += (c == rows[r] ? "1" : "0") + std::string(", ");
      return t + "0, 0, 0> translate " + vec(p.base) + " }";
    }
    case PieceKind::Tridiscsphere: return "object { " + tridiscsphereName(p) + " translate " + vec(p.base) + " }";
    case PieceKind::Bidisc:
    case PieceKind::DiscSum: break;  // expanded by minkowski::primitives()
  }
  return "";
}

// A tridiscsphere (discs on three axes and/or a ball, the hull of Theorem 5's R12–R16 surfaces,
// whose equations the paper does not give) has no POV primitive: it is declared once as a mesh2,
// polygonised from its exact field (disc_sum_distance.h) by frep's mesher with 40 voxels across
// (vertices on the surface by root finding; the flat disc faces and their rims to within a voxel).
constexpr int kTridiscsphereVoxels = 40;

std::string tridiscsphereDeclaration(const Piece& p) {
  Vec3 ext;
  for (int i = 0; i < 3; ++i) ext[i] = p.discs[0] + p.discs[1] + p.discs[2] - p.discs[i] + p.ball;
  for (double e : ext) num(4 * e);  // its grid's bounds must be finite (throws PovNonFinite)
  const double margin = 2.0 * std::max({ext[0], ext[1], ext[2]}) / kTridiscsphereVoxels;
  const auto field = std::make_shared<minkowski::DiscSumField>(Vec3{0, 0, 0}, p.discs, p.ball);
  const TapePtr tape = Tape::compile(fieldExpr(field, Expr::x(0), Expr::x(1), Expr::x(2)), 3);
  // The lower corner is shifted by a fraction of a voxel so that no grid plane lies on a flat
  // disc face (grid points on the surface make slivers along the face's rim).
  const double shift = 0.3183 * margin;
  const GridSpec grid = GridSpec::fromBounds({-ext[0] - margin - shift, -ext[1] - margin - shift, -ext[2] - margin - shift},
                                             {ext[0] + margin, ext[1] + margin, ext[2] + margin},
                                             kTridiscsphereVoxels + 4);
  MeshOptions o;
  o.threads = 1;
  return povMesh2(meshGrid(tape, grid, o), tridiscsphereName(p));
}

// POV's matrix maps a point P to P·M + T (row vector): M's rows are R's columns.
std::string frameText(const Sum& s) {
  bool identity = minkowski::sameRotation(s.rot, minkowski::identityRotation());
  if (identity) return "translate " + vec(s.offset);
  std::string m = "matrix <";
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m += num(s.rot[c * 3 + r]) + ", ";
  return m + num(s.offset[0]) + ", " + num(s.offset[1]) + ", " + num(s.offset[2]) + ">";
}

// A block eroded by a reduced sum: the box of erosionExpr's block case.
std::string erodedBlock(const Sum& c0, const Reduction& r) {
  Vec3 lo, hi;
  for (int i = 0; i < 3; ++i) {
    Vec3 n{c0.rot[i], c0.rot[3 + i], c0.rot[6 + i]};
    lo[i] = minkowski::supportValue(r, {-n[0], -n[1], -n[2]});
    hi[i] = c0.lengths[i] - minkowski::supportValue(r, n);
    if (lo[i] > hi[i]) return "";  // empty
  }
  Sum frame = c0;
  return "box { " + vec(lo) + ", " + vec(hi) + " " + frameText(frame) + " }";
}

struct Cursor {
  const std::string& text;
  const std::string& file;
  size_t pos;
  std::string where(size_t at) const {
    int line = 1, col = 1;
    for (size_t i = 0; i < at && i < text.size(); ++i) {
      if (text[i] == '\n') {
        ++line;
        col = 1;
      } else {
        ++col;
      }
    }
    return file + ":" + std::to_string(line) + ":" + std::to_string(col);
  }
  [[noreturn]] void fail(size_t at, const std::string& msg) const { throw PovError(where(at) + ": " + msg); }
  void skipSpace() {
    while (pos < text.size() && std::isspace(static_cast<unsigned char>(text[pos]))) ++pos;
  }
};

struct Term {
  Shape shape;
  size_t at;
  std::string text;
};

Term parseTerm(Cursor& c) {
  c.skipSpace();
  Term t;
  t.at = c.pos;
  size_t s = c.pos;
  while (c.pos < c.text.size() && std::isalpha(static_cast<unsigned char>(c.text[c.pos]))) ++c.pos;
  std::string name = c.text.substr(s, c.pos - s);
  if (name.empty()) c.fail(s, "expected a basic-set term (xline, yline, zline, xdisc, ydisc, zdisc, sphere, block)");
  Shape& sh = t.shape;
  size_t sizes = 1;
  if (name.size() == 5 && name.substr(1) == "line" && name[0] >= 'x' && name[0] <= 'z') {
    sh.kind = ShapeKind::Segment;
    sh.axis = name[0] - 'x';
  } else if (name.size() == 5 && name.substr(1) == "disc" && name[0] >= 'x' && name[0] <= 'z') {
    sh.kind = ShapeKind::Disc;
    sh.axis = name[0] - 'x';
  } else if (name == "sphere") {
    sh.kind = ShapeKind::Sphere;
  } else if (name == "block") {
    sh.kind = ShapeKind::Block;
    sizes = 3;
  } else {
    c.fail(s, "'" + name + "' is not in the basic set (xline, yline, zline, xdisc, ydisc, zdisc, sphere, block)");
  }
  c.skipSpace();
  if (c.pos >= c.text.size() || c.text[c.pos] != '(') c.fail(c.pos, "expected '(' after " + name);
  ++c.pos;
  std::vector<double> v;
  for (;;) {
    c.skipSpace();
    const char* b = c.text.c_str() + c.pos;
    char* e = nullptr;
    double d = std::strtod(b, &e);
    if (e == b || !std::isfinite(d)) c.fail(c.pos, "expected a number in " + name + "(...)");
    v.push_back(d);
    c.pos += static_cast<size_t>(e - b);
    c.skipSpace();
    if (c.pos < c.text.size() && c.text[c.pos] == ',') {
      ++c.pos;
      continue;
    }
    if (c.pos < c.text.size() && c.text[c.pos] == ')') {
      ++c.pos;
      break;
    }
    c.fail(c.pos, "expected ',' or ')' in " + name + "(...)");
  }
  if (v.size() != sizes && v.size() != sizes + 3)
    c.fail(t.at, name + " takes " + std::to_string(sizes) + " size" + (sizes > 1 ? "s" : "") +
                     ", optionally followed by its placement x, y, z (got " + std::to_string(v.size()) + " numbers)");
  for (size_t i = 0; i < sizes; ++i) sh.size[i] = v[i];
  if ((sh.kind == ShapeKind::Disc || sh.kind == ShapeKind::Sphere) && sh.size[0] < 0)
    c.fail(t.at, name + ": the radius must be >= 0");
  if (v.size() == sizes + 3) sh.pos = {v[sizes], v[sizes + 1], v[sizes + 2]};
  t.text = c.text.substr(t.at, c.pos - t.at);
  return t;
}

// One `$ … $` term from just after the opening '$' to after the closing one.
std::string translateTerm(Cursor& c, double thin) {
  std::vector<Term> terms{parseTerm(c)};
  int op = 0;  // 1 sum, 2 difference
  for (;;) {
    c.skipSpace();
    if (c.pos < c.text.size() && c.text[c.pos] == '$') {
      ++c.pos;
      break;
    }
    const size_t at = c.pos;
    int here = c.text.compare(c.pos, 3, "<+>") == 0 ? 1 : c.text.compare(c.pos, 3, "<->") == 0 ? 2 : 0;
    if (here == 0) c.fail(at, "expected <+>, <-> or the closing $");
    if (op != 0 && here != op)
      c.fail(at, "a term mixes <+> and <->; write C0 <-> C1 <-> ... (eq. 19) or a sum, not both");
    op = here;
    c.pos += 3;
    terms.push_back(parseTerm(c));
  }
  const size_t first = op == 2 ? 1 : 0;
  Sum sum;
  for (size_t i = first; i < terms.size(); ++i) {
    if (!sum.add(terms[i].shape)) c.fail(terms[i].at, terms[i].text + ": not in the frame of the sum");
    if (!minkowski::reduce(sum).ok)
      c.fail(terms[i].at, terms[i].text + " makes the sum not reducible: " + minkowski::reduce(sum).reason +
                              "; export a mesh instead (frep mesh model.hf -O model.inc)");
  }
  Reduction r = minkowski::reduce(sum);
  if (op != 2) {
    try {
      return povUnion(r, thin);
    } catch (const PovNonFinite& e) {
      c.fail(terms[0].at, e.what());
    }
  }
  Sum c0 = minkowski::sumOf(terms[0].shape);
  if (terms[0].shape.kind != ShapeKind::Block && terms[0].shape.kind != ShapeKind::Segment)
    c.fail(terms[0].at, terms[0].text + " <-> ...: only a block can be eroded into POV primitives (a box)");
  std::string box;
  try {
    box = erodedBlock(c0, r);
  } catch (const PovNonFinite& e) {
    c.fail(terms[0].at, e.what());
  }
  if (box.empty()) c.fail(terms[0].at, terms[0].text + " <-> ...: the erosion is empty");
  return box;
}

}  // namespace

std::string povUnion(const Reduction& r, double thin) {
  const std::vector<Piece> prims = minkowski::primitives(r);
  std::string s;
  std::map<std::string, bool> declared;
  for (const Piece& p : prims)
    if (p.kind == PieceKind::Tridiscsphere && !declared[tridiscsphereName(p)]) {
      declared[tridiscsphereName(p)] = true;
      s += tridiscsphereDeclaration(p);
    }
  s += "union { // " + r.sum.describe() + ": " + std::to_string(prims.size()) + " primitives (Roerdink-Minkowski)\n";
  for (const Piece& p : prims) s += "  " + pieceText(p, thin) + "\n";
  return s + "  " + frameText(r.sum) + "\n}";
}

std::string translateScene(const std::string& text, const std::string& fileName, double thin) {
  std::string out;
  Cursor c{text, fileName, 0};
  while (c.pos < text.size()) {
    // POV comments and strings are copied as they are (a '$' in them is not a term).
    if (text.compare(c.pos, 2, "//") == 0 || text.compare(c.pos, 2, "/*") == 0 || text[c.pos] == '"') {
      const bool line = text[c.pos + 1] == '/', str = text[c.pos] == '"';
      size_t e = str ? text.find('"', c.pos + 1) : line ? text.find('\n', c.pos) : text.find("*/", c.pos + 2);
      e = e == std::string::npos ? text.size() : e + (line ? 0 : str ? 1 : 2);
      out += text.substr(c.pos, e - c.pos);
      c.pos = e;
      continue;
    }
    if (text[c.pos] != '$') {
      out += text[c.pos++];
      continue;
    }
    ++c.pos;
    out += translateTerm(c, thin);
  }
  return out;
}

std::string povFromField(const Expr& f, double thin, Expr* offending) {
  if (std::optional<minkowski::ExactTerm> t = minkowski::lookupExact(f);
      t && (t->kind == minkowski::ExactTerm::Kind::Sum || t->kind == minkowski::ExactTerm::Kind::Erosion)) {
    Reduction r = minkowski::reduce(t->sum);
    if (t->kind == minkowski::ExactTerm::Kind::Sum) return povUnion(r, thin);
    if (t->c0.ball == 0 && t->c0.discAxes() == 0) {
      std::string box = erodedBlock(t->c0, r);
      if (!box.empty()) return box;
    }
  }
  auto both = [&](const char* csg) {
    return std::string(csg) + " {\n" + povFromField(f.arg(0), thin, offending) + "\n" +
           povFromField(f.arg(1), thin, offending) + "\n}";
  };
  switch (f.op()) {
    case Op::Max:
    case Op::ROr: return both("union");
    case Op::Min:
    case Op::RAnd: return both("intersection");
    case Op::Neg: return "object { " + povFromField(f.arg(0), thin, offending) + " inverse }";
    default: break;
  }
  *offending = f;
  throw PovError("not a basic-set term");
}

}  // namespace frep::io
