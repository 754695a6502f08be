// The payload codecs (frep/farm/brick_codec.h): FRB2 samples, FRM4 mesh pieces, FRR1 render
// tiles. Moved from worker/brick.cpp so that the master and the CLI decode results without
// linking the compute side.
#include "frep/farm/brick_codec.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "frep/farm/leaf_expand.h"

namespace frep::farm {

namespace {
uint64_t meshPointEvals(const MeshStats& s) { return s.samplePointEvals + s.rootEvals + s.gradientEvals; }
}  // namespace

namespace {
template <typename T>
void put(std::string& s, const T& v) {
  s.append(reinterpret_cast<const char*>(&v), sizeof v);
}
struct Reader {
  const char* p;
  const char* end;
  template <typename T>
  bool get(T& v) {
    if (size_t(end - p) < sizeof v) return false;
    std::memcpy(&v, p, sizeof v);
    p += sizeof v;
    return true;
  }
  bool bytes(void* dst, size_t n) {
    if (size_t(end - p) < n) return false;
    std::memcpy(dst, p, n);
    p += n;
    return true;
  }
};
constexpr uint32_t kCompact = 1;  // leaf flag: inactive voxels are +-magnitude, only active values sent

// A leaf's inactive voxels all hold +m or -m (the sampler's band value): then only the signs of
// the inactive voxels and the active values travel, about half the bytes of a surface leaf.
bool compactable(const LeafBlock& l, float& magnitude) {
  bool found = false;
  for (int i = 0; i < kLeafVoxels; ++i) {
    if (l.isActive(i)) continue;
    float m = std::fabs(l.values[size_t(i)]);
    if (!found) magnitude = m, found = true;
    else if (m != magnitude) return false;
  }
  if (!found) magnitude = 0;
  // A band of 0 stores the signs as +0 and the negative float nearest 0 (sample.h storedValue):
  // not a +-magnitude pair, so such leaves travel whole.
  return !found || magnitude >= std::numeric_limits<float>::min();
}
}  // namespace

std::string encodeBrick(const BrickOutput& out) {
  std::string s;
  s.reserve(12 + out.tiles.size() * 20 + out.leaves.size() * 1200);
  s.append("FRB2", 4);
  put(s, uint32_t(out.leaves.size()));
  put(s, uint32_t(out.tiles.size()));
  for (const Tile& t : out.tiles) {
    for (int a = 0; a < 3; ++a) put(s, t.origin[a]);
    put(s, t.size);
    put(s, int32_t(t.inside ? 1 : 0));
  }
  for (const LeafBlock& l : out.leaves) {
    for (int a = 0; a < 3; ++a) put(s, l.origin[a]);
    float magnitude = 0;
    const bool compact = compactable(l, magnitude);
    put(s, compact ? kCompact : 0u);
    s.append(reinterpret_cast<const char*>(l.active.data()), sizeof l.active);
    if (!compact) {
      s.append(reinterpret_cast<const char*>(l.values.data()), sizeof l.values);
      continue;
    }
    std::array<uint64_t, kLeafVoxels / 64> positive{};
    for (int i = 0; i < kLeafVoxels; ++i)
      if (!l.isActive(i) && l.values[size_t(i)] > 0) positive[size_t(i >> 6)] |= uint64_t(1) << (i & 63);
    s.append(reinterpret_cast<const char*>(positive.data()), sizeof positive);
    put(s, magnitude);
    for (int i = 0; i < kLeafVoxels; ++i)
      if (l.isActive(i)) put(s, l.values[size_t(i)]);
  }
  return s;
}

namespace {
// One leaf record of an FRB2 payload, at r.p: its origin, mask and values into *l (nullptr: its
// bytes are checked and skipped, not expanded). Returns why it is malformed, or nullptr.
const char* readLeaf(Reader& r, LeafBlock* l, std::array<int32_t, 3>& origin) {
  uint32_t flags = 0;
  std::array<uint64_t, kLeafVoxels / 64> active{};
  if (!r.get(origin[0]) || !r.get(origin[1]) || !r.get(origin[2]) || !r.get(flags) ||
      !r.bytes(active.data(), sizeof active))
    return "payload: truncated leaf";
  if ((origin[0] | origin[1] | origin[2]) & 7) return "payload: leaf origin not a multiple of 8";
  if (flags & ~kCompact) return "payload: unknown leaf flags";
  if (l) l->origin = origin, l->active = active;
  if (!(flags & kCompact)) {
    constexpr size_t kValueBytes = kLeafVoxels * sizeof(float);
    if (size_t(r.end - r.p) < kValueBytes) return "payload: truncated leaf values";
    if (l) std::memcpy(l->values.data(), r.p, kValueBytes);
    r.p += kValueBytes;
    return nullptr;
  }
  std::array<uint64_t, kLeafVoxels / 64> positive{};
  float magnitude = 0;
  if (!r.bytes(positive.data(), sizeof positive) || !r.get(magnitude)) return "payload: truncated leaf";
  const size_t activeCount = countVoxels(active.data());
  if (size_t(r.end - r.p) < activeCount * sizeof(float)) return "payload: truncated leaf values";
  if (!l) {
    r.p += activeCount * sizeof(float);
    return nullptr;
  }
  uint32_t m = 0;
  std::memcpy(&m, &magnitude, sizeof m);
  r.p = expandCompactLeaf(l->values.data(), active.data(), positive.data(), m, r.p);
  return nullptr;
}

// The one FRB2 parser behind decodeBrick and scanBrick (and, leaf by leaf, decodeLeafAt), so
// they accept exactly the same payloads. The sink sizes the output (begin), takes each tile,
// and says where leaf i's values go (leaf: nullptr to check its bytes only, without expanding
// them; it learns where the leaf's record starts).
template <typename Sink>
bool walkBrick(const void* data, size_t size, Sink& sink, std::string* error) {
  auto fail = [&](const char* why) {
    if (error) *error = why;
    return false;
  };
  Reader r{static_cast<const char*>(data), static_cast<const char*>(data) + size};
  if (size < 12 || std::memcmp(data, "FRB2", 4) != 0) return fail("payload: bad magic");
  r.p += 4;
  uint32_t nl = 0, nt = 0;
  r.get(nl);
  r.get(nt);
  // Every leaf takes at least 92 bytes: reject absurd counts before allocating.
  if (uint64_t(nt) * 20 + uint64_t(nl) * 92 > size - 12) return fail("payload: counts exceed its size");
  sink.begin(nl, nt);
  for (uint32_t i = 0; i < nt; ++i) {
    Tile t{};
    int32_t inside = 0;
    if (!r.get(t.origin[0]) || !r.get(t.origin[1]) || !r.get(t.origin[2]) || !r.get(t.size) || !r.get(inside))
      return fail("payload: truncated tile");
    if (t.size < kLeafDim || (t.size & (t.size - 1)) != 0) return fail("payload: bad tile size");
    t.inside = inside != 0;
    sink.tile(i, t);
  }
  for (uint32_t i = 0; i < nl; ++i) {
    const size_t at = size_t(r.p - static_cast<const char*>(data));
    std::array<int32_t, 3> origin{};
    if (const char* why = readLeaf(r, sink.leaf(i, at), origin)) return fail(why);
    sink.origin(i, origin);
  }
  if (r.p != r.end) return fail("payload: trailing bytes");
  return true;
}
}  // namespace

bool decodeBrick(const void* data, size_t size, BrickOutput& out, std::string* error) {
  struct Sink {
    BrickOutput& out;
    void begin(uint32_t nl, uint32_t nt) {
      out.tiles.resize(nt);
      out.leaves.resize(nl);
    }
    void tile(uint32_t i, const Tile& t) { out.tiles[i] = t; }
    LeafBlock* leaf(uint32_t i, size_t) { return &out.leaves[i]; }
    void origin(uint32_t, const std::array<int32_t, 3>&) {}
  } sink{out};
  return walkBrick(data, size, sink, error);
}

bool scanBrick(const void* data, size_t size, std::vector<std::array<int32_t, 3>>& origins, std::vector<Tile>& tiles,
               std::vector<uint32_t>& leafAt, std::string* error) {
  struct Sink {
    std::vector<std::array<int32_t, 3>>& origins;
    std::vector<Tile>& tiles;
    std::vector<uint32_t>& leafAt;
    void begin(uint32_t nl, uint32_t nt) {
      origins.resize(nl);
      tiles.resize(nt);
      leafAt.resize(nl);
    }
    void tile(uint32_t i, const Tile& t) { tiles[i] = t; }
    LeafBlock* leaf(uint32_t i, size_t at) {
      leafAt[i] = uint32_t(at);  // fits: scanBrick refuses payloads of 4 GiB or more
      return nullptr;
    }
    void origin(uint32_t i, const std::array<int32_t, 3>& o) { origins[i] = o; }
  } sink{origins, tiles, leafAt};
  if (size > UINT32_MAX) {
    if (error) *error = "payload: larger than 4 GiB";
    return false;
  }
  return walkBrick(data, size, sink, error);
}

bool decodeLeafAt(const char* record, size_t bytes, LeafBlock& leaf) {
  Reader r{record, record + bytes};
  std::array<int32_t, 3> origin{};
  return !readLeaf(r, &leaf, origin) && r.p == r.end;
}

// ---- mesh pieces ----------------------------------------------------------------------------

namespace {
void putVarint(std::string& s, uint64_t v) {
  while (v >= 0x80) {
    s.push_back(char(uint8_t(v) | 0x80));
    v >>= 7;
  }
  s.push_back(char(uint8_t(v)));
}
uint64_t zigzag(int64_t v) { return (uint64_t(v) << 1) ^ uint64_t(v >> 63); }
int64_t unzigzag(uint64_t v) { return int64_t(v >> 1) ^ -int64_t(v & 1); }
bool getVarint(Reader& r, uint64_t& v) {
  v = 0;
  for (int shift = 0; shift < 70; shift += 7) {
    if (r.p == r.end) return false;
    const uint8_t b = uint8_t(*r.p++);
    if (shift == 63 && b > 1) return false;  // more than 64 bits
    v |= uint64_t(b & 0x7f) << shift;
    if (!(b & 0x80)) return true;
  }
  return false;
}
constexpr size_t kMeshHeader = 4 + 12 + 6 * 8 + 8;
constexpr size_t kMinVertexBytes = 1 + 48;
constexpr size_t kMinTriangleBytes = 3;
}  // namespace

std::string encodeMeshPiece(const MeshPiece& piece) {
  std::string s;
  s.reserve(kMeshHeader + piece.vertices.size() * 51 + piece.triangles.size() * 5);
  s.append("FRM4", 4);
  for (int a = 0; a < 3; ++a) put(s, piece.regionLo[a]);
  const MeshStats& st = piece.stats;
  for (uint64_t v : {st.cellsVisited, st.cellsCrossed, st.rootEvals, st.gradientEvals, st.samplePointEvals,
                     st.fallbackEdges})
    put(s, v);
  put(s, uint32_t(piece.vertices.size()));
  put(s, uint32_t(piece.triangles.size()));
  EdgeKey prev = 0;
  for (size_t i = 0; i < piece.vertices.size(); ++i) {
    const MeshVertex& v = piece.vertices[i];
    putVarint(s, i == 0 ? v.key : v.key - prev);
    prev = v.key;
    for (double c : v.position) put(s, c);
    for (double c : v.normal) put(s, c);
  }
  int64_t first = 0;
  for (const auto& t : piece.triangles) {
    putVarint(s, zigzag(int64_t(t[0]) - first));
    putVarint(s, zigzag(int64_t(t[1]) - int64_t(t[0])));
    putVarint(s, zigzag(int64_t(t[2]) - int64_t(t[0])));
    first = t[0];
  }
  const SimplifyCarry& c = piece.carry;
  const SimplifyCounters& n = c.counters;
  for (uint64_t v : {n.collapses, n.rejectedTopology, n.rejectedShape, n.rejectedError, n.rejectedIntersection, n.modelEvals})
    put(s, v);
  put(s, uint32_t(c.vertices.size()));
  uint32_t prevIndex = 0;
  for (size_t i = 0; i < c.vertices.size(); ++i) {
    const SimplifyCarry::Vertex& v = c.vertices[i];
    putVarint(s, i == 0 ? v.index : v.index - prevIndex);
    prevIndex = v.index;
    for (double q : v.quadric) put(s, q);
    s.push_back(char(v.moved));
    put(s, v.settled);
  }
  s.push_back(char(c.triangles.empty() ? 0 : 1));
  s.append(reinterpret_cast<const char*>(c.triangles.data()), c.triangles.size());
  return s;
}

bool decodeMeshPiece(const void* data, size_t size, MeshPiece& out, std::string* error) {
  auto fail = [&](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (size < kMeshHeader || std::memcmp(data, "FRM4", 4) != 0) return fail("mesh payload: bad magic or header");
  Reader r{static_cast<const char*>(data) + 4, static_cast<const char*>(data) + size};
  for (int a = 0; a < 3; ++a) r.get(out.regionLo[a]);
  if (((out.regionLo[0] | out.regionLo[1] | out.regionLo[2]) & 7) != 0 || out.regionLo[0] < 0 || out.regionLo[1] < 0 ||
      out.regionLo[2] < 0)
    return fail("mesh payload: region origin not a non-negative multiple of 8");
  MeshStats& st = out.stats;
  for (uint64_t* v : {&st.cellsVisited, &st.cellsCrossed, &st.rootEvals, &st.gradientEvals, &st.samplePointEvals,
                      &st.fallbackEdges})
    r.get(*v);
  uint32_t nv = 0, nt = 0;
  r.get(nv);
  r.get(nt);
  // Reject absurd counts before allocating anything.
  if (uint64_t(nv) * kMinVertexBytes + uint64_t(nt) * kMinTriangleBytes > size - kMeshHeader)
    return fail("mesh payload: counts exceed its size");
  out.vertices.resize(nv);
  for (uint32_t i = 0; i < nv; ++i) {
    MeshVertex& v = out.vertices[i];
    uint64_t k = 0;
    if (!getVarint(r, k)) return fail("mesh payload: truncated or overlong vertex key");
    if (i == 0) {
      v.key = k;
    } else {
      if (k == 0 || k > ~uint64_t(0) - out.vertices[i - 1].key) return fail("mesh payload: vertex keys not increasing");
      v.key = out.vertices[i - 1].key + k;
    }
    for (double& c : v.position)
      if (!r.get(c)) return fail("mesh payload: truncated vertex");
    for (double& c : v.normal)
      if (!r.get(c)) return fail("mesh payload: truncated vertex");
    for (int a = 0; a < 3; ++a)
      if (!std::isfinite(v.position[size_t(a)]) || !std::isfinite(v.normal[size_t(a)]))
        return fail("mesh payload: non-finite vertex coordinate");
  }
  out.triangles.resize(nt);
  int64_t first = 0;
  for (auto& t : out.triangles) {
    uint64_t z[3];
    for (uint64_t& x : z)
      if (!getVarint(r, x)) return fail("mesh payload: truncated or overlong triangle");
    // Deltas are bounded before any addition, so nothing overflows.
    const int64_t d0 = unzigzag(z[0]), d1 = unzigzag(z[1]), d2 = unzigzag(z[2]), n = int64_t(nv);
    if (d0 <= -n || d0 >= n || d1 <= -n || d1 >= n || d2 <= -n || d2 >= n)
      return fail("mesh payload: triangle index out of range");
    const int64_t a = first + d0, b = a + d1, c = a + d2;
    if (a < 0 || a >= n || b < 0 || b >= n || c < 0 || c >= n) return fail("mesh payload: triangle index out of range");
    if (a == b || b == c || a == c) return fail("mesh payload: degenerate triangle");
    t = {uint32_t(a), uint32_t(b), uint32_t(c)};
    first = a;
  }
  // The simplifier's carry (simplifyRegion): counters, carried vertices, triangle states.
  SimplifyCarry& c = out.carry;
  c = SimplifyCarry();
  SimplifyCounters& n = c.counters;
  for (uint64_t* v : {&n.collapses, &n.rejectedTopology, &n.rejectedShape, &n.rejectedError, &n.rejectedIntersection,
                      &n.modelEvals})
    if (!r.get(*v)) return fail("mesh payload: truncated simplifier counters");
  uint32_t ncv = 0;
  if (!r.get(ncv)) return fail("mesh payload: truncated simplifier state");
  if (uint64_t(ncv) * (1 + 88 + 1 + 4) > size_t(r.end - r.p)) return fail("mesh payload: carried vertices exceed its size");
  c.vertices.resize(ncv);
  for (uint32_t i = 0; i < ncv; ++i) {
    SimplifyCarry::Vertex& v = c.vertices[i];
    uint64_t k = 0;
    if (!getVarint(r, k)) return fail("mesh payload: truncated carried vertex");
    if (i > 0 && k == 0) return fail("mesh payload: carried vertices not increasing");
    const uint64_t index = i == 0 ? k : uint64_t(c.vertices[i - 1].index) + k;
    if (index >= nv) return fail("mesh payload: carried vertex index out of range");
    v.index = uint32_t(index);
    for (double& q : v.quadric)
      if (!r.get(q) || !std::isfinite(q)) return fail("mesh payload: truncated or non-finite quadric");
    uint8_t moved = 0;
    if (!r.get(moved) || moved > 1) return fail("mesh payload: bad carried vertex flag");
    v.moved = moved;
    if (!r.get(v.settled)) return fail("mesh payload: truncated carried vertex");
  }
  uint8_t hasStates = 0;
  if (!r.get(hasStates) || hasStates > 1) return fail("mesh payload: bad triangle-state flag");
  if (hasStates) {
    if (size_t(r.end - r.p) < nt) return fail("mesh payload: truncated triangle states");
    c.triangles.assign(reinterpret_cast<const uint8_t*>(r.p), reinterpret_cast<const uint8_t*>(r.p) + nt);
    r.p += nt;
    for (uint8_t st : c.triangles)
      if ((st & 0x7f) > 16) return fail("mesh payload: triangle error level out of range");
  }
  if (r.p != r.end) return fail("mesh payload: trailing bytes");
  return true;
}

// ---- render tiles ---------------------------------------------------------------------------

namespace {
constexpr size_t kRenderHeader = 4 + 6 * 4;
constexpr size_t kHitBytes = 1 + 7 * 8;
}  // namespace

std::string encodeRenderTile(const BrickOutput& out) {
  std::string s;
  size_t hitCount = 0;
  for (const RayHit& h : out.hits) hitCount += h.kind != RayHit::kNone;
  s.reserve(kRenderHeader + out.hits.size() + hitCount * (kHitBytes - 1));
  s.append("FRR1", 4);
  for (int a = 0; a < 3; ++a) put(s, out.tileLo[size_t(a)]);
  for (int a = 0; a < 3; ++a) put(s, out.tileHi[size_t(a)]);
  for (const RayHit& h : out.hits) {
    s.push_back(char(h.kind));
    if (h.kind == RayHit::kNone) continue;
    put(s, h.depth);
    for (double c : h.point) put(s, c);
    for (double c : h.normal) put(s, c);
  }
  return s;
}

bool decodeRenderTile(const void* data, size_t size, BrickOutput& out, std::string* error) {
  auto fail = [&](const char* why) {
    if (error) *error = why;
    return false;
  };
  if (size < kRenderHeader || std::memcmp(data, "FRR1", 4) != 0) return fail("render payload: bad magic or header");
  Reader r{static_cast<const char*>(data) + 4, static_cast<const char*>(data) + size};
  for (int a = 0; a < 3; ++a) r.get(out.tileLo[size_t(a)]);
  for (int a = 0; a < 3; ++a) r.get(out.tileHi[size_t(a)]);
  uint64_t pixels = 1;
  for (int a = 0; a < 2; ++a) {
    if (out.tileLo[size_t(a)] < 0 || out.tileHi[size_t(a)] <= out.tileLo[size_t(a)]) return fail("render payload: bad region");
    pixels *= uint64_t(out.tileHi[size_t(a)] - out.tileLo[size_t(a)]);
  }
  if (pixels > size - kRenderHeader) return fail("render payload: region exceeds its size");  // a byte per pixel at least
  out.hits.assign(size_t(pixels), RayHit{});
  for (RayHit& h : out.hits) {
    uint8_t kind = 0;
    if (!r.get(kind)) return fail("render payload: truncated");
    if (kind > RayHit::kFootprint) return fail("render payload: unknown hit kind");
    h.kind = RayHit::Kind(kind);
    if (h.kind == RayHit::kNone) continue;
    bool ok = r.get(h.depth);
    for (double& c : h.point) ok = ok && r.get(c);
    for (double& c : h.normal) ok = ok && r.get(c);
    if (!ok) return fail("render payload: truncated hit");
    bool finite = std::isfinite(h.depth);
    for (int a = 0; a < 3; ++a) finite = finite && std::isfinite(h.point[size_t(a)]) && std::isfinite(h.normal[size_t(a)]);
    if (!finite) return fail("render payload: non-finite hit");
  }
  if (r.p != r.end) return fail("render payload: trailing bytes");
  return true;
}

std::string encodePayload(Operation op, const BrickOutput& out) {
  if (op == Operation::Render) return encodeRenderTile(out);
  return op == Operation::Mesh ? encodeMeshPiece(out.piece) : encodeBrick(out);
}

bool decodePayload(Operation op, const void* data, size_t size, BrickOutput& out, std::string* error) {
  if (op == Operation::Sample) return decodeBrick(data, size, out, error);
  if (op == Operation::Render) return decodeRenderTile(data, size, out, error);
  if (!decodeMeshPiece(data, size, out.piece, error)) return false;
  out.stats.pointEvals = meshPointEvals(out.piece.stats);
  return true;
}

}  // namespace frep::farm
