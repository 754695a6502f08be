// crc32Of (brick.h), zlib's CRC-32 in chunks zlib's uInt can hold. A file of its own so that
// builds needing only the checksum (the journal's fuzz target) do not pull in the core.
#include <zlib.h>

#include <cstddef>
#include <cstdint>

namespace frep::farm {
uint32_t crc32Of(const void* data, size_t size) {
  uLong c = crc32(0L, Z_NULL, 0);
  const Bytef* p = static_cast<const Bytef*>(data);
  while (size > 0) {
    uInt n = size > (1u << 30) ? (1u << 30) : uInt(size);
    c = crc32(c, p, n);
    p += n;
    size -= n;
  }
  return uint32_t(c);
}
}  // namespace frep::farm
