// frep view's HTTP server, the module libfrep_view.so that frep loads for that verb only
// (view_command.cpp; cpp-httplib links libssl and libcrypto, ~3 ms of every process start): the
// page with the model in 3D (three.js, WebGL), its slices and the report of frep mesh, updated on
// every save of the .hf file (view_session.h). The page's files are view/web (docs/view.md), three.js
// among them from npm. Its calls into frepfarm bind to the program's functions (exported by it).
#include <httplib.h>
#include <signal.h>
#include <sys/socket.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <thread>

#include "commands.h"
#include "exit_codes.h"
#include "view_child.h"
#include "view_server.h"
#include "view_session.h"

#ifndef FREP_VIEW_SOURCE_DIR
#define FREP_VIEW_SOURCE_DIR ""
#endif
#ifndef FREP_VERSION
#define FREP_VERSION "unknown"
#endif

namespace frep::cli {

namespace {

namespace fs = std::filesystem;

constexpr const char* kThreeModule = "node_modules/three/build/three.module.js";

// The page's folder: $FREP_VIEW_WEB, else installed beside the binary (PREFIX/share/frepfarm/view),
// else the source tree's view/web. It must hold index.html and three.js (installed by npm).
fs::path findWebDir() {
  std::vector<fs::path> candidates;
  if (const char* env = std::getenv("FREP_VIEW_WEB")) candidates.emplace_back(env);
  candidates.push_back(fs::path(selfExecutable()).parent_path() / "../share/frepfarm/view");
  if (*FREP_VIEW_SOURCE_DIR) candidates.emplace_back(FREP_VIEW_SOURCE_DIR);
  std::string looked;
  for (const auto& dir : candidates) {
    if (fs::exists(dir / "index.html") && fs::exists(dir / kThreeModule)) return fs::canonical(dir);
    looked += "\n  " + dir.string() + (fs::exists(dir / "index.html") ? " (no " + std::string(kThreeModule) + ")" : "");
  }
  throw ioError("frep view: the page's files (index.html and three.js) were not found; looked in:" + looked +
                "\nthree.js comes from npm: run deploy/build.sh, or `npm ci` in view/web");
}

bool isLoopback(const std::string& host) {
  return host == "127.0.0.1" || host == "localhost" || host == "::1" || host.rfind("127.", 0) == 0;
}

// SIGINT/SIGTERM/SIGHUP stop the server: blocked in every thread (children unblock them) and
// taken by a thread of their own, so that the job in progress is interrupted and cleaned up.
class SignalStop {
 public:
  SignalStop() {
    sigemptyset(&set_);
    for (int s : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&set_, s);
    pthread_sigmask(SIG_BLOCK, &set_, &old_);
  }
  ~SignalStop() {
    done_ = true;
    if (thread_.joinable()) thread_.join();
    pthread_sigmask(SIG_SETMASK, &old_, nullptr);
  }
  void watch(httplib::Server& server) {
    thread_ = std::thread([this, &server] {
      const timespec tick{0, 200 * 1000 * 1000};
      while (!done_) {
        const int s = sigtimedwait(&set_, nullptr, &tick);
        if (s > 0) {
          spdlog::info("signal {}: stopping", s);
          server.stop();
          return;
        }
      }
    });
  }

