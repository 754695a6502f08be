// Input files told by their first bytes; see frep/io/file_kind.h.
#include "frep/io/file_kind.h"

#include <sys/stat.h>

#include <cstring>
#include <fstream>

namespace frep::io {

FileKind sniffFileKind(const std::string& head, uint64_t size) {
  auto starts = [&](const char* magic, size_t n) {
    return head.size() >= n && std::memcmp(head.data(), magic, n) == 0;
  };
  if (starts(" BDV\0\0\0\0", 8)) return FileKind::Vdb;
  if (starts("ply\n", 4) || starts("ply\r\n", 5)) return FileKind::Ply;
  if (starts("glTF", 4)) return FileKind::Glb;
  if (starts("PK\x03\x04", 4)) return FileKind::Zip;
  if (starts("\x89PNG\r\n\x1a\n", 8)) return FileKind::Png;
  if (starts("\xff\xd8\xff", 3)) return FileKind::Jpeg;
  if (starts("\x1f\x8b", 2)) return FileKind::Gzip;
  if (starts("\x7f"
             "ELF",
             4))
    return FileKind::Elf;
  if (starts("%PDF-", 5)) return FileKind::Pdf;
  if (head.size() >= 84) {  // a binary STL states its triangle count after an 80-byte header
    uint32_t n = 0;
    std::memcpy(&n, head.data() + 80, 4);
    if (size == 84 + 50 * uint64_t(n)) return FileKind::StlBinary;
  }
  const size_t look = head.size() < 512 ? head.size() : 512;
  for (size_t i = 0; i < look; ++i) {
    const unsigned char c = static_cast<unsigned char>(head[i]);
    if (c == 0 || (c < 32 && c != '\t' && c != '\n' && c != '\r' && c != '\f' && c != '\v') || c == 127)
      return FileKind::Binary;
  }
  return FileKind::Text;
}

FileKind sniffFile(const std::string& path) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return FileKind::Text;
  std::ifstream in(path, std::ios::binary);
  std::string head(512, '\0');
  in.read(head.data(), std::streamsize(head.size()));
  head.resize(size_t(in.gcount()));
  return sniffFileKind(head, uint64_t(st.st_size));
}

std::string describeFileKind(FileKind kind) {
  switch (kind) {
    case FileKind::Vdb:
      return "an OpenVDB grid file (.vdb)";
    case FileKind::Ply:
      return "a PLY mesh";
    case FileKind::StlBinary:
      return "a binary STL mesh";
    case FileKind::Glb:
      return "a glTF 2.0 binary (.glb)";
    case FileKind::Zip:
      return "a ZIP archive (a .3mf, for one)";
    case FileKind::Png:
      return "a PNG image";
    case FileKind::Jpeg:
      return "a JPEG image";
    case FileKind::Gzip:
      return "a gzip-compressed file";
    case FileKind::Elf:
      return "an executable (ELF)";
    case FileKind::Pdf:
      return "a PDF document";
    case FileKind::Binary:
      return "a binary file";
    case FileKind::Text:
      break;
  }
  return "text";
}

}  // namespace frep::io
