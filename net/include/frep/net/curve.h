// ZeroMQ CURVE security for the farm on shared networks.
//
// `frep keygen DIR` writes two key pairs: master.{pub,key} and worker.{pub,key} (Z85 text).
// The master (--curve DIR) serves CURVE with master.key and, through a ZAP handler, admits
// only clients whose public key is listed in DIR/authorized (one Z85 key per line; keygen puts
// worker.pub there). A worker (--curve DIR) needs master.pub and worker.{pub,key}. A client
// without the keys cannot complete the handshake, so it never reaches the master's code.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>
#include <zmq.hpp>

namespace frep::farm {

struct CurveKeys {
  std::string masterPublic, masterSecret;  // masterSecret only on the master
  std::string workerPublic, workerSecret;  // worker pair only on workers
  std::vector<std::string> authorized;     // on the master
};

// Thrown by generateCurveKeys when dir already has keys and `replace` is false.
struct CurveKeysExist : std::runtime_error {
  using std::runtime_error::runtime_error;
};
// The key files (master.pub, master.key, worker.pub, worker.key, authorized) present in dir.
std::vector<std::string> existingCurveKeys(const std::string& dir);
// Writes a fresh set of keys into dir (created if missing). Refuses (CurveKeysExist, nothing
// written) when dir has any of them already, unless `replace`: new keys lock out every worker
// that holds the old ones. Throws std::runtime_error when a file cannot be written.
void generateCurveKeys(const std::string& dir, bool replace = false);
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
