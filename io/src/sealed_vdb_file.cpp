#include "sealed_vdb_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdint>
#include <cstring>
#include <streambuf>
#include <vector>

#include "frep/io/error.h"
#include "vdb_checksum.h"

namespace frep::io::detail {
namespace {

// An output stream buffer on a file descriptor: OpenVDB's archive writer needs tellp and seekp
// (it writes a grid's offsets, then patches them), and a failed write must be seen (its own file
// writer ignores a failing stream: ENOSPC, EFBIG). The first error is kept in error().
class FdOutBuf : public std::streambuf {
 public:
  explicit FdOutBuf(int fd) : fd_(fd), buf_(size_t(1) << 20) { setp(buf_.data(), buf_.data() + buf_.size()); }
  int error() const { return error_; }

 protected:
  int_type overflow(int_type c) override {
    if (!drain()) return traits_type::eof();
    if (!traits_type::eq_int_type(c, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(c);
      pbump(1);
    }
    return traits_type::not_eof(c);
  }
  int sync() override { return drain() ? 0 : -1; }
  pos_type seekoff(off_type off, std::ios_base::seekdir dir, std::ios_base::openmode) override {
    if (!drain()) return pos_type(off_type(-1));
    const int whence = dir == std::ios_base::beg ? SEEK_SET : dir == std::ios_base::cur ? SEEK_CUR : SEEK_END;
    const off_t at = ::lseek(fd_, off_t(off), whence);
    if (at < 0) {
      error_ = error_ ? error_ : errno;
      return pos_type(off_type(-1));
    }
    return pos_type(off_type(at));
  }
  pos_type seekpos(pos_type pos, std::ios_base::openmode mode) override {
    return seekoff(off_type(pos), std::ios_base::beg, mode);
  }

 private:
  bool drain() {
    const char* at = pbase();
    while (!error_ && at < pptr()) {
      const ssize_t n = ::write(fd_, at, size_t(pptr() - at));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) error_ = n == 0 ? ENOSPC : errno;
      else at += n;
    }
    setp(buf_.data(), buf_.data() + buf_.size());
    return !error_;
  }
  int fd_;
  std::vector<char> buf_;
  int error_ = 0;
};

struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

uint64_t fnv(uint64_t h, const char* p, size_t n) {
  for (size_t i = 0; i < n; ++i) h = (h ^ uint8_t(p[i])) * 0x100000001b3ULL;
  return h;
}

}  // namespace

void writeSealedVdb(const std::string& path, const std::function<void(std::ostream&)>& write) {
  auto fail = [&](const std::string& what, int err) {
    throw ioError("cannot write VDB '" + path + "': " + what + ": " + std::strerror(err));
  };
  Fd f;
  f.fd = ::open(path.c_str(), O_RDWR | O_TRUNC | O_NOFOLLOW | O_CLOEXEC);
  if (f.fd < 0) fail("open", errno);
  int64_t size = 0;
  {
    FdOutBuf buf(f.fd);
    std::ostream os(&buf);
    try {
      write(os);
    } catch (...) {
      if (buf.error()) fail("write", buf.error());  // what made the writer give up
      throw;
    }
    os.seekp(0, std::ios_base::end);
    size = int64_t(os.tellp());
    os.flush();
    if (buf.error()) fail("write", buf.error());
    if (!os || size < 0) fail("write", EIO);
  }
  // The seal (vdb_checksum.h): the hash of the bytes read back, the UUID skipped; the placeholder
  // digits are '0's in the file, as the hash counts them. The entry is found with its length
  // prefixes, which hold NUL bytes no metadata text from argv has.
  auto u32 = [](uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  const std::string key = kGridChecksumKey;
  const std::string entry = u32(uint32_t(key.size())) + key + u32(6) + "string" + u32(uint32_t(kChecksumDigits)) +
                            std::string(kChecksumDigits, '0');
  std::vector<char> chunk(size_t(1) << 20);
  std::string header, window;  // the first bytes (the UUID's); the tail of the bytes searched
  uint64_t h = 0xcbf29ce484222325ULL;
  int64_t digitsAt = -1;
  for (int64_t at = 0; at < size;) {
    const ssize_t n =
        ::pread(f.fd, chunk.data(), size_t(std::min<int64_t>(int64_t(chunk.size()), size - at)), off_t(at));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) fail("read back", n == 0 ? EIO : errno);
    const int64_t end = at + n;
    if (header.size() < kVdbUuidAt + kVdbUuidLength + 1)
      header.append(chunk.data(),
                    size_t(std::min<int64_t>(n, int64_t(kVdbUuidAt + kVdbUuidLength + 1 - header.size()))));
    // Hash [at, end) outside [kVdbUuidAt, kVdbUuidAt + kVdbUuidLength).
    const int64_t uuidLo = int64_t(kVdbUuidAt), uuidHi = uuidLo + int64_t(kVdbUuidLength);
    if (end <= uuidLo || at >= uuidHi) h = fnv(h, chunk.data(), size_t(n));
    else {
      if (at < uuidLo) h = fnv(h, chunk.data(), size_t(uuidLo - at));
      if (end > uuidHi) h = fnv(h, chunk.data() + (uuidHi - at), size_t(end - uuidHi));
    }
    if (digitsAt < 0) {
      const int64_t windowAt = at - int64_t(window.size());
      window.append(chunk.data(), size_t(n));
      const size_t found = window.find(entry);
      if (found != std::string::npos) digitsAt = windowAt + int64_t(found + entry.size() - kChecksumDigits);
      else window.erase(0, window.size() - std::min(window.size(), entry.size() - 1));
    }
    at = end;
  }
  if (digitsAt < 0) fail("the checksum entry is missing from the serialised grid", EINVAL);
  const bool looksLikeUuid = header.size() > kVdbUuidAt + kVdbUuidLength && header[kVdbUuidAt + 8] == '-' &&
                             header[kVdbUuidAt + 13] == '-' && header[kVdbUuidAt + 18] == '-' &&
                             header[kVdbUuidAt + 23] == '-';
  if (!looksLikeUuid) fail("the serialised header has no UUID where OpenVDB 10 puts it", EINVAL);
  char hex[kChecksumDigits + 1];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  const std::string checksum(hex, kChecksumDigits), uuid = vdbUuidForChecksum(checksum);
  errno = 0;
  if (::pwrite(f.fd, checksum.data(), checksum.size(), off_t(digitsAt)) != ssize_t(checksum.size()) ||
      ::pwrite(f.fd, uuid.data(), uuid.size(), off_t(kVdbUuidAt)) != ssize_t(uuid.size()))
    fail("write", errno ? errno : EIO);
  struct stat st;
  if (::fsync(f.fd) != 0 || ::fstat(f.fd, &st) != 0) fail("fsync", errno);
  const int fd = f.fd;
  f.fd = -1;
  if (::close(fd) != 0) fail("close", errno);
  if (int64_t(st.st_size) != size)
    fail("size " + std::to_string(st.st_size) + " instead of " + std::to_string(size), EIO);
}

}  // namespace frep::io::detail
