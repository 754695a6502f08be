#include "atomic_output.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>

#include "exit_codes.h"

namespace frep::cli {
namespace {

// The temporary file in progress, for the signal handler: Ctrl-C or a batch system's SIGTERM
// must not leave it behind. One output at a time is all the frep verbs need.
char gPendingTemp[4096];
volatile std::sig_atomic_t gHavePending = 0;

extern "C" void removePendingAndReraise(int sig) {
  if (gHavePending) ::unlink(gPendingTemp);
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

void trackPending(const std::string& temp) {
  static const bool installed = [] {
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) std::signal(sig, removePendingAndReraise);
    return true;
  }();
  (void)installed;
  gHavePending = 0;
  if (temp.size() >= sizeof gPendingTemp) return;  // untracked: only a leftover on a signal
  std::memcpy(gPendingTemp, temp.c_str(), temp.size() + 1);
  gHavePending = 1;
}

}  // namespace

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
  trackPending(temp_);
}

AtomicOutput::~AtomicOutput() {
  gHavePending = 0;
  if (!committed_) std::remove(temp_.c_str());
}

void AtomicOutput::commit() {
  if (std::rename(temp_.c_str(), path_.c_str()) != 0)
    throw ioError(field_ + ": cannot rename '" + temp_ + "' to '" + path_ + "': " + std::strerror(errno));
  committed_ = true;
}

}  // namespace frep::cli
