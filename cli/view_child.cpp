// Child processes of frep view (view_child.h): fork/exec with both output pipes read by poll().
#include "view_child.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/prctl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <initializer_list>
#include <stdexcept>

namespace frep::cli {

std::string selfExecutable() {
  char buf[4096];
  const ssize_t n = ::readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) throw std::runtime_error(std::string("cannot read /proc/self/exe: ") + std::strerror(errno));
  return std::string(buf, size_t(n));
}

ChildResult runChild(const std::vector<std::string>& argv, const std::atomic<bool>* cancel) {
  int outPipe[2], errPipe[2];
  if (::pipe2(outPipe, O_CLOEXEC) != 0) throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
  if (::pipe2(errPipe, O_CLOEXEC) != 0) {
    ::close(outPipe[0]), ::close(outPipe[1]);
    throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
  }
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
  if (pid == 0) {  // the child: only async-signal-safe calls until exec
    sigset_t none;
    sigemptyset(&none);
    struct sigaction dfl {};
    dfl.sa_handler = SIG_DFL;
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) ::sigaction(sig, &dfl, nullptr);  // no handler of ours before exec
    ::sigprocmask(SIG_SETMASK, &none, nullptr);  // frep view blocks SIGINT/SIGTERM in its threads
    ::setpgid(0, 0);                             // its own group, so that SIGKILL reaches the processes it starts too
    const int devNull = ::open("/dev/null", O_RDONLY);
    if (devNull >= 0) ::dup2(devNull, 0);
    ::dup2(outPipe[1], 1);
    ::dup2(errPipe[1], 2);
    ::execv(args[0], args.data());
    const char* why = std::strerror(errno);  // not async-signal-safe in theory; glibc's reads a table
    for (const char* part : std::initializer_list<const char*>{"frep view: cannot run ", args[0], ": ", why, "\n"})
      if (::write(2, part, std::strlen(part)) < 0) break;
    _exit(127);
  }
  ::close(outPipe[1]);
  ::close(errPipe[1]);
  ChildResult r;
  pollfd fds[2] = {{outPipe[0], POLLIN, 0}, {errPipe[0], POLLIN, 0}};
  std::string* sinks[2] = {&r.out, &r.err};
  int open = 2, status = 0;
  using Clock = std::chrono::steady_clock;
  Clock::time_point termSent, ended;
  bool killed = false, exited = false;
  // Until both pipes close, or 200 ms after the child ended: a process it started (a local
  // worker) may hold them open a while longer.
  while (open > 0 && !(exited && Clock::now() - ended > std::chrono::milliseconds(200))) {
    if (cancel && cancel->load() && !r.cancelled) {
      r.cancelled = true;
      ::kill(pid, SIGTERM);
      termSent = Clock::now();
    }
    if (r.cancelled && !killed && !exited && Clock::now() - termSent > std::chrono::seconds(2)) {
      ::kill(-pid, SIGKILL);  // a child that ignores the interrupt contract, and what it started
      killed = true;
    }
    if (::poll(fds, 2, 50) < 0 && errno != EINTR) break;
    for (int i = 0; i < 2; ++i) {
      if (fds[i].fd < 0 || !(fds[i].revents & (POLLIN | POLLHUP | POLLERR))) continue;
      char buf[65536];
      const ssize_t n = ::read(fds[i].fd, buf, sizeof buf);
      if (n > 0) {
        sinks[i]->append(buf, size_t(n));
      } else if (n == 0 || errno != EINTR) {
        ::close(fds[i].fd);
        fds[i].fd = -1;  // poll() ignores negative descriptors
        --open;
      }
    }
    if (!exited && ::waitpid(pid, &status, WNOHANG) == pid) exited = true, ended = Clock::now();
  }
  for (auto& f : fds)
    if (f.fd >= 0) ::close(f.fd);
  if (!exited)
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {}
  if (r.cancelled) r.stopSeconds = std::chrono::duration<double>(Clock::now() - termSent).count();
  if (exited && r.cancelled) r.stopSeconds = std::chrono::duration<double>(ended - termSent).count();
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : WIFSIGNALED(status) ? 128 + WTERMSIG(status) : -1;
  return r;
}

}  // namespace frep::cli
