// vdbBackend() for frep and frep-worker: the OpenVDB code loaded from libfrep_vdb.so the first
// time a job reads or writes a .vdb (vdb_backend.h says why). Linked into those programs as an
// object file, so the linker takes this definition and never the archive's linked one.
#include <typeinfo>
#include <vector>

#include "allocation_cap.h"
#include "frep/geometry/field.h"
#include "frep/io/format_number.h"
#include "frep/io/program_module.h"
#include "frep/sampling/band_distance.h"
#include "frep/sampling/exact_band_distance.h"
#include "vdb_backend.h"

namespace frep::io::detail {

// Never called: its references keep in the program the frepfarm functions the module calls that
// the program may not call itself (tests/tools/module_check.py fails when one is missing).
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
  // Thread-safe; a throw leaves it to be tried again.
  static const auto* const backend = static_cast<const VdbBackend*>(loadProgramModule(
      "libfrep_vdb.so", kVdbModuleEntry, sizeof(VdbBackend), "frepfarm's OpenVDB module (needed for .vdb files)"));
  return *backend;
}

}  // namespace frep::io::detail
