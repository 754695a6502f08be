// The entry point of libfrep_vdb.so, the OpenVDB code that frep and frep-worker load when a job
// first reads or writes a .vdb (vdb_backend_loaded.cpp). The module is built from the same
// sources as the program that loads it; frepfarm's own functions it calls are the program's
// (exported by it), so one copy of every frep function and global serves both.
#include <cstring>

#include "vdb_backend.h"

#ifndef FREP_VERSION
#define FREP_VERSION "unknown"
#endif

extern "C" __attribute__((visibility("default"))) const void* frep_vdb_backend(const char* version, size_t tableSize) {
  // A module of another build (a stale install next to a new program) answers nothing.
  if (!version || std::strcmp(version, FREP_VERSION) != 0 || tableSize != sizeof(frep::io::detail::VdbBackend))
    return nullptr;
  return &frep::io::detail::openVdbBackend();
}
