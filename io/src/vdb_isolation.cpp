// A child process for OpenVDB's parse of a file; see vdb_isolation.h.
#include "vdb_isolation.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <exception>

#include "frep/io/error.h"

namespace frep::io {
namespace {

constexpr int kChildError = 10;  // the child threw Error: its code and message are in the pipe

void writeAll(int fd, const std::string& s) {
  for (size_t at = 0; at < s.size();) {
    const ssize_t n = ::write(fd, s.data() + at, s.size() - at);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;
    at += size_t(n);
  }
}

std::string readAll(int fd) {
  std::string s;
  char buf[4096];
  for (;;) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return s;
    if (s.size() < 65536) s.append(buf, size_t(n));  // a message, not a stream: bounded
  }
}

[[noreturn]] void childMain(int fd, int pipeOut, const std::function<void(const std::string&)>& write) {
  struct rlimit noCore = {0, 0};
  ::setrlimit(RLIMIT_CORE, &noCore);  // a crash here is reported by the parent, not dumped
  int code = kExitIoError;
  std::string message;
  try {
    write("/proc/self/fd/" + std::to_string(fd));
    // OpenVDB does not check its stream: a copy cut short by the file size limit (ulimit -f,
    // which holds for a memfd too) must be an I/O error here, not a damaged copy later.
    struct rlimit limit;
    struct stat st;
    if (::getrlimit(RLIMIT_FSIZE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY && ::fstat(fd, &st) == 0 &&
        uint64_t(st.st_size) >= uint64_t(limit.rlim_cur))
      throw ioError("cannot write the copy frep reads it from: the file size limit (ulimit -f, " +
                    std::to_string(uint64_t(limit.rlim_cur)) + " bytes) is reached");
    ::_exit(0);
  } catch (const Error& e) {
    code = e.code;
    message = e.what();
  } catch (const std::exception& e) {
    message = std::string("damaged (") + e.what() + ")";
  } catch (...) {
    message = "damaged (an unknown exception while OpenVDB parsed it)";
  }
  writeAll(pipeOut, std::to_string(code) + "\n" + message);
  ::_exit(kChildError);
}

}  // namespace

IsolatedOutput::~IsolatedOutput() {
  if (fd_ >= 0) ::close(fd_);
}

IsolatedOutput runIsolated(const std::string& shown, const std::function<void(const std::string&)>& write) {
  const std::string what = "cannot read VDB '" + shown + "': ";
  const int fd = ::memfd_create("frep-vdb", MFD_CLOEXEC);
  if (fd < 0) throw ioError(what + "memfd_create: " + std::strerror(errno));
  IsolatedOutput out(fd);
  int p[2];
  if (::pipe2(p, O_CLOEXEC) != 0) throw ioError(what + "pipe: " + std::strerror(errno));
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(p[0]);
    ::close(p[1]);
    throw ioError(what + "fork: " + std::strerror(errno));
  }
  if (pid == 0) {
    ::close(p[0]);
    childMain(fd, p[1], write);
  }
  ::close(p[1]);
  const std::string report = readAll(p[0]);
  ::close(p[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) throw ioError(what + "waitpid: " + std::strerror(errno));
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return out;
  if (WIFEXITED(status) && WEXITSTATUS(status) == kChildError) {
    const size_t nl = report.find('\n');
    if (nl != std::string::npos) {
      const int code = std::atoi(report.substr(0, nl).c_str());
      const std::string message = report.substr(nl + 1);
      if (code == kExitModelError || code == kExitIoError) {
        if (message.rfind("cannot read VDB", 0) == 0 || code == kExitModelError) throw Error(code, message);
        throw Error(code, what + message);
      }
    }
  }
  if (WIFSIGNALED(status))
    throw ioError(what + "OpenVDB's reader crashed on it (signal " + std::to_string(WTERMSIG(status)) + ", " +
                  ::strsignal(WTERMSIG(status)) +
                  ", in the child process frep reads grids in): the file is damaged or crafted");
  throw ioError(what + "OpenVDB's reader failed on it (child process exit " +
                std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + "): the file is damaged");
}

}  // namespace frep::io
