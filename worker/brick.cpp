#include "brick.h"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "frep/lang/field.h"
#include "frep/lang/hyperfun.h"

namespace frep::farm {

GridSpec gridOf(const JobSpec& job) {
  if (job.origin_size() != 3 || job.dims_size() != 3)
    throw std::invalid_argument("job: origin and dims need 3 values each");
  GridSpec g;
  for (int a = 0; a < 3; ++a) {
    g.origin[a] = job.origin(a);
    g.dims[a] = job.dims(a);
  }
  g.voxel = job.voxel();
  return g;
}

uint64_t jobIdOf(const JobSpec& job) {
  std::string bytes;
  job.SerializeToString(&bytes);  // deterministic for a given message (no maps in JobSpec)
  uint64_t h = 1469598103934665603ULL;
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 1099511628211ULL;
  }
  return h;
}

TapePtr compileJobModel(const JobSpec& job) {
  lang::CompileOptions opt;
  opt.object = job.object();
  lang::CompileResult r = lang::compile(job.model_source(), job.model_name(), opt);
  if (!r.ok) {
    std::string msg;
    for (auto& d : r.diagnostics)
      if (d.severity == lang::Diagnostic::Severity::Error) msg += d.format() + "\n";
    throw std::runtime_error(msg.empty() ? "model does not compile" : msg);
  }
  lang::FieldSpec spec;
  spec.params.assign(job.params().begin(), job.params().end());
  spec.iso = job.iso();
  spec.axis.assign(job.map_axis().begin(), job.map_axis().end());
  spec.constant.assign(job.map_constant().begin(), job.map_constant().end());
  Expr f = lang::fieldOf(r.model, spec);
  const uint32_t dims = spec.axis.empty() ? uint32_t(r.model.xSize) : 3u;
  if (frep::numVars(f) > 3)
    throw std::runtime_error("the field has " + std::to_string(frep::numVars(f)) +
                             " coordinates: map x[4..] to constants (-x)");
  return Tape::compile(f, std::min(dims, 3u));
}

TapePtr ModelCache::get(const JobSpec& job, uint64_t jobId) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = tapes_.find(jobId);
  if (it != tapes_.end()) return it->second;
  TapePtr t = compileJobModel(job);
  tapes_[jobId] = t;
  return t;
}

BrickOutput computeBrick(const TapePtr& tape, const JobSpec& job, const std::array<int32_t, 3>& lo,
                         const std::array<int32_t, 3>& hi, int threads) {
  SampleOptions opt;
  opt.bandVoxels = job.band();
  opt.regionLo = lo;
  opt.regionHi = hi;
  opt.threads = threads;
  SampleResult r = sample(tape, gridOf(job), opt);
  return BrickOutput{std::move(r.leaves), std::move(r.tiles), r.stats};
}

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
  return true;
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

bool decodeBrick(const void* data, size_t size, BrickOutput& out, std::string* error) {
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
  out.tiles.resize(nt);
  for (Tile& t : out.tiles) {
    int32_t inside = 0;
    if (!r.get(t.origin[0]) || !r.get(t.origin[1]) || !r.get(t.origin[2]) || !r.get(t.size) || !r.get(inside))
      return fail("payload: truncated tile");
    if (t.size < kLeafDim || (t.size & (t.size - 1)) != 0) return fail("payload: bad tile size");
    t.inside = inside != 0;
  }
  out.leaves.resize(nl);
  for (LeafBlock& l : out.leaves) {
    uint32_t flags = 0;
    if (!r.get(l.origin[0]) || !r.get(l.origin[1]) || !r.get(l.origin[2]) || !r.get(flags) ||
        !r.bytes(l.active.data(), sizeof l.active))
      return fail("payload: truncated leaf");
    if ((l.origin[0] | l.origin[1] | l.origin[2]) & 7) return fail("payload: leaf origin not a multiple of 8");
    if (flags & ~kCompact) return fail("payload: unknown leaf flags");
    if (!(flags & kCompact)) {
      if (!r.bytes(l.values.data(), sizeof l.values)) return fail("payload: truncated leaf values");
      continue;
    }
    std::array<uint64_t, kLeafVoxels / 64> positive{};
    float magnitude = 0;
    if (!r.bytes(positive.data(), sizeof positive) || !r.get(magnitude)) return fail("payload: truncated leaf");
    for (int i = 0; i < kLeafVoxels; ++i) {
      if (l.isActive(i)) {
        if (!r.get(l.values[size_t(i)])) return fail("payload: truncated leaf values");
      } else {
        l.values[size_t(i)] = ((positive[size_t(i >> 6)] >> (i & 63)) & 1u) ? magnitude : -magnitude;
      }
    }
  }
  if (r.p != r.end) return fail("payload: trailing bytes");
  return true;
}

uint32_t crc32Of(const void* data, size_t size) {
  uLong c = crc32(0L, Z_NULL, 0);
  const Bytef* p = static_cast<const Bytef*>(data);
  while (size > 0) {
    uInt n = size > (1u << 30) ? (1u << 30) : uInt(size);
    c = crc32(c, p, n);
    p += n;
    size -= n;
  }
  return uint32_t(c);
}

}  // namespace frep::farm
