// frep check: compile only; diagnostics go to stderr (by loadModel), the objects to stdout.
#include <iostream>

#include "commands.h"
#include "exit_codes.h"

namespace frep::cli {

int runCheck(const ModelRequest& model) {
  LoadedModel m = loadModel(model, false);
  std::cout << model.path << ": ok, " << m.objects.size() << (m.objects.size() == 1 ? " object" : " objects")
            << "\n";
  for (const lang::ObjectInfo& o : m.objects) {
    std::cout << "  " << o.name << "(x[" << o.xSize << "], a[" << o.aSize << "]";
    if (o.sSize > 0) std::cout << ", s[" << o.sSize << "]";
    std::cout << ")  line " << o.line << (o.name == m.model.objectName ? "  (selected)" : "") << "\n";
  }
  return kExitOk;
}

}  // namespace frep::cli
