#include "frep/net/wire.h"

#include <zmq_addon.hpp>

namespace frep::farm {

bool receive(zmq::socket_t& socket, bool router, Incoming& in, std::string* error, const FrameLimit& limit) {
  std::vector<zmq::message_t> frames;
  auto n = zmq::recv_multipart(socket, std::back_inserter(frames), zmq::recv_flags::dontwait);
  if (!n) return false;
  in = Incoming{};
  size_t first = 0;
  if (router) {
    in.routingId = frames[0].to_string();
    first = 1;
  }
  size_t count = frames.size() - first;
  for (size_t f = first; f < frames.size(); ++f) in.bytes += frames[f].size();
  if (limit && in.bytes > limit(in.routingId)) {
    in.oversized = true;
    if (error) *error = "oversized message (" + std::to_string(in.bytes) + " bytes)";
    return true;
  }
  if (count < 1 || count > 2) {
    if (error) *error = "wrong frame count " + std::to_string(count);
    return true;
  }
  if (!in.envelope.ParseFromArray(frames[first].data(), int(frames[first].size()))) {
    in.envelope.Clear();
    if (error) *error = "unparsable envelope (" + std::to_string(frames[first].size()) + " bytes)";
    return true;
  }
  if (count == 2) in.payload = std::move(frames[first + 1]);
  if (error) error->clear();
  return true;
}

bool send(zmq::socket_t& socket, const std::string& routingId, Envelope& env, const std::string* payload) {
  static thread_local uint64_t seq = 0;
  env.set_proto_major(kProtoMajor);
  env.set_proto_minor(kProtoMinor);
  env.set_seq(++seq);
  std::string bytes;
  env.SerializeToString(&bytes);
  try {
    if (!routingId.empty()) {
      if (!socket.send(zmq::buffer(routingId), zmq::send_flags::sndmore | zmq::send_flags::dontwait)) return false;
    }
    auto more = payload ? zmq::send_flags::sndmore : zmq::send_flags::none;
    if (!socket.send(zmq::buffer(bytes), more | zmq::send_flags::dontwait)) return false;
    if (payload && !socket.send(zmq::buffer(*payload), zmq::send_flags::dontwait)) return false;
  } catch (const zmq::error_t&) {
    return false;  // EHOSTUNREACH with router_mandatory: the peer is gone
  }
  return true;
}

}  // namespace frep::farm
