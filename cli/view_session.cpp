// frep view's session (view_session.h): the file watcher and the frep mesh / frep slice children.
#include "view_session.h"

#include <spdlog/spdlog.h>
#include <sys/stat.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "arg_parse.h"
#include "exit_codes.h"
#include "view_child.h"

namespace frep::cli {

namespace {

namespace fs = std::filesystem;

// What changes when a file is saved, in place or by rename (editors do both).
struct FileStamp {
  int64_t sec = -1, nsec = 0, size = 0;
  uint64_t inode = 0;
  bool operator==(const FileStamp& o) const {
    return sec == o.sec && nsec == o.nsec && size == o.size && inode == o.inode;
  }
};

FileStamp stampOf(const std::string& path) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) return {};  // missing for now (mid-rename): sec = -1
  return {int64_t(st.st_mtim.tv_sec), int64_t(st.st_mtim.tv_nsec), int64_t(st.st_size), uint64_t(st.st_ino)};
}

std::string readFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// A fresh private directory for one child's output files; removed by the caller.
fs::path makeTempDir() {
  std::string pattern = (fs::temp_directory_path() / "frep-view-XXXXXX").string();
  if (!::mkdtemp(pattern.data()))
    throw std::runtime_error("cannot create a temporary directory in " + fs::temp_directory_path().string());
  return pattern;
}

std::string joinCommand(const std::vector<std::string>& argv) {
  std::string s = "frep";  // argv[0] is the full path of this binary
  for (size_t i = 1; i < argv.size(); ++i) {
    const bool quote = argv[i].find_first_of(" \t'\"") != std::string::npos || argv[i].empty();
    s += " " + (quote ? "'" + argv[i] + "'" : argv[i]);
  }
  return s;
}

}  // namespace

ViewSession::ViewSession(const ViewRequest& request, std::string frepExe)
    : request_(request), exe_(std::move(frepExe)) {
  const Box box = request.bounds.empty() ? Box{} : parseBounds("-b/--bounds", request.bounds);
  for (int a = 0; a < 3; ++a) bounds_[size_t(a)] = box.lo[size_t(a)], bounds_[size_t(a + 3)] = box.hi[size_t(a)];
}

ViewSession::~ViewSession() { stop(); }

void ViewSession::start() {
  watcher_ = std::thread([this] { watchLoop(); });
}

void ViewSession::stop() {
  stopping_ = true;
  wake_.notify_all();
  if (watcher_.joinable()) watcher_.join();
}

std::vector<std::string> ViewSession::modelArgs() const {
  std::vector<std::string> a{request_.model.path};
  const std::pair<const char*, const std::string*> opts[] = {{"-o", &request_.model.object},
                                                             {"-a", &request_.model.params},
                                                             {"-x", &request_.model.mapping},
                                                             {"-b", &request_.bounds}};
  for (const auto& [flag, value] : opts)
    if (!value->empty()) a.insert(a.end(), {flag, *value});
  if (request_.model.iso != 0) a.insert(a.end(), {"-i", formatNumber(request_.model.iso)});
  return a;
}

// Polls the file's stamp (every 100 ms); a change starts a new job after the previous one was
// interrupted. A save is taken when the stamp has been stable for one poll, so that a file
// written in several pieces is read once.
void ViewSession::watchLoop() {
  FileStamp seen{-2, 0, 0, 0};  // never a real stamp: the first poll starts a job
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stopping_) {
    lock.unlock();
    FileStamp now = stampOf(request_.model.path);
    if (!(now == seen)) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      FileStamp settled = stampOf(request_.model.path);
      if (settled == now) {
        seen = now;
        if (jobCancel_) *jobCancel_ = true;  // the save interrupts the work in progress
        if (job_.joinable()) job_.join();
        lock.lock();
        const uint64_t generation = ++generation_;
        status_ = "computing";
        lock.unlock();
        jobCancel_ = std::make_shared<std::atomic<bool>>(false);
        job_ = std::thread([this, generation, cancel = jobCancel_] { runJob(generation, cancel); });
      }
    }
    lock.lock();
    wake_.wait_for(lock, std::chrono::milliseconds(100), [this] { return stopping_.load(); });
  }
  lock.unlock();
  if (jobCancel_) *jobCancel_ = true;
  if (job_.joinable()) job_.join();
}

