// Reading an input file whole (a model, a mesh, a POV scene, a model's data file): only a
// regular file, never blocking on a FIFO nor reading a device without end, and at most
// kMaxInputBytes, a size checked before anything is allocated.
#pragma once

#include <cstdint>
#include <string>

namespace frep::io {

constexpr uint64_t kMaxInputBytes = uint64_t(1) << 30;  // 1 GiB, as lang's CompileOptions::maxFileBytes

// The file's bytes; throws Error(kExitIoError) naming `path` and why (not a regular file, too
// large, cannot be opened).
std::string readInputFile(const std::string& path, uint64_t maxBytes = kMaxInputBytes);

}  // namespace frep::io
