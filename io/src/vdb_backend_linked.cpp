// The OpenVDB code's table (vdb_backend.h), and the table of a binary with that code linked in.
// frep and frep-worker link vdb_backend_loaded.cpp's vdbBackend() instead, so the linker never
// takes this file, nor the OpenVDB code, into them; the module libfrep_vdb.so returns the table.
#include "vdb_backend.h"

namespace frep::io::detail {

const VdbBackend& openVdbBackend() {
  static const VdbBackend table{openVdbReadSampled, openVdbWriteLevelSet, openVdbLevelSetTree, openVdbReadVolumeField};
  return table;
}

const VdbBackend& vdbBackend() { return openVdbBackend(); }

}  // namespace frep::io::detail
