// Internal to io/src: a .vdb file written straight to its path, then sealed (vdb_checksum.h).
#pragma once

#include <functional>
#include <ostream>
#include <string>

namespace frep::io::detail {

// Runs `write` on a seekable stream into the existing file `path` (truncated; a last-component
// symbolic link refused), then seals it: the checksum entry's placeholder digits (kChecksumDigits
// '0's after the kGridChecksumKey entry) and the header's UUID replaced as sealChecksum did on
// the bytes in memory. The file's bytes go through a 1 MiB buffer and are hashed by reading them
// back: nothing proportional to the file is held. Every write checked, then fsync and the size
// read back; throws Error(kExitIoError) naming the path.
void writeSealedVdb(const std::string& path, const std::function<void(std::ostream&)>& write);

}  // namespace frep::io::detail
