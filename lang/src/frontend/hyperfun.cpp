// Entry points: source text -> diagnostics, object list and the selected object's model.
#include "frep/lang/hyperfun.h"

#include <cctype>
#include <fstream>
#include <sstream>

#include "frep/lang/frontend/diagnostics.h"
#include "frep/lang/frontend/lexer.h"
#include "frep/lang/lowering/lower.h"
#include "frep/lang/frontend/parser.h"

namespace frep::lang {
namespace {

uint64_t fnv1a(const std::string& s) {
  uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

std::string lowerCase(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

CompileResult compile(const std::string& source, const std::string& fileName,
                      const CompileOptions& options) {
  CompileResult result;
  DiagnosticSink diags(fileName, source);
  std::vector<Token> tokens = lex(source, diags);
  Program program = parse(tokens, diags);
  std::vector<LoweredObject> lowered = lowerProgram(program, options, diags, fileName, result.files);
  for (const auto& o : lowered) result.objects.push_back(o.info);
  int sel = selectedObject(program, options);
  if (sel >= 0 && !options.object.empty() && lowered[sel].info.name != lowerCase(options.object))
    diags.warning(Loc{}, "no object named '" + options.object + "'; using '" +
                             lowered[sel].info.name + "'");
  if (sel >= 0) {
    const LoweredObject& o = lowered[sel];
    result.model.objectName = o.info.name;
    result.model.xSize = o.info.xSize;
    result.model.aSize = o.info.aSize;
    result.model.field = o.field;
    result.model.attributes = o.attributes;
    result.model.hasAttributes = o.attributesWritten;
    result.model.sourceHash = fnv1a(source);
    result.ok = o.ok && diags.errorCount() == 0;
  }
  result.diagnostics = diags.take();
  return result;
}

CompileResult compileFile(const std::string& path, const CompileOptions& options) {
  std::string source;
  try {
    source = readRegularFile(path, options.maxFileBytes);  // never a FIFO, a device or 1 GB of /dev/zero
  } catch (const std::runtime_error& e) {
    CompileResult r;
    Diagnostic d;
    d.file = path;
    const std::string what = e.what();
    d.message = what.rfind("cannot open file", 0) == 0 ? "cannot open file" : what;
    r.diagnostics.push_back(d);
    return r;
  }
  return compile(source, path, options);
}

}  // namespace frep::lang
