// loadProgramModule (frep/io/program_module.h): linked into frep and frep-worker with the
// loaded tables (vdb_backend_loaded.cpp, mesh_files_loaded.cpp) and cli/view_command.cpp.
#include "frep/io/program_module.h"

#include <dlfcn.h>
#include <unistd.h>

#include <climits>
#include <string>

#include "frep/io/error.h"

#ifndef FREP_VERSION
#define FREP_VERSION "unknown"
#endif
#ifndef FREP_MODULE_INSTALL_DIR
#define FREP_MODULE_INSTALL_DIR "../lib/frepfarm"  // from the program's directory
#endif

namespace frep::io {
namespace {

std::string programDirectory() {
  char buf[PATH_MAX];
  const ssize_t n = ::readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) return ".";
  std::string path(buf, size_t(n));
  const size_t slash = path.rfind('/');
  return slash == std::string::npos ? "." : path.substr(0, slash);
}

}  // namespace

const void* loadProgramModule(const char* fileName, const char* entry, size_t tableSize, const char* what) {
  const std::string dir = programDirectory();
  // Next to the program (the build tree), then where `cmake --install` puts it.
  const std::string candidates[] = {dir + "/" + fileName, dir + "/" + FREP_MODULE_INSTALL_DIR + "/" + fileName};
  std::string tried;
  for (const std::string& path : candidates) {
    if (::access(path.c_str(), F_OK) != 0) {
      tried += "\n  " + path + ": not found";
      continue;
    }
    // RTLD_NOW: a symbol the module needs and the program lacks is named here, not mid-job.
    void* handle = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      const char* why = ::dlerror();
      tried += "\n  " + path + ": " + (why ? why : "dlopen failed");
      continue;
    }
    auto answer = reinterpret_cast<ModuleEntry>(::dlsym(handle, entry));
    const void* table = answer ? answer(FREP_VERSION, tableSize) : nullptr;
    if (table) return table;
    ::dlclose(handle);
    tried += "\n  " + path + ": not the module of this frep " FREP_VERSION " build";
  }
  throw Error(kExitInternal, std::string("cannot load ") + what + "; tried:" + tried +
                                 "\n(reinstall frepfarm: the module belongs next to the program or in " +
                                 FREP_MODULE_INSTALL_DIR + " from it)");
}

}  // namespace frep::io