 private:
  sigset_t set_, old_;
  std::atomic<bool> done_{false};
  std::thread thread_;
};

void noStore(httplib::Response& res) { res.set_header("Cache-Control", "no-store"); }

// Bound to loopback, only requests addressed to loopback are answered: a web page elsewhere
// whose domain name resolves to 127.0.0.1 (DNS rebinding) is refused, as Jupyter and webpack's
// dev server do. Another --host serves any name.
void refuseForeignHosts(httplib::Server& server, const std::string& host, int port) {
  if (!isLoopback(host)) return;
  const std::string p = ":" + std::to_string(port);
  const std::vector<std::string> allowed{"127.0.0.1" + p, "localhost" + p, "[::1]" + p, host + p};
  server.set_pre_routing_handler([allowed](const httplib::Request& req, httplib::Response& res) {
    const std::string h = req.get_header_value("Host");
    for (const auto& a : allowed)
      if (h == a) return httplib::Server::HandlerResponse::Unhandled;
    res.status = 403;
    res.set_content("frep view answers only requests to this machine's loopback address\n", "text/plain");
    return httplib::Server::HandlerResponse::Handled;
  });
}

void addRoutes(httplib::Server& server, ViewSession& session, const fs::path& web) {
  for (const auto& [ext, type] : {std::pair{"js", "text/javascript"},
                                  {"mjs", "text/javascript"},
                                  {"html", "text/html"},
                                  {"css", "text/css"},
                                  {"png", "image/png"}})
    server.set_file_extension_and_mimetype_mapping(ext, type);
  server.set_mount_point("/", web.string());
  server.Get("/api/state", [&](const httplib::Request&, httplib::Response& res) {
    noStore(res);
    res.set_content(session.state().dump(), "application/json");
  });
  server.Get("/api/mesh", [&](const httplib::Request&, httplib::Response& res) {
    uint64_t generation = 0;
    auto glb = session.mesh(&generation);
    noStore(res);
    res.set_header("X-Generation", std::to_string(generation));
    res.set_content(*glb, "model/gltf-binary");
  });
  // /api/slice?axis=z&at=0.25&res=256: frep slice of the current file, or its error text (422).
  server.Get("/api/slice", [&](const httplib::Request& req, httplib::Response& res) {
    noStore(res);
    const std::string axis = req.has_param("axis") ? req.get_param_value("axis") : "z";
    char* end = nullptr;
    const std::string atText = req.has_param("at") ? req.get_param_value("at") : "0";
    const double at = std::strtod(atText.c_str(), &end);
    const int sliceRes = req.has_param("res") ? std::atoi(req.get_param_value("res").c_str()) : 256;
    if ((axis != "x" && axis != "y" && axis != "z") || end == atText.c_str() || *end || !std::isfinite(at) ||
        sliceRes < 16 || sliceRes > 2048) {
      res.status = 400;
      res.set_content("expected axis=x|y|z, a finite at= and res= from 16 to 2048", "text/plain");
      return;
    }
    ViewSession::Slice s = session.slice(axis[0], at, sliceRes);
    if (s.ok) return res.set_content(s.png, "image/png");
    res.status = 422;
    res.set_content(s.error, "text/plain; charset=utf-8");
  });
}

}  // namespace

int serveView(const ViewRequest& request) {
  const fs::path web = findWebDir();
  spdlog::info("the page's files: {}", web.string());
  if (!isLoopback(request.host))
    spdlog::warn("--host {}: anyone who reaches this address sees the model and can run slices of it", request.host);

  SignalStop signals;  // before any thread starts, so that every thread inherits the mask
  ViewSession session(request, selfExecutable());
  httplib::Server server;
  // SO_REUSEADDR only: httplib's default adds SO_REUSEPORT, with which a second frep view on the
  // same port would bind too and share the connections with the first.
  server.set_socket_options([](int sock) {
    const int yes = 1;
    ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });
  addRoutes(server, session, web);
  const int port = request.port == 0 ? server.bind_to_any_port(request.host)
                                     : (server.bind_to_port(request.host, request.port) ? request.port : -1);
  if (port <= 0)
    throw CliError(kExitFarmError, "--host/--port: cannot listen on " + request.host + ":" +
                                       std::to_string(request.port) + " (in use, or not an address of this machine)");
  refuseForeignHosts(server, request.host, port);
  const std::string host = request.host.find(':') != std::string::npos ? "[" + request.host + "]" : request.host;
  std::cout << "frep view: http://" << host << ":" << port << "/ shows " << request.model.path
            << " (updated on every save; Ctrl-C stops)" << std::endl;
  session.start();
  signals.watch(server);
  server.listen_after_bind();
  session.stop();
  return kExitOk;
}

}  // namespace frep::cli

extern "C" __attribute__((visibility("default"))) const void* frep_view_server(const char* version, size_t tableSize) {
  // A module of another build (a stale install next to a new program) answers nothing.
  if (!version || std::strcmp(version, FREP_VERSION) != 0 || tableSize != sizeof(frep::cli::ViewServer)) return nullptr;
  static const frep::cli::ViewServer table{frep::cli::serveView};
  return &table;
}
