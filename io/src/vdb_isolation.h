// OpenVDB's parse of a .vdb's grids, run in a child process. OpenVDB trusts the lengths inside a
// grid's compressed blocks (io::bloscFromStream copies a stored size before it checks it), which
// no check in front of it can see without parsing the whole tree: a damaged or crafted file may
// overwrite the reader's heap. The child parses the file and writes the grid it read again to an
// anonymous in-memory file (memfd), all values stored, no compression; the parent then reads that
// file, which OpenVDB itself wrote from a tree it holds. A crash in the child becomes exit 3.
#pragma once

#include <functional>
#include <string>

namespace frep::io {

// The child's output: an anonymous file read through /proc/self/fd (closed on destruction).
class IsolatedOutput {
 public:
  explicit IsolatedOutput(int fd) : fd_(fd) {}
  ~IsolatedOutput();
  IsolatedOutput(IsolatedOutput&& o) noexcept : fd_(o.fd_) { o.fd_ = -1; }
  IsolatedOutput(const IsolatedOutput&) = delete;
  IsolatedOutput& operator=(const IsolatedOutput&) = delete;
  std::string path() const { return "/proc/self/fd/" + std::to_string(fd_); }

 private:
  int fd_;
};

// Runs write(path of an empty anonymous file) in a forked child. An Error it throws is passed back
// and thrown again here (code and message); a child killed by a signal (SIGSEGV, SIGABRT, a heap
// check) or ending any other way throws Error(kExitIoError) "cannot read VDB 'shown': …".
IsolatedOutput runIsolated(const std::string& shown, const std::function<void(const std::string&)>& write);

}  // namespace frep::io
