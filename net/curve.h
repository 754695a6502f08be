// ZeroMQ CURVE security for the farm on shared networks.
//
// `frep keygen DIR` writes two key pairs: master.{pub,key} and worker.{pub,key} (Z85 text).
// The master (--curve DIR) serves CURVE with master.key and, through a ZAP handler, admits
// only clients whose public key is listed in DIR/authorized (one Z85 key per line; keygen puts
// worker.pub there). A worker (--curve DIR) needs master.pub and worker.{pub,key}. A client
// without the keys cannot complete the handshake, so it never reaches the master's code.
#pragma once

#include <memory>
#include <string>
#include <vector>
#include <zmq.hpp>

namespace frep::farm {

struct CurveKeys {
  std::string masterPublic, masterSecret;  // masterSecret only on the master
  std::string workerPublic, workerSecret;  // worker pair only on workers
  std::vector<std::string> authorized;     // on the master
};

// Writes a fresh set of keys into dir (created if missing). Throws std::runtime_error.
void generateCurveKeys(const std::string& dir);
// Reads the keys a master (server = true) or a worker needs. Throws std::runtime_error naming
// the missing or malformed file.
CurveKeys loadCurveKeys(const std::string& dir, bool server);
void applyCurveServer(zmq::socket_t& socket, const CurveKeys& keys);
void applyCurveClient(zmq::socket_t& socket, const CurveKeys& keys);

// Runs the ZAP authentication handler on its own thread for as long as it lives; must be
// created before the server socket binds. Rejected attempts are counted.
class ZapAuthenticator {
 public:
  ZapAuthenticator(zmq::context_t& ctx, std::vector<std::string> authorizedKeys);
  ~ZapAuthenticator();
  uint64_t rejected() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace frep::farm
