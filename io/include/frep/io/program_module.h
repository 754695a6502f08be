// Code that frep and frep-worker load only when a job needs it: every shared library a program
// links costs each process start its dynamic linking (OpenVDB ~40 ms; lib3MF, tinygltf and
// cpp-httplib with libcrypto ~5 ms of a 15 ms `frep mesh`), so the code that links them is built as
// modules (libfrep_vdb.so, libfrep_mesh_files.so, libfrep_view.so) beside the program in the build
// tree and in LIBDIR/frepfarm when installed. A module's calls into frepfarm bind to the loading
// program's functions (exported by io/frep_exports.list): one copy of every function and global.
#pragma once

#include <cstddef>

namespace frep::io {

// The entry point every module exports (extern "C"): its table of functions when `version` is
// the version of the module's own build and `tableSize` the size of the table it returns, else
// nullptr (a stale module of another build next to a new program).
using ModuleEntry = const void* (*)(const char* version, size_t tableSize);

// Opens `fileName` next to the running program, else in its install folder, and returns the
// table its entry point `entry` answers for this build; kept loaded for the life of the process.
// Throws Error(kExitInternal) naming `what` (e.g. "frepfarm's OpenVDB module (needed for .vdb
// files)") and every path tried, with the reason each failed.
const void* loadProgramModule(const char* fileName, const char* entry, size_t tableSize, const char* what);

}  // namespace frep::io
