// The entry point of libfrep_mesh_files.so, the 3MF and glTF writers that frep loads when a job
// first writes a .3mf or a .glb (mesh_files_loaded.cpp). Built from the same sources as the
// program that loads it; the frepfarm functions it calls are the program's (exported by it).
#include <cstring>

#include "mesh_writers.h"

#ifndef FREP_VERSION
#define FREP_VERSION "unknown"
#endif

extern "C" __attribute__((visibility("default"))) const void* frep_mesh_files_backend(const char* version,
                                                                                      size_t tableSize) {
  using frep::io::detail::MeshFilesBackend;
  // A module of another build (a stale install next to a new program) answers nothing.
  if (!version || std::strcmp(version, FREP_VERSION) != 0 || tableSize != sizeof(MeshFilesBackend)) return nullptr;
  return &frep::io::detail::linkedMeshFiles();
}
