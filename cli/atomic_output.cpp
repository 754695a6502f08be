#include "atomic_output.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "exit_codes.h"

namespace frep::cli {

AtomicOutput::AtomicOutput(const std::string& field, const std::string& path) : field_(field), path_(path) {
  if (path.empty()) throw badArgs(field + ": the output path is empty");
  if (path.back() == '/') throw badArgs(field + ": '" + path + "' names a directory, not a file");
  // A hidden name in the target's directory: rename() then never crosses a file system.
  size_t slash = path.rfind('/');
  std::string dir = slash == std::string::npos ? "" : path.substr(0, slash + 1);
  std::string base = slash == std::string::npos ? path : path.substr(slash + 1);
  temp_ = dir + "." + base + ".tmp" + std::to_string(::getpid());
  int fd = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0)
    throw ioError(field + ": cannot write '" + path + "': " + std::strerror(errno));
  ::close(fd);
}

AtomicOutput::~AtomicOutput() {
  if (!committed_) std::remove(temp_.c_str());
}

void AtomicOutput::commit() {
  if (std::rename(temp_.c_str(), path_.c_str()) != 0)
    throw ioError(field_ + ": cannot rename '" + temp_ + "' to '" + path_ + "': " + std::strerror(errno));
  committed_ = true;
}

}  // namespace frep::cli
