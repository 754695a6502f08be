// Sending and receiving envelopes over ZeroMQ: [routing id (ROUTER side only)] envelope [payload].
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>
#include <zmq.hpp>

#include "farm.pb.h"

namespace frep::farm {

// Major 2: the job once per connection (Welcome.job), tasks carry its id only. Minors of major 1
// (all kept): 1 "render" jobs (RenderSpec), 2 ModelFile.hash (checked), 3 Hello.holding.
// Minors of major 2: 1 JobSpec.distance_exact (--store sdf-exact computed by the workers).
constexpr uint32_t kProtoMajor = 2;
constexpr uint32_t kProtoMinor = 1;

struct Incoming {
  std::string routingId;  // empty on the DEALER side
  Envelope envelope;
  std::optional<zmq::message_t> payload;
  size_t bytes = 0;        // all frames after the routing id
  bool oversized = false;  // over the caller's limit: dropped unparsed
};

// The most bytes (all frames after the routing id) accepted from a routing id, checked before
// anything is parsed: the master allows an un-welcomed peer only a small hello.
using FrameLimit = std::function<size_t(const std::string& routingId)>;

// Receives one message without blocking. Returns false if none is waiting. Sets *error (and
// returns true with an empty envelope body) when a message arrived but was malformed: wrong
// frame count, unparsable protobuf, over `limit` (then in.oversized, nothing parsed). Never
// throws on bad input.
bool receive(zmq::socket_t& socket, bool router, Incoming& in, std::string* error, const FrameLimit& limit = {});

// Sends an envelope (and optional payload). Returns false when the peer is unreachable.
bool send(zmq::socket_t& socket, const std::string& routingId, Envelope& env, const std::string* payload = nullptr);

}  // namespace frep::farm
