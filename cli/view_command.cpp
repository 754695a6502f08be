// frep view (docs/view.md): the arguments checked here, so that a bad one is exit 2 at once, then
// the page served by the module libfrep_view.so (view_server.h says why it is a module).
#include <filesystem>
#include <string>

#include "arg_parse.h"
#include "commands.h"
#include "exit_codes.h"
#include "frep/io/program_module.h"
#include "view_server.h"

namespace frep::cli {

int runView(const ViewRequest& request) {
  if (request.port < 0 || request.port > 65535) throw badArgs("--port: expected 0 (any free port) to 65535");
  if (request.res < 0) throw badArgs("--res: expected a positive number of points");
  if (!std::filesystem::is_regular_file(request.model.path)) throw ioError(request.model.path + ": no such file");
  if (!request.bounds.empty()) parseBounds("-b/--bounds", request.bounds);  // bad -b: exit 2 now, not on the page
  static const auto* const server = static_cast<const ViewServer*>(io::loadProgramModule(
      "libfrep_view.so", kViewServerEntry, sizeof(ViewServer), "frepfarm's web page module (needed for frep view)"));
  return server->serve(request);
}

}  // namespace frep::cli
