#include "model_loader.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <sstream>

#include "arg_parse.h"
#include "exit_codes.h"
#include "frep/io/file_kind.h"
#include "frep/io/input_file.h"

namespace frep::cli {
namespace {

// The model: a regular file of at most 1 GiB (a FIFO or /dev/zero is refused at once, exit 3).
std::string readFile(const std::string& path) {
  try {
    return io::readInputFile(path);
  } catch (const io::Error& e) {
    // "cannot read model 'm.hf': No such file or directory", "… '/dev/zero': is not a regular file …"
    const std::string what = e.what(), open = "cannot open file '" + path + "' (";
    if (what.rfind(open, 0) == 0 && what.back() == ')')
      throw ioError("cannot read model '" + path + "': " + what.substr(open.size(), what.size() - open.size() - 1));
    throw ioError("cannot read model " + what);
  }
}

std::vector<double> parseParameters(const lang::Model& model, const std::string& text) {
  if (text.empty()) return {};
  std::vector<double> given = parseNumbers("-a/--params", text, "at most " + std::to_string(model.aSize));
  if (given.size() > size_t(model.aSize))
    throw badArgs("-a/--params: object '" + model.objectName + "' has a[" + std::to_string(model.aSize) +
                  "], got " + std::to_string(given.size()) + " values in '" + text + "'");
  return given;
}

// Chooses each model coordinate's view axis or constant; returns the view's dimension.
int mapCoordinates(const lang::Model& model, const std::string& text, bool toView, lang::FieldSpec& spec) {
  const int n = model.xSize;
  if (text.empty()) {
    if (!toView || n <= 3) return n;
    std::string example = "X,Y,Z";
    for (int i = 3; i < n; ++i) example += ",0";
    spdlog::warn("object '{}' has x[{}]: x[4] and above are held at 0 (choose with -x, e.g. -x {})",
                 model.objectName, n, example);
    for (int i = 0; i < n; ++i) {
      spec.axis.push_back(i < 3 ? i : -1);
      spec.constant.push_back(0.0);
    }
    return 3;
  }
  AxisMapping map = parseMapping("-x/--map", text);
  if (int(map.axis.size()) != n)
    throw badArgs("-x/--map: object '" + model.objectName + "' has x[" + std::to_string(n) + "], so -x needs " +
                  std::to_string(n) + " entries, got '" + text + "'");
  for (int i = 0; i < n; ++i) {
    spec.axis.push_back(map.axis[size_t(i)]);
    spec.constant.push_back(map.axis[size_t(i)] >= 0 ? 0.0 : map.constant[size_t(i)]);
  }
  return map.viewDims;
}

}  // namespace

LoadedModel loadModel(const ModelRequest& request, bool toView) {
  const std::string source = readFile(request.path);
  // Told by its bytes, not its name: a binary file is never lexed (its bytes would be echoed).
  const io::FileKind kind = io::sniffFileKind(source.substr(0, 512), source.size());
  if (kind != io::FileKind::Text)
    throw CliError(kExitModelError, request.path + ": " + io::describeFileKind(kind) +
                                        ", not a HyperFun model (frep mesh reads .vdb grids; frep render reads .vdb "
                                        "grids and .ply, .obj, .stl meshes)");
  lang::CompileOptions options;
  options.object = request.object;
  lang::CompileResult compiled = lang::compile(source, request.path, options);
  int errors = 0;
  for (const lang::Diagnostic& d : compiled.diagnostics) {
    std::cerr << d.format() << "\n";
    errors += d.severity == lang::Diagnostic::Severity::Error;
  }
  if (!compiled.ok) {
    if (errors == 0) throw CliError(kExitModelError, request.path + ": no object to evaluate");
    throw CliError(kExitModelError, request.path + ": " + std::to_string(errors) +
                                        (errors == 1 ? " error" : " errors"));
  }

  LoadedModel m;
  m.source = source;
  m.model = compiled.model;
  m.objects = compiled.objects;
  m.files = compiled.files;
  m.spec.params = parseParameters(m.model, request.params);
  m.spec.iso = request.iso;
  m.dims = mapCoordinates(m.model, request.mapping, toView, m.spec);
  m.field = lang::fieldOf(m.model, m.spec);
  m.colour = lang::colourOf(m.model, m.spec);
  return m;
}

std::string canonicalModel(const LoadedModel& m) {
  auto exact = [](double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return std::string(buf);
  };
  std::string s = "object=" + m.model.objectName + " params=";
  for (size_t i = 0; i < m.spec.params.size(); ++i) s += (i ? "," : "") + exact(m.spec.params[i]);
  s += " iso=" + exact(m.spec.iso) + " map=";
  for (size_t i = 0; i < m.spec.axis.size(); ++i)
    s += (i ? "," : "") + (m.spec.axis[i] >= 0 ? std::string(1, char('X' + m.spec.axis[i])) : exact(m.spec.constant[i]));
  return s;
}

}  // namespace frep::cli
