// frep view's server, behind one table: the module libfrep_view.so (view_server.cpp) holds it and
// frep loads it when the verb runs (view_command.cpp), so that cpp-httplib and the TLS libraries
// it links are not loaded by every other frep process (frep/io/program_module.h).
#pragma once

#include <cstddef>

#include "commands.h"

namespace frep::cli {

struct ViewServer {
  // Serves the page until a signal stops it; throws CliError and io::Error like every verb.
  int (*serve)(const ViewRequest& request);
};

// view_server.cpp, in the module only.
int serveView(const ViewRequest& request);

inline constexpr const char* kViewServerEntry = "frep_view_server";

}  // namespace frep::cli