void ViewSession::runJob(uint64_t generation, std::shared_ptr<std::atomic<bool>> cancel) {
  const auto start = std::chrono::steady_clock::now();
  fs::path dir;
  ChildResult r;
  std::vector<std::string> argv{exe_, "mesh"};
  try {
    dir = makeTempDir();
    const std::vector<std::string> model = modelArgs();
    argv.insert(argv.end(), model.begin(), model.end());
    // --up z: the page's camera is Z-up like the model, so bounds and slices need no mapping.
    argv.insert(argv.end(), {"-O", (dir / "view.glb").string(), "--up", "z", "--no-progress"});
    if (request_.res > 0) argv.insert(argv.end(), {"--res", std::to_string(request_.res)});
    if (!request_.cells.empty()) argv.insert(argv.end(), {"-g", request_.cells});
    if (request_.workers >= 0) argv.insert(argv.end(), {"--workers", std::to_string(request_.workers)});
    if (request_.logLevel != "info") argv.insert(argv.end(), {"--log-level", request_.logLevel});
    spdlog::info("save {}: {}", generation, joinCommand(argv));
    r = runChild(argv, cancel.get());
  } catch (const std::exception& e) {
    r.exitCode = kExitInternal;
    r.err = std::string("frep: internal error: ") + e.what() + "\n";
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::string glb, reportText;
  if (r.exitCode == 0 && !r.cancelled) {
    glb = readFile(dir / "view.glb");
    reportText = readFile(dir / "view.glb.report.json");
  }
  std::error_code ignored;
  if (!dir.empty()) fs::remove_all(dir, ignored);
  // The report shows where the files went: the temporary names say nothing to the user.
  auto scrub = [&](std::string s) {
    const std::string tmp = (dir / "view.glb").string();
    for (size_t p; !tmp.empty() && (p = s.find(tmp)) != std::string::npos;) s.replace(p, tmp.size(), "(view)");
    return s;
  };

  std::lock_guard<std::mutex> lock(mutex_);
  if (r.cancelled) {
    ++interrupted_;
    spdlog::info("save {}: interrupted by a newer save after {:.3f} s; frep mesh stopped {:.3f} s after SIGTERM",
                 generation, seconds, r.stopSeconds);
    return;  // the newer job owns the state
  }
  if (generation != generation_) return;
  command_ = scrub(joinCommand(argv));
  exitCode_ = r.exitCode;
  seconds_ = seconds;
  if (r.exitCode == 0 && !glb.empty()) {
    status_ = "ready";
    message_.clear();
    report_ = scrub(r.out);
    log_ = scrub(r.err);
    reportJson_ = nlohmann::json::parse(reportText, nullptr, false);
    mesh_ = std::make_shared<const std::string>(std::move(glb));
    meshGeneration_ = generation;
    spdlog::info("save {}: meshed in {:.3f} s", generation, seconds);
  } else {
    status_ = "error";
    message_ = scrub(r.err.empty() ? "frep mesh exited " + std::to_string(r.exitCode) + " without a message" : r.err);
    const std::string first = message_.substr(0, message_.find('\n'));
    spdlog::info("save {}: frep mesh exited {}: {}", generation, r.exitCode, first);
  }
}

nlohmann::json ViewSession::state() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return {{"generation", generation_},   {"status", status_},   {"message", message_},
          {"report", report_},           {"log", log_},         {"command", command_},
          {"exit_code", exitCode_},      {"seconds", seconds_}, {"mesh_generation", meshGeneration_},
          {"interrupted", interrupted_}, {"bounds", bounds_},   {"model", request_.model.path},
          {"report_json", reportJson_}};
}

std::shared_ptr<const std::string> ViewSession::mesh(uint64_t* generation) const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (generation) *generation = meshGeneration_;
  return mesh_;
}

ViewSession::Slice ViewSession::slice(char axis, double at, int res) const {
  Slice s;
  fs::path dir;
  try {
    dir = makeTempDir();
    std::vector<std::string> argv{exe_, "slice"};
    const std::vector<std::string> model = modelArgs();
    argv.insert(argv.end(), model.begin(), model.end());
    argv.insert(argv.end(), {"-O", (dir / "slice.png").string(), "--axis", std::string(1, axis), "--at",
                             formatNumber(at), "--res", std::to_string(res)});
    ChildResult r = runChild(argv, nullptr);
    if (r.exitCode == 0) {
      s.png = readFile(dir / "slice.png");
      s.ok = !s.png.empty();
    }
    if (!s.ok) s.error = r.err.empty() ? "frep slice exited " + std::to_string(r.exitCode) : r.err;
  } catch (const std::exception& e) {
    s.error = std::string("frep: internal error: ") + e.what();
  }
  std::error_code ignored;
  if (!dir.empty()) fs::remove_all(dir, ignored);
  return s;
}

}  // namespace frep::cli
