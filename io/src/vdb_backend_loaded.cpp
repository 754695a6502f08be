// vdbBackend() for frep and frep-worker: the OpenVDB code loaded from libfrep_vdb.so the first
// time a job reads or writes a .vdb (vdb_backend.h says why). Linked into those programs as an
// object file, so the linker takes this definition and never the archive's linked one.
#include <dlfcn.h>
#include <unistd.h>

#include <climits>
#include <string>

#include <typeinfo>
#include <vector>

#include "allocation_cap.h"
#include "frep/geometry/field.h"
#include "frep/io/error.h"
#include "frep/io/format_number.h"
#include "frep/sampling/band_distance.h"
#include "frep/sampling/exact_band_distance.h"
#include "vdb_backend.h"

#ifndef FREP_VERSION
#define FREP_VERSION "unknown"
#endif
#ifndef FREP_VDB_MODULE_INSTALL_DIR
#define FREP_VDB_MODULE_INSTALL_DIR "../lib/frepfarm"  // from the program's directory
#endif

namespace frep::io::detail {
namespace {

constexpr const char* kModuleName = "libfrep_vdb.so";

std::string programDirectory() {
  char buf[PATH_MAX];
  const ssize_t n = ::readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) return ".";
  std::string path(buf, size_t(n));
  const size_t slash = path.rfind('/');
  return slash == std::string::npos ? "." : path.substr(0, slash);
}

const VdbBackend* load() {
  const std::string dir = programDirectory();
  // Next to the program (the build tree), then where `cmake --install` puts it.
  const std::string candidates[] = {dir + "/" + kModuleName,
                                    dir + "/" + FREP_VDB_MODULE_INSTALL_DIR + "/" + kModuleName};
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
    auto entry = reinterpret_cast<VdbModuleEntry>(::dlsym(handle, kVdbModuleEntry));
    const VdbBackend* backend = entry ? entry(FREP_VERSION, sizeof(VdbBackend)) : nullptr;
    if (backend) return backend;  // kept loaded for the life of the process
    ::dlclose(handle);
    tried += "\n  " + path + ": not the module of this frep " FREP_VERSION " build";
  }
  throw Error(kExitInternal, std::string("cannot load frepfarm's OpenVDB module (needed for .vdb files); tried:") +
                                 tried + "\n(reinstall frepfarm: the module belongs next to the program or in " +
                                 FREP_VDB_MODULE_INSTALL_DIR + " from it)");
}

}  // namespace

// Never called: its references keep in the program the frepfarm functions the module calls that
// the program may not call itself (tests/cli/check_vdb_module.py fails when one is missing).
void keepForModule(std::vector<LeafBlock>& leaves, std::vector<Tile>& tiles) {
  sortByOrigin(leaves, tiles);
  (void)bandDistanceBound();
  (void)exactBandDistanceBound();
  (void)formatNumber(1.0);
  (void)storeName(VdbStore::Sdf);
  AllocationCap cap(1);
  (void)typeid(DistanceField).name();
}

const VdbBackend& vdbBackend() {
  static const VdbBackend* const backend = load();  // thread-safe; a throw leaves it to be tried again
  return *backend;
}

}  // namespace frep::io::detail
