#include "frep/io/atomic_output.h"

#include <dirent.h>
#include <fcntl.h>
#include <pthread.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <string>

#include "frep/io/error.h"

namespace frep::io {
namespace {

// The temporary files in progress, for the signal handler: Ctrl-C or a batch system's SIGTERM
// during planning or the final write must not leave them behind (the farm's job loop has its own
// handlers while it runs). A verb has at most a few outputs at a time (data file and report).
constexpr int kSlots = 8;
char gPendingTemp[kSlots][4096];
volatile std::sig_atomic_t gPending[kSlots] = {};

// Async-signal-safe: unlink() and _exit() only. The documented code for SIGINT/SIGTERM/SIGHUP
// is 6 (interrupted; a journal, if any, is complete up to the last merged brick).
extern "C" void removePendingAndExit(int) {
  for (int i = 0; i < kSlots; ++i)
    if (gPending[i]) ::unlink(gPendingTemp[i]);
  ::_exit(kExitInterrupted);
}

// Installed when the program starts (this file is linked into frep), so that a signal during
// argument checks or model loading gives the documented code too.
const bool gHandlersInstalled = [] {
  struct sigaction sa {};
  sa.sa_handler = removePendingAndExit;
  sigemptyset(&sa.sa_mask);
  sigset_t set;
  sigemptyset(&set);
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) sigaction(sig, &sa, nullptr), sigaddset(&set, sig);
  // A launcher may start us with them blocked (so that none is lost before this point): take them now.
  sigprocmask(SIG_UNBLOCK, &set, nullptr);
  return true;
}();

int trackPending(const std::string& temp) {
  (void)gHandlersInstalled;
  if (temp.size() >= sizeof gPendingTemp[0]) return -1;  // untracked: only a leftover on a signal
  for (int i = 0; i < kSlots; ++i) {
    if (gPending[i]) continue;
    std::memcpy(gPendingTemp[i], temp.c_str(), temp.size() + 1);
    gPending[i] = 1;
    return i;
  }
  return -1;
}

const char* fileKind(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISLNK(mode)) return "a symbolic link";
  return "not a regular file";
}

// The policy for -O: a new file or an existing regular file is replaced by rename(); anything
// else (a symlink, a FIFO, a device such as /dev/null, a socket, a directory) is refused, so
// that frep never replaces a special file nor writes somewhere the name does not show.
void requireReplaceable(const std::string& field, const std::string& path) {
  struct stat st;
  if (::lstat(path.c_str(), &st) != 0) {
    if (errno == ENOENT) return;
    throw ioError(field + ": cannot write '" + path + "': " + std::strerror(errno));
  }
  if (!S_ISREG(st.st_mode))
    throw ioError(field + ": '" + path + "' is " + fileKind(st.st_mode) +
                  "; frep writes only new or regular files (it would replace it)");
}

// The temporaries of this target left by processes that are gone (a SIGKILLed master cannot
// remove its own): ".NAME.tmpPID" with PID no longer running. A live process's is never touched.
void removeOrphanedTemporaries(const std::string& path) {
  const size_t slash = path.rfind('/');
  const std::string dir = slash == std::string::npos ? "." : path.substr(0, slash + 1);
  const std::string prefix = "." + (slash == std::string::npos ? path : path.substr(slash + 1)) + ".tmp";
  DIR* d = ::opendir(dir.c_str());
  if (!d) return;
  while (const dirent* e = ::readdir(d)) {
    const std::string name = e->d_name;
    if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string digits = name.substr(prefix.size());
    if (digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos) continue;
    const pid_t pid = pid_t(std::stol(digits));
    if (pid <= 0 || pid == ::getpid() || ::kill(pid, 0) == 0 || errno != ESRCH) continue;
    const std::string full = (slash == std::string::npos ? "" : dir) + name;
    struct stat st;
    if (::lstat(full.c_str(), &st) == 0 && S_ISREG(st.st_mode)) ::unlink(full.c_str());
  }
  ::closedir(d);
}

}  // namespace

AtomicOutput::AtomicOutput(const std::string& field, const std::string& path) : field_(field), path_(path) {
  if (path.empty()) throw badArgs(field + ": the output path is empty");
  if (path.back() == '/') throw badArgs(field + ": '" + path + "' names a directory, not a file");
  requireReplaceable(field, path);
  // A hidden name in the target's directory: rename() then never crosses a file system.
  size_t slash = path.rfind('/');
  std::string dir = slash == std::string::npos ? "" : path.substr(0, slash + 1);
  std::string base = slash == std::string::npos ? path : path.substr(slash + 1);
  temp_ = dir + "." + base + ".tmp" + std::to_string(::getpid());
  ::unlink(temp_.c_str());  // a leftover of an earlier process with our pid (never followed)
  // The stop signals wait while the file is created and tracked: one arriving in between would
  // exit without knowing the file (seen on a loaded machine).
  sigset_t stops, old;
  sigemptyset(&stops);
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&stops, sig);
  ::pthread_sigmask(SIG_BLOCK, &stops, &old);
  int fd = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
  const int err = errno;
  if (fd >= 0) {
    ::close(fd);
    slot_ = trackPending(temp_);
  }
  ::pthread_sigmask(SIG_SETMASK, &old, nullptr);
  if (fd < 0) throw ioError(field + ": cannot write '" + path + "': " + std::strerror(err));
}

AtomicOutput::~AtomicOutput() {
  if (!committed_) std::remove(temp_.c_str());
  if (slot_ >= 0) gPending[slot_] = 0;
}

void AtomicOutput::commit() {
  // The data must be on the disk before the name is: a crash after rename() shows the whole file.
  int fd = ::open(temp_.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0 || ::fsync(fd) != 0) {
    int err = errno;
    if (fd >= 0) ::close(fd);
    throw ioError(field_ + ": cannot write '" + path_ + "': " + std::strerror(err));
  }
  ::close(fd);
  requireReplaceable(field_, path_);  // it may have appeared while the job ran
  if (std::rename(temp_.c_str(), path_.c_str()) != 0)
    throw ioError(field_ + ": cannot rename '" + temp_ + "' to '" + path_ + "': " + std::strerror(errno));
  committed_ = true;
  if (slot_ >= 0) gPending[slot_] = 0;
  removeOrphanedTemporaries(path_);
}

}  // namespace frep::io
