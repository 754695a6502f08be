#include "model_loader.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <iostream>
#include <sstream>

#include "arg_parse.h"
#include "exit_codes.h"

namespace frep::cli {
namespace {

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ioError("cannot read model '" + path + "': " + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw ioError("cannot read model '" + path + "': read error");
  return text.str();
}

Expr bindParameters(const LoadedModel& m, const std::string& text) {
  std::vector<Expr> values(size_t(m.model.aSize), Expr(0.0));  // hfp's default: all zero
  if (!text.empty()) {
    std::vector<double> given = parseNumbers("-a/--params", text, "at most " + std::to_string(m.model.aSize));
    if (given.size() > values.size())
      throw badArgs("-a/--params: object '" + m.model.objectName + "' has a[" + std::to_string(m.model.aSize) +
                    "], got " + std::to_string(given.size()) + " values in '" + text + "'");
    std::copy(given.begin(), given.end(), values.begin());
  }
  return bindParams(m.model.field, values);
}

// Substitutes each model coordinate by a view axis or a constant; returns the view's dimension.
int mapCoordinates(LoadedModel& m, const std::string& text, bool toView) {
  const int n = m.model.xSize;
  if (text.empty()) {
    if (!toView || n <= 3) return n;
    std::string example = "X,Y,Z";
    for (int i = 3; i < n; ++i) example += ",0";
    spdlog::warn("object '{}' has x[{}]: x[4] and above are held at 0 (choose with -x, e.g. -x {})",
                 m.model.objectName, n, example);
    std::vector<Expr> vars;
    for (int i = 0; i < n; ++i) vars.push_back(i < 3 ? Expr::x(uint32_t(i)) : Expr(0.0));
    m.field = remap(m.field, vars);
    return 3;
  }
  AxisMapping map = parseMapping("-x/--map", text);
  if (int(map.axis.size()) != n)
    throw badArgs("-x/--map: object '" + m.model.objectName + "' has x[" + std::to_string(n) + "], so -x needs " +
                  std::to_string(n) + " entries, got '" + text + "'");
  std::vector<Expr> vars;
  for (int i = 0; i < n; ++i)
    vars.push_back(map.axis[size_t(i)] >= 0 ? Expr::x(uint32_t(map.axis[size_t(i)])) : Expr(map.constant[size_t(i)]));
  m.field = remap(m.field, vars);
  return map.viewDims;
}

}  // namespace

LoadedModel loadModel(const ModelRequest& request, bool toView) {
  const std::string source = readFile(request.path);
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
  m.model = compiled.model;
  m.objects = compiled.objects;
  m.field = bindParameters(m, request.params);
  if (request.iso != 0.0) m.field = m.field - Expr(request.iso);
  m.dims = mapCoordinates(m, request.mapping, toView);
  return m;
}

}  // namespace frep::cli
