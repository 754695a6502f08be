// The Python module `frepfarm`: HyperFun models compiled by frep_lang, evaluated by the core's
// batch evaluator on NumPy arrays, sampled and meshed by the core, written by frep_io (docs/python.md).
#include <cmath>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <cstdlib>
#include <string>
#include <unistd.h>
#include <vector>

#include "frep/evaluators/eval.h"
#include "frep/io/atomic_output.h"
#include "frep/io/error.h"
#include "frep/io/geometry_files.h"
#include "frep/io/input_file.h"
#include "frep/io/mesh_writer.h"
#include "frep/io/vdb_writer.h"
#include "frep/io/world_lattice.h"
#include "frep/lang/field.h"
#include "frep/lang/hyperfun.h"
#include "frep/measure/mass_properties.h"
#include "frep/meshing/mesh.h"
#include "frep/primitives/ops.h"
#include "frep/meshing/mesh_simplify.h"
#include "frep/sampling/sample.h"
#include "interruptible.h"

namespace py = pybind11;
using namespace frep;

namespace {

// Raised for a model with errors; args[0] holds every diagnostic as file:line:column: ...
struct ModelError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Model {
  std::string name;
  int dims = 0;                      // the object's x[n]
  std::vector<std::string> objects;  // every object in the source
  std::vector<std::string> warnings;
  uint64_t sourceHash = 0;
  std::vector<double> params;
  double iso = 0;
  TapePtr tape;  // f - iso over the model's coordinates, parameters bound
  Expr field;    // ... as an expression (mesh() cuts it by its box)
};

Model compileModel(const std::string& source, const std::string& file, const std::string& object,
                   const std::vector<double>& params, double iso) {
  lang::CompileOptions options;
  options.object = object;
  lang::CompileResult r = lang::compile(source, file, options);
  std::string errors;
  Model m;
  for (const lang::Diagnostic& d : r.diagnostics) {
    if (d.severity == lang::Diagnostic::Severity::Error) errors += d.format() + "\n";
    else m.warnings.push_back(d.format());
  }
  if (!r.ok) throw ModelError(errors.empty() ? file + ": no object to evaluate" : errors.substr(0, errors.size() - 1));
  if (params.size() > size_t(r.model.aSize))
    throw py::value_error("params: object '" + r.model.objectName + "' has a[" + std::to_string(r.model.aSize) +
                          "], got " + std::to_string(params.size()) + " values");
  lang::FieldSpec spec;
  spec.params = params;
  spec.iso = iso;
  m.name = r.model.objectName;
  m.dims = r.model.xSize;
  for (const lang::ObjectInfo& o : r.objects) m.objects.push_back(o.name);
  m.sourceHash = r.model.sourceHash;
  m.params = params;
  m.iso = iso;
  m.field = lang::fieldOf(r.model, spec);
  m.tape = Tape::compile(m.field, uint32_t(std::max(m.dims, 3)));
  return m;
}

// The model file as frep reads it (io::readInputFile): a regular file of at most 1 GiB, its
// size checked before anything is allocated; a FIFO, a device (/dev/zero) or a larger file
// raise IoError (an OSError) naming the path at once, never a hang nor a huge allocation.
Model loadModel(const std::string& path, const std::string& object, const std::vector<double>& params, double iso) {
  std::string text;
  try {
    text = io::readInputFile(path);
  } catch (const io::Error& e) {
    // "cannot open file 'm.hf' (No such file or directory)" -> "cannot read model 'm.hf': No such ..."
    const std::string what = e.what(), open = "cannot open file '" + path + "' (";
    if (what.rfind(open, 0) == 0 && what.back() == ')')
      throw io::ioError("cannot read model '" + path + "': " + what.substr(open.size(), what.size() - open.size() - 1));
    throw io::ioError("cannot read model " + what);
  }
  return compileModel(text, path, object, params, iso);
}

// NumPy is optional (pip's extra frepfarm[numpy]): the calls that return arrays say so by name
// instead of failing inside pybind11's array conversion with a bare "No module named 'numpy'".
void requireNumpy(const char* call) {
  try {
    py::module_::import("numpy");
  } catch (py::error_already_set& e) {
    if (!e.matches(PyExc_ImportError)) throw;
    const std::string msg = std::string(call) +
                            " works on NumPy arrays, and numpy is not installed: pip install 'frepfarm[numpy]' "
                            "(or numpy; the calls that return no array work without it)";
    PyErr_SetString(PyExc_ModuleNotFoundError, msg.c_str());
    throw py::error_already_set();
  }
}

// f at each row of an (N, dims) array, by the batch evaluator (256 points per call).
py::array_t<double> evalPoints(const Model& m, py::object pointsIn, py::object progress) {
  requireNumpy("Model.eval");
  auto points = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(pointsIn);
  if (!points)
    throw py::type_error("points: expected an array of numbers of shape (N, " + std::to_string(m.dims) + ")");
  if (points.ndim() == 1 && points.shape(0) == m.dims) points = points.reshape({py::ssize_t(1), py::ssize_t(m.dims)});
  if (points.ndim() != 2 || points.shape(1) != m.dims)
    throw py::value_error("points: expected an array of shape (N, " + std::to_string(m.dims) + ") for object '" +
                          m.name + "' (x[" + std::to_string(m.dims) + "])");
  const size_t n = size_t(points.shape(0));
  py::array_t<double> out{py::ssize_t(n)};
  const double* in = points.data();
  double* res = out.mutable_data();
  python::interruptible(progress, [&] {
    BatchEvaluator<double> eval;
    eval.reserve(*m.tape);
    const uint32_t vars = m.tape->numVars();
    for (size_t start = 0; start < n; start += BatchEvaluator<double>::kBatch) {
      if (start % (64 * BatchEvaluator<double>::kBatch) == 0) reportProgress("eval", start, n);
      const size_t count = std::min(BatchEvaluator<double>::kBatch, n - start);
      for (uint32_t v = 0; v < vars; ++v) {
        double* lane = eval.in(v);
        for (size_t k = 0; k < count; ++k) lane[k] = v < uint32_t(m.dims) ? in[(start + k) * m.dims + v] : 0.0;
      }
      const double* values = eval.eval(*m.tape, count);
      std::copy(values, values + count, res + start);
    }
    return true;
  });
  return out;
}

std::vector<double> fixedCoordsOf(const Model& m, const std::vector<double>& fixed) {
  const size_t extra = m.dims > 3 ? size_t(m.dims - 3) : 0;
  if (fixed.size() != extra)
    throw py::value_error("fixed: object '" + m.name + "' has x[" + std::to_string(m.dims) + "], so fixed needs " +
                          std::to_string(extra) + " values (x[4] and above), got " + std::to_string(fixed.size()));
  return fixed;
}

GridSpec gridOf(const std::array<double, 3>& lo, const std::array<double, 3>& hi, int res) {
  for (int a = 0; a < 3; ++a)
    if (!(hi[a] > lo[a])) throw py::value_error("box: hi must exceed lo on every axis");
  if (res < 2 || res > 4096) throw py::value_error("res: expected 2 to 4096 points along the longest axis");
  // The voxel of res points along the longest axis, on the world lattice as frep sample's
  // grids and the .vdb writer have it (the box rounds outward).
  return io::worldLatticeGrid("box", lo, hi, GridSpec::fromBounds(lo, hi, res).voxel);
}

struct Volume {
  SampleResult result;
  std::string name;
  uint64_t sourceHash = 0;
  double iso = 0;
  std::string params;
};

Volume sampleModel(const Model& m, std::array<double, 3> lo, std::array<double, 3> hi, int res, int band,
                   const std::vector<double>& fixed, py::object progress) {
  if (band < 1 || band > 64) throw py::value_error("band: expected 1 to 64 voxels");
  SampleOptions options;
  options.bandVoxels = band;
  options.fixedCoords = fixedCoordsOf(m, fixed);
  GridSpec grid = gridOf(lo, hi, res);
  Volume v;
  v.result = python::interruptible(progress, [&] { return sample(m.tape, grid, options); });
  v.name = m.name;
  v.sourceHash = m.sourceHash;
  v.iso = m.iso;
  for (size_t i = 0; i < m.params.size(); ++i) v.params += (i ? "," : "") + std::to_string(m.params[i]);
  return v;
}

// Writes the grid as frep sample does (frep_io: -f as a level set, metadata), atomically.
void writeVdb(const Volume& v, const std::string& path) {
  io::AtomicOutput out("path", path);
  io::VdbMetadata meta;
  meta.gridName = v.name;
  meta.job = "frepfarm (Python) sample";
  meta.params = v.params;
  meta.sourceHash = v.sourceHash;
  meta.iso = v.iso;
  io::writeLevelSet(out.tempPath(), v.result, meta);
  out.commit();
}

// pyopenvdb (python3-openvdb) is built on Boost.Python, which cannot take a C++ grid from this
// module: the grid goes through a temporary .vdb written by frep_io and read by pyopenvdb.
py::object toPyOpenVdb(const Volume& v) {
  py::module_ vdb = py::module_::import("pyopenvdb");
  const char* dir = std::getenv("TMPDIR");
  std::string path = std::string(dir && *dir ? dir : "/tmp") + "/frepfarm-" + std::to_string(::getpid()) + "-" +
                     std::to_string(reinterpret_cast<uintptr_t>(&v)) + ".vdb";
  writeVdb(v, path);
  py::object grid;
  try {
    grid = vdb.attr("read")(path, v.name);
  } catch (...) {
    std::remove(path.c_str());
    throw;
  }
  std::remove(path.c_str());
  return grid;
}

py::array_t<double> rows(const std::vector<std::array<double, 3>>& v, const char* call) {
  requireNumpy(call);
  py::array_t<double> a({py::ssize_t(v.size()), py::ssize_t(3)});
  if (!v.empty()) std::copy(v.data()->data(), v.data()->data() + 3 * v.size(), a.mutable_data());
  return a;
}

struct PyMesh {
  Mesh mesh;
  double errorBound = 0;
};

PyMesh meshModel(const Model& m, std::array<double, 3> lo, std::array<double, 3> hi, int res, double simplify,
                 const std::vector<double>& fixed, py::object progress) {
  // As frep mesh --tolerance: NaN or an infinity would make simplification spin without end.
  if (!(simplify == 0 || (simplify >= kMinSimplifyTolerance && simplify <= kMaxSimplifyTolerance)))
    throw py::value_error("simplify: expected 0 (no simplification) or 1e-30 to 1e30 voxels");
  GridSpec grid = gridOf(lo, hi, res);
  MeshOptions options;
  options.fixedCoords = fixedCoordsOf(m, fixed);
  PyMesh out;
  python::interruptible(progress, [&] {
  // As frep mesh: a solid cut by the box is meshed as solid ∩ box, capped 2e-3 voxel inside the
  // box's faces on a grid one voxel larger, and the result must be closed.
  TapePtr tape = m.tape;
  if (facesReached(m.tape, grid, options.fixedCoords) != 0) {
    std::array<double, 3> cutLo, cutHi;
    for (int a = 0; a < 3; ++a) {
      cutLo[a] = grid.origin[a] + 2e-3 * grid.voxel;
      cutHi[a] = grid.origin[a] + grid.voxel * (grid.dims[a] - 1) - 2e-3 * grid.voxel;
      grid.origin[a] -= grid.voxel;
      grid.dims[a] += 2;
    }
    tape = Tape::compile(cutByBox(m.field, cutLo, cutHi), m.tape->numVars());
  }
  out.mesh = meshGrid(tape, grid, options);
  if (simplify > 0) {
    SimplifyOptions s;
    s.tolerance = simplify;
    s.fixedCoords = options.fixedCoords;
    out.errorBound = simplifyMesh(out.mesh, tape, grid, s).errorBound;
  }
  return true;
  });
  const std::string defect = closureDefect(out.mesh.triangles, out.mesh.positions.size());
  if (!defect.empty()) throw std::runtime_error("internal error: the mesh is not closed (" + defect + ")");
  return out;
}

py::dict boundDict(const MeasureBound& b) {
  py::dict d;
  d["lower"] = b.lower;
  d["upper"] = b.upper;
  return d;
}

py::list tensorList(const std::array<MeasureBound, 9>& t) {
  py::list rows;
  for (int i = 0; i < 3; ++i) {
    py::list row;
    for (int j = 0; j < 3; ++j) row.append(boundDict(t[size_t(i * 3 + j)]));
    rows.append(row);
  }
  return rows;
}

// As frep measure --json: certified bounds of solid ∩ [lo, hi] (frep/measure/mass_properties.h).
py::dict measureModel(const Model& m, std::array<double, 3> lo, std::array<double, 3> hi, double tolerance,
                      int threads, long long maxCells, py::object progress) {
  if (m.dims != 3) throw py::value_error("measure: the object has x[" + std::to_string(m.dims) + "]; measure needs a 3D object");
  if (!(tolerance > 0.0 && tolerance < 1.0)) throw py::value_error("tolerance: expected a relative width in (0, 1), e.g. 0.005");
  if (maxCells < 1000) throw py::value_error("max_cells: expected at least 1000");
  for (int a = 0; a < 3; ++a)
    if (!(hi[size_t(a)] > lo[size_t(a)]) || !std::isfinite(lo[size_t(a)]) || !std::isfinite(hi[size_t(a)]))
      throw py::value_error("lo, hi: expected finite bounds with hi > lo on every axis");
  const Interval box[3] = {{lo[0], hi[0]}, {lo[1], hi[1]}, {lo[2], hi[2]}};
  MeasureOptions options;
  options.tolerance = tolerance;
  options.threads = threads;
  options.maxBoundaryCells = uint64_t(maxCells);
  // Ctrl-C: KeyboardInterrupt; progress returning False: the last whole round's bounds,
  // stop_reason "cancelled".
  const MassProperties r =
      python::interruptible(progress, [&] { return measureMassProperties(m.field, box, options); });
  py::dict d;
  d["volume"] = boundDict(r.volume);
  d["area"] = boundDict(r.area);
  d["cut_area"] = boundDict(r.cutArea);
  py::list faces;
  for (int b = 0; b < 6; ++b)
    if (r.cutFaces & (1u << b)) faces.append(std::string(1, "xyz"[b / 2]) + (b % 2 ? "-max" : "-min"));
  d["cut_faces"] = faces;
  py::list centroid;
  for (const MeasureBound& c : r.centroid) centroid.append(boundDict(c));
  d["centroid"] = centroid;
  d["inertia"] = tensorList(r.inertia);
  d["inertia_about"] = "centroid";
  d["inertia_origin"] = tensorList(r.inertiaOrigin);
  d["area_bounded"] = r.areaBounded;
  d["tolerance_reached"] = r.toleranceReached;
  d["stop_reason"] = r.stopReason;
  py::dict cells;
  cells["inside"] = r.insideCells;
  cells["boundary"] = r.boundaryCells;
  cells["first_order"] = r.firstOrderCells;
  d["cells"] = cells;
  return d;
}

void writeMeshFile(const PyMesh& m, const std::string& path) {
  io::MeshFormat format = io::meshFormatFromPath("path", path);
  io::AtomicOutput out("path", path);
  io::writeMesh(out.tempPath(), m.mesh, format, "frepfarm (Python)");
  out.commit();
}

}  // namespace

