#include "frep/net/curve.h"

#include <spdlog/spdlog.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zmq_addon.hpp>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <thread>

namespace frep::farm {

namespace fs = std::filesystem;

namespace {
const char* const kKeyFiles[] = {"master.pub", "master.key", "worker.pub", "worker.key", "authorized"};

// Written to a temporary created here (O_EXCL | O_NOFOLLOW: never through a planted link, never
// an existing file), with its final mode from the start (a secret key is never readable by others,
// not even for a moment), then renamed over the key.
void writeKey(const fs::path& p, const std::string& key, bool secret) {
  fs::path tmp = p;
  tmp += ".tmp" + std::to_string(::getpid());
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, secret ? 0600 : 0644);
  if (fd < 0) throw std::runtime_error("cannot create " + tmp.string() + ": " + std::strerror(errno));
  const std::string line = key + "\n";
  const bool ok = ::write(fd, line.data(), line.size()) == ssize_t(line.size()) && ::fsync(fd) == 0;
  if (::close(fd) != 0 || !ok) {
    ::unlink(tmp.c_str());
    throw std::runtime_error("cannot write " + tmp.string() + ": " + std::strerror(errno));
  }
  std::error_code ec;
  fs::rename(tmp, p, ec);
  if (ec) {
    ::unlink(tmp.c_str());
    throw std::runtime_error("cannot write " + p.string() + ": " + ec.message());
  }
}

std::string readKey(const fs::path& p) {
  std::ifstream f(p);
  std::string k;
  if (!(f >> k)) throw std::runtime_error("CURVE key file missing or empty: " + p.string() + " (make keys with `frep keygen DIR`)");
  if (k.size() != 40) throw std::runtime_error("CURVE key file " + p.string() + ": expected a 40-character Z85 key");
  return k;
}
}  // namespace

std::vector<std::string> existingCurveKeys(const std::string& dir) {
  std::vector<std::string> found;
  for (const char* f : kKeyFiles) {
    std::error_code ec;
    if (fs::symlink_status(fs::path(dir) / f, ec).type() != fs::file_type::not_found && !ec) found.push_back(f);
  }
  return found;
}

void generateCurveKeys(const std::string& dir, bool replace) {
  if (!replace) {
    const std::vector<std::string> found = existingCurveKeys(dir);
    if (!found.empty()) {
      std::string list;
      for (const std::string& f : found) list += (list.empty() ? "" : ", ") + f;
      throw CurveKeysExist(dir + " already has CURVE keys (" + list +
                           "): new ones would lock out every worker holding the old ones; add --force to replace them");
    }
  }
  fs::create_directories(dir);
  char pub[41], sec[41];
  if (zmq_curve_keypair(pub, sec) != 0) throw std::runtime_error("this libzmq has no CURVE support");
  writeKey(fs::path(dir) / "master.pub", pub, false);
  writeKey(fs::path(dir) / "master.key", sec, true);
  if (zmq_curve_keypair(pub, sec) != 0) throw std::runtime_error("this libzmq has no CURVE support");
  writeKey(fs::path(dir) / "worker.pub", pub, false);
  writeKey(fs::path(dir) / "worker.key", sec, true);
  writeKey(fs::path(dir) / "authorized", pub, false);
}

CurveKeys loadCurveKeys(const std::string& dir, bool server) {
  CurveKeys k;
  k.masterPublic = readKey(fs::path(dir) / "master.pub");
  if (server) {
    k.masterSecret = readKey(fs::path(dir) / "master.key");
    std::ifstream f(fs::path(dir) / "authorized");
    std::string line;
    while (f >> line)
      if (line.size() == 40) k.authorized.push_back(line);
    if (k.authorized.empty()) throw std::runtime_error("CURVE: " + (fs::path(dir) / "authorized").string() + " lists no worker key");
  } else {
    k.workerPublic = readKey(fs::path(dir) / "worker.pub");
    k.workerSecret = readKey(fs::path(dir) / "worker.key");
  }
  return k;
}

void applyCurveServer(zmq::socket_t& s, const CurveKeys& k) {
  s.set(zmq::sockopt::curve_server, 1);
  s.set(zmq::sockopt::curve_secretkey, k.masterSecret);
  s.set(zmq::sockopt::zap_domain, "frepfarm");
}

void applyCurveClient(zmq::socket_t& s, const CurveKeys& k) {
  s.set(zmq::sockopt::curve_serverkey, k.masterPublic);
  s.set(zmq::sockopt::curve_publickey, k.workerPublic);
  s.set(zmq::sockopt::curve_secretkey, k.workerSecret);
}

struct ZapAuthenticator::Impl {
  zmq::socket_t socket;
  std::thread thread;
  std::atomic<bool> stop{false};
  std::atomic<uint64_t> rejected{0};
  std::vector<std::string> keys;  // Z85
};

ZapAuthenticator::ZapAuthenticator(zmq::context_t& ctx, std::vector<std::string> authorized)
    : impl_(new Impl{zmq::socket_t(ctx, zmq::socket_type::rep), {}, {}, {}, std::move(authorized)}) {
  impl_->socket.set(zmq::sockopt::linger, 0);
  impl_->socket.bind("inproc://zeromq.zap.01");
  impl_->thread = std::thread([impl = impl_.get()] {
    // ZAP (RFC 27): version, request id, domain, address, identity, mechanism, credentials...
    while (!impl->stop) {
      zmq::pollitem_t item{static_cast<void*>(impl->socket), 0, ZMQ_POLLIN, 0};
      zmq::poll(&item, 1, std::chrono::milliseconds(100));
      if (!(item.revents & ZMQ_POLLIN)) continue;
      std::vector<zmq::message_t> req;
      if (!zmq::recv_multipart(impl->socket, std::back_inserter(req))) continue;
      bool ok = false;
      if (req.size() >= 7 && req[5].to_string() == "CURVE" && req[6].size() == 32) {
        char z85[41];
        zmq_z85_encode(z85, static_cast<const uint8_t*>(req[6].data()), 32);
        for (auto& k : impl->keys) ok = ok || k == z85;
      }
      if (!ok) {
        ++impl->rejected;
        spdlog::warn("CURVE: refused a client whose key is not authorized");
      }
      const std::string requestId = req.size() > 1 ? req[1].to_string() : std::string();
      std::vector<zmq::const_buffer> reply{zmq::str_buffer("1.0"), zmq::buffer(requestId),
                                           ok ? zmq::str_buffer("200") : zmq::str_buffer("400"),
                                           ok ? zmq::str_buffer("OK") : zmq::str_buffer("not authorized"),
                                           zmq::str_buffer(""), zmq::str_buffer("")};
      zmq::send_multipart(impl->socket, reply);
    }
  });
}

ZapAuthenticator::~ZapAuthenticator() {
  impl_->stop = true;
  impl_->thread.join();
}

uint64_t ZapAuthenticator::rejected() const { return impl_->rejected; }

}  // namespace frep::farm
