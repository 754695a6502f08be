// Files a model names (frVolumeSplineFile, frMesh, frVolume) read from the disk, under the
// compile's policy (CompileOptions::fileAccess): a farm worker opens no path a job names unless
// the path lies inside its --data-dir; whatever is opened is a regular file of bounded size.
#include <fcntl.h>
#include <limits.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>

#include "frep/lang/hyperfun.h"

namespace frep::lang {
namespace {

[[noreturn]] void refuse(const std::string& path, const std::string& why) {
  throw std::runtime_error("'" + path + "': " + why);
}

std::string sizeText(uint64_t n) {
  if (n >= (uint64_t(1) << 30) && n % (uint64_t(1) << 30) == 0) return std::to_string(n >> 30) + " GiB";
  if (n >= (uint64_t(1) << 20) && n % (uint64_t(1) << 20) == 0) return std::to_string(n >> 20) + " MiB";
  return std::to_string(n) + " bytes";
}

// The canonical path (every symbolic link resolved), or "" when it does not exist.
std::string realPath(const std::string& p) {
  char buf[PATH_MAX];
  if (!::realpath(p.c_str(), buf)) return "";
  return buf;
}

struct Fd {
  int fd;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

std::string readOpened(int fd, const std::string& path, uint64_t maxBytes) {
  struct stat st {};
  if (::fstat(fd, &st) != 0) refuse(path, std::string("cannot read the file (") + std::strerror(errno) + ")");
  if (S_ISDIR(st.st_mode)) refuse(path, "is a directory, not a file");
  if (!S_ISREG(st.st_mode))
    refuse(path, "is not a regular file (a device, FIFO or socket); refusing to read it");
  if (uint64_t(st.st_size) > maxBytes)
    refuse(path, "is " + std::to_string(uint64_t(st.st_size)) + " bytes, more than the limit of " + sizeText(maxBytes));
  std::string bytes(size_t(st.st_size), '\0');
  size_t got = 0;
  while (got < bytes.size()) {
    const ssize_t n = ::read(fd, bytes.data() + got, bytes.size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) refuse(path, std::string("cannot read the file (") + std::strerror(errno) + ")");
    if (n == 0) break;  // shrank while read: what is there
    got += size_t(n);
  }
  bytes.resize(got);
  return bytes;
}

}  // namespace

std::string readRegularFile(const std::string& path, uint64_t maxBytes, bool noFollow) {
  if (path.empty()) throw std::runtime_error("empty file name");
  if (path.find('\0') != std::string::npos) refuse(path, "a file name with a NUL byte");
  // O_NONBLOCK: opening a FIFO with no writer would otherwise wait for one.
  Fd f{::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY | (noFollow ? O_NOFOLLOW : 0))};
  if (f.fd < 0) {
    if (errno == ELOOP && noFollow) refuse(path, "is a symbolic link; refusing to follow it");
    throw std::runtime_error("cannot open file '" + path + "' (" + std::strerror(errno) + ")");
  }
  return readOpened(f.fd, path, maxBytes);
}

std::string readModelFileFromDisk(const std::string& written, const std::string& modelFile,
                                  const CompileOptions& options) {
  if (written.empty()) throw std::runtime_error("empty file name");
  switch (options.fileAccess) {
    case CompileOptions::FileAccess::Local: {
      std::string full = written;
      const size_t slash = modelFile.rfind('/');
      if (written[0] != '/' && slash != std::string::npos) full = modelFile.substr(0, slash + 1) + written;
      return readRegularFile(full, options.maxFileBytes);
    }
    case CompileOptions::FileAccess::JobOnly:
      refuse(written,
             "is not among the files the job ships; a farm worker opens no path a job names "
             "(frep-worker --data-dir DIR lets it read regular files inside DIR)");
    case CompileOptions::FileAccess::DataDir:
      break;
  }
  const std::string dir = realPath(options.dataDir);
  if (dir.empty()) refuse(options.dataDir, "the data directory does not exist");
  const std::string candidate = written[0] == '/' ? written : dir + "/" + written;
  const std::string real = realPath(candidate);
  const std::string inside = dir == "/" ? dir : dir + "/";
  if (real.empty() || real.compare(0, inside.size(), inside) != 0 || real.size() == inside.size())
    refuse(written, real.empty() ? "is not among the files the job ships, nor in the worker's data directory"
                                 : "is not among the files the job ships and lies outside the worker's data "
                                   "directory; refusing to read it");
  // The resolved path, its last component not followed, and what was opened checked again (a
  // directory swapped for a link between realpath and open is caught here).
  Fd f{::open(real.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY | O_NOFOLLOW)};
  if (f.fd < 0) refuse(written, std::string("cannot open the file in the data directory (") + std::strerror(errno) + ")");
  char link[PATH_MAX];
  const std::string self = "/proc/self/fd/" + std::to_string(f.fd);
  const ssize_t n = ::readlink(self.c_str(), link, sizeof link - 1);
  if (n > 0) {
    const std::string opened(link, size_t(n));
    if (opened.compare(0, inside.size(), inside) != 0)
      refuse(written, "changed while it was opened and lies outside the worker's data directory; refusing to read it");
  }
  return readOpened(f.fd, written, options.maxFileBytes);
}

}  // namespace frep::lang