PYBIND11_MODULE(frepfarm, mod) {
  mod.doc() = "frepfarm: F-rep solids in the HyperFun language (inside is f >= 0)";
  mod.attr("__version__") = FREP_VERSION;
  io::installGeometryLoader();  // frMesh / frVolume in models
  // frep_io installs handlers for SIGINT/SIGTERM/SIGHUP when it is loaded (for the frep
  // command's exit code 6); in Python, Ctrl-C must stay KeyboardInterrupt.
  py::module_ signal = py::module_::import("signal");
  signal.attr("signal")(signal.attr("SIGINT"), signal.attr("default_int_handler"));
  signal.attr("signal")(signal.attr("SIGTERM"), signal.attr("SIG_DFL"));
  signal.attr("signal")(signal.attr("SIGHUP"), signal.attr("SIG_DFL"));

  static py::exception<ModelError> modelError(mod, "ModelError", PyExc_ValueError);
  static py::exception<io::Error> ioErrorType(mod, "IoError", PyExc_OSError);
  static py::exception<python::Cancelled> cancelledType(mod, "Cancelled", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const ModelError& e) {
      modelError(e.what());
    } catch (const python::Cancelled& e) {
      cancelledType(e.what());
    } catch (const io::Error& e) {
      if (e.code == io::kExitBadArgs) PyErr_SetString(PyExc_ValueError, e.what());
      else ioErrorType(e.what());
    }
  });

  py::class_<Model>(mod, "Model", "A compiled HyperFun object: f(x) - iso, parameters bound")
      .def_readonly("name", &Model::name)
      .def_readonly("dims", &Model::dims, "n of the object's x[n]")
      .def_readonly("objects", &Model::objects, "every object in the source")
      .def_readonly("warnings", &Model::warnings)
      .def("eval", &evalPoints, py::arg("points"), py::arg("progress") = py::none(),
           "f at each row of an (N, dims) float64 array (or one point of length dims): N values")
      .def("sample", &sampleModel, py::arg("lo"), py::arg("hi"), py::arg("res") = 128, py::arg("band") = 3,
           py::arg("fixed") = std::vector<double>{}, py::arg("progress") = py::none(),
           "Sparse narrow-band sampling of the box [lo, hi] with res points along its longest axis")
      .def("mesh", &meshModel, py::arg("lo"), py::arg("hi"), py::arg("res") = 128, py::arg("simplify") = 0.0,
           py::arg("fixed") = std::vector<double>{}, py::arg("progress") = py::none(),
           "Watertight mesh of f = 0 in [lo, hi]; simplify > 0: tolerance in voxels (frep mesh's 0.1)")
      .def("measure", &measureModel, py::arg("lo") = std::array<double, 3>{-10, -10, -10},
           py::arg("hi") = std::array<double, 3>{10, 10, 10}, py::arg("tolerance") = 0.005, py::arg("threads") = 0,
           py::arg("max_cells") = 2000000LL, py::arg("progress") = py::none(),
           "Certified volume, area, centroid and inertia tensors of solid ∩ [lo, hi] as lower/upper bounds "
           "(frep measure --json's dict; docs/measure.md)");

  mod.def("compile", &compileModel, py::arg("source"), py::arg("file") = "<string>", py::arg("object") = "",
          py::arg("params") = std::vector<double>{}, py::arg("iso") = 0.0,
          "Compiles HyperFun source text; errors raise ModelError (file:line:column)");
  mod.def("load", &loadModel, py::arg("path"), py::arg("object") = "", py::arg("params") = std::vector<double>{},
          py::arg("iso") = 0.0, "Reads and compiles a .hf file");

  py::class_<Volume>(mod, "Volume", "A sampled model: f in the narrow band, inside/outside tiles elsewhere")
      .def_property_readonly("voxel", [](const Volume& v) { return v.result.grid.voxel; })
      .def_property_readonly("origin", [](const Volume& v) { return v.result.grid.origin; })
      .def_property_readonly("dims", [](const Volume& v) { return v.result.grid.dims; })
      .def_property_readonly("leaf_count", [](const Volume& v) { return v.result.leaves.size(); })
      .def("world", [](const Volume& v, int64_t i, int64_t j, int64_t k) { return v.result.grid.world(i, j, k); },
           "world point of voxel (i, j, k)")
      .def("inside_volume", [](const Volume& v) { return insideVolume(v.result); },
           "grid points with f >= 0 times the voxel volume")
      .def("write_vdb", &writeVdb, py::arg("path"), "Writes the .vdb that frep sample writes (frep_io)")
      .def("to_pyopenvdb", &toPyOpenVdb, "A pyopenvdb.FloatGrid (through a temporary .vdb file)");

  py::class_<PyMesh>(mod, "Mesh", "A watertight, outward-oriented triangle mesh")
      .def_property_readonly("vertices", [](const PyMesh& m) { return rows(m.mesh.positions, "Mesh.vertices"); })
      .def_property_readonly("normals", [](const PyMesh& m) { return rows(m.mesh.normals, "Mesh.normals"); })
      .def_property_readonly("triangles", [](const PyMesh& m) {
        requireNumpy("Mesh.triangles");
        py::array_t<uint32_t> a({py::ssize_t(m.mesh.triangles.size()), py::ssize_t(3)});
        if (!m.mesh.triangles.empty())
          std::copy(m.mesh.triangles.data()->data(), m.mesh.triangles.data()->data() + 3 * m.mesh.triangles.size(),
                    a.mutable_data());
        return a;
      })
      .def_readonly("error_bound", &PyMesh::errorBound, "simplification's bound on the distance to the surface")
      .def("write", &writeMeshFile, py::arg("path"), "Writes .ply, .obj or .stl (frep_io)");
}
