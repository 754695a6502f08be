// What an input file holds, told by its first bytes (magic numbers, a binary STL's size rule), not
// by its name: `frep render x.glb` is refused as a glTF file instead of being lexed as HyperFun,
// and a grid or mesh whose name has another extension is still read as what it is.
#pragma once

#include <cstdint>
#include <string>

namespace frep::io {

enum class FileKind {
  Text,       // no signature and no NUL or control bytes: HyperFun, OBJ, ASCII STL/PLY, a POV scene
  Vdb,        // OpenVDB (" BDV" magic)
  Ply,        // "ply" line
  StlBinary,  // 84 + 50 n bytes, n stated at byte 80
  Glb,        // glTF 2.0 binary ("glTF")
  Zip,        // a ZIP archive (3MF, for one)
  Png,
  Jpeg,
  Gzip,
  Elf,  // an executable or shared object
  Pdf,
  Binary,  // NUL or control bytes: some other binary file
};

// `head`: the file's first bytes (up to 512 are looked at); `size`: its whole size in bytes.
FileKind sniffFileKind(const std::string& head, uint64_t size);
// Reads the first bytes of `path`; Text when it cannot be read (its reader then says why).
FileKind sniffFile(const std::string& path);

// "an OpenVDB grid file (.vdb)", "a glTF 2.0 binary (.glb)", …; "text" for Text.
std::string describeFileKind(FileKind kind);
// A mesh frep render and frMesh read (PLY, binary STL).
inline bool isMeshKind(FileKind k) { return k == FileKind::Ply || k == FileKind::StlBinary; }

}  // namespace frep::io
