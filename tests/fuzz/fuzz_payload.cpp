// Fuzz target: what the farm decodes from the network. The first byte picks the decoder, the rest
// is its input: 0 a brick result's FRB2 payload (decodeBrick), 1 a mesh piece's FRM4 payload
// (decodeMeshPiece, then the master's merge of it), 2 an Envelope frame (wire.cpp's parse) and,
// when it holds a welcome, the job a worker would compute (fuzz_target.h). Oracles: a payload
// that decodes re-encodes to bytes that decode and re-encode to the same bytes (the codec has
// one meaning per payload), scanBrick accepts exactly what decodeBrick accepts and gives the same
// origins and tiles, decodeLeafAt decodes each leaf record it finds to the same leaf, and nothing
// crashes or reads out of bounds.
#include <cstring>
#include <stdexcept>
#include <string>

#include "frep/worker/brick.h"
#include "farm.pb.h"
#include "frep/meshing/mesh.h"
#include "fuzz_target.h"

namespace frep::fuzz {
namespace {

void sampleBrick(const uint8_t* data, size_t size) {
  farm::BrickOutput out;
  std::string err;
  // The master's two other readers of the format: scanBrick (verification: origins, tiles and
  // where each leaf's record starts) accepts exactly what decodeBrick accepts, and decodeLeafAt
  // (the merge, leaf by leaf) decodes each record alone to decodeBrick's leaf.
  std::vector<std::array<int32_t, 3>> origins;
  std::vector<Tile> tiles;
  std::vector<uint32_t> leafAt;
  std::string scanErr;
  const bool scanned = farm::scanBrick(data, size, origins, tiles, leafAt, &scanErr);
  if (!farm::decodeBrick(data, size, out, &err)) {
    FREP_FUZZ_CHECK(!err.empty());
    FREP_FUZZ_CHECK(!scanned && scanErr == err);
    return;
  }
  FREP_FUZZ_CHECK(scanned && origins.size() == out.leaves.size() && leafAt.size() == out.leaves.size() &&
                  tiles.size() == out.tiles.size());
  for (size_t l = 0; l < out.leaves.size(); ++l) {
    const LeafBlock& a = out.leaves[l];
    const size_t end = l + 1 < leafAt.size() ? leafAt[l + 1] : size;
    FREP_FUZZ_CHECK(leafAt[l] < end && end <= size);
    LeafBlock b;
    FREP_FUZZ_CHECK(farm::decodeLeafAt(reinterpret_cast<const char*>(data) + leafAt[l], end - leafAt[l], b));
    FREP_FUZZ_CHECK(a.origin == origins[l] && b.origin == a.origin && b.active == a.active &&
                    std::memcmp(a.values.data(), b.values.data(), sizeof a.values) == 0);
  }
  for (size_t t = 0; t < tiles.size(); ++t)
    FREP_FUZZ_CHECK(tiles[t].origin == out.tiles[t].origin && tiles[t].size == out.tiles[t].size &&
                    tiles[t].inside == out.tiles[t].inside);
  const std::string once = farm::encodeBrick(out);
  farm::BrickOutput again;
  FREP_FUZZ_CHECK(farm::decodeBrick(once.data(), once.size(), again, &err));
  FREP_FUZZ_CHECK(farm::encodeBrick(again) == once);
}

void meshPiece(const uint8_t* data, size_t size) {
  MeshPiece piece;
  std::string err;
  if (!farm::decodeMeshPiece(data, size, piece, &err)) {
    FREP_FUZZ_CHECK(!err.empty());
    return;
  }
  const std::string once = farm::encodeMeshPiece(piece);
  MeshPiece again;
  FREP_FUZZ_CHECK(farm::decodeMeshPiece(once.data(), once.size(), again, &err));
  FREP_FUZZ_CHECK(farm::encodeMeshPiece(again) == once);
  try {
    const Mesh m = mergePieces({piece});
    FREP_FUZZ_CHECK(m.positions.size() == piece.vertices.size());
  } catch (const std::invalid_argument&) {
    // a piece the merge refuses by name
  }
}

void envelope(const uint8_t* data, size_t size) {
  farm::Envelope e;
  if (!e.ParseFromArray(data, int(size))) return;
  if (!e.has_welcome()) return;
  // What a worker does with a welcome: the job must hash to the envelope's id, then it is read.
  const farm::JobSpec& job = e.welcome().job();
  if (farm::jobIdOf(job) != e.job_id()) return;
  try {
    (void)farm::operationOf(job);
    (void)farm::gridOf(job);
  } catch (const std::invalid_argument&) {
  }
}

}  // namespace

void payload(const uint8_t* data, size_t size) {
  if (size == 0) return;
  switch (data[0] % 3) {
    case 0: return sampleBrick(data + 1, size - 1);
    case 1: return meshPiece(data + 1, size - 1);
    default: return envelope(data + 1, size - 1);
  }
}

}  // namespace frep::fuzz

FREP_FUZZ_ENTRY(frep::fuzz::payload)
