// 3MF writer (3D Manufacturing Format, for printing) through lib3mf, Debian's lib3mf-dev (1.8):
// one mesh object in the build, positions in millimetres as given, per-vertex colours as the
// sRGB gradient colours of each triangle's corners (the 3MF materials extension's colour group)
// when the mesh has them.
// The package is a ZIP; lib3mf stamps its entries with a constant date (1980, no clock), so the
// same mesh gives the same bytes (tested).
#include <Model/COM/NMR_DLLInterfaces.h>
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "byte_sink.h"  // oneLine
#include "mesh_writers.h"

namespace frep::io::detail {

namespace {

// Owns a lib3mf instance.
struct Handle {
  NMR::PLib3MFBase* p = nullptr;
  ~Handle() {
    if (p) NMR::lib3mf_release(p);
  }
};

void check(LIB3MFRESULT r, const std::string& path, const char* what) {
  if (r != LIB3MF_OK) throw ioError("cannot write " + path + ": lib3mf " + what + " failed (code " + std::to_string(r) + ")");
}

// A UUID (version-4 layout) from two FNV-1a hashes of the mesh's float positions, its
// triangles and its colours, salted.
std::string uuidOf(const Mesh& m, uint64_t salt) {
  uint64_t h[2] = {1469598103934665603ull ^ salt, 1099511628211ull * (salt + 7)};
  auto mix = [&](const void* data, size_t n) {
    const auto* b = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i)
      for (uint64_t& x : h) x = (x ^ b[i]) * 1099511628211ull + (&x == &h[1]);
  };
  for (const auto& p : m.positions) {
    float f[3] = {float(p[0]), float(p[1]), float(p[2])};
    mix(f, sizeof f);
  }
  for (const auto& t : m.triangles) mix(t.data(), sizeof t);
  for (const auto& c : m.colours) mix(c.data(), sizeof c);
  char s[40];
  std::snprintf(s, sizeof s, "%08x-%04x-4%03x-%04x-%012llx", unsigned(h[0] >> 32), unsigned((h[0] >> 16) & 0xffff),
                unsigned(h[0] & 0xfff), unsigned(0x8000 | ((h[1] >> 48) & 0x3fff)),
                (unsigned long long)(h[1] & 0xffffffffffffull));
  return s;
}

// lib3mf's write and seek callbacks (NMR_ExportStream_Callback.h: nfUint32 (nfByte*, nfUint32,
// void*), nfUint32 (nfUint64, void*); 0 is success) onto a file descriptor: they always succeed and
// keep the first error (errno) instead (see write3mfOrThrow).
struct FileSink {
  int fd = -1;
  int error = 0;
  static unsigned int write(unsigned char* data, unsigned int bytes, void* user) {
    auto* s = static_cast<FileSink*>(user);
    for (size_t done = 0; s->error == 0 && done < bytes;) {
      const ssize_t n = ::write(s->fd, data + done, bytes - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) s->error = n < 0 ? errno : EIO;
      else done += size_t(n);
    }
    return 0;
  }
  static unsigned int seek(unsigned long long position, void* user) {
    auto* s = static_cast<FileSink*>(user);
    if (s->error == 0 && ::lseek(s->fd, off_t(position), SEEK_SET) < 0) s->error = errno;
    return 0;
  }
};

}  // namespace

namespace {
void write3mfOrThrow(const std::string& path, const Mesh& m, const MeshWriteOptions& options) {
  using namespace NMR;
  Handle model, mesh, writer, build;
  check(lib3mf_createmodel(&model.p), path, "createmodel");
  check(lib3mf_model_addmeshobject(model.p, &mesh.p), path, "addmeshobject");
  check(lib3mf_object_setnameutf8(mesh.p, options.name.c_str()), path, "setname");
  std::vector<MODELMESHVERTEX> vertices(m.positions.size());
  for (size_t i = 0; i < m.positions.size(); ++i)
    for (int c = 0; c < 3; ++c) vertices[i].m_fPosition[c] = float(m.positions[i][c]);
  std::vector<MODELMESHTRIANGLE> triangles(m.triangles.size());
  for (size_t i = 0; i < m.triangles.size(); ++i)
    for (int c = 0; c < 3; ++c) triangles[i].m_nIndices[c] = m.triangles[i][c];
  check(lib3mf_meshobject_setgeometry(mesh.p, vertices.data(), DWORD(vertices.size()), triangles.data(),
                                      DWORD(triangles.size())),
        path, "setgeometry");
  if (!m.colours.empty() && !m.triangles.empty()) {
    Handle properties;
    check(lib3mf_meshobject_createpropertyhandler(mesh.p, &properties.p), path, "createpropertyhandler");
    std::vector<MODELMESH_TRIANGLECOLOR_SRGB> colours(m.triangles.size());
    for (size_t i = 0; i < m.triangles.size(); ++i)
      for (int v = 0; v < 3; ++v) {
        const auto& c = m.colours[m.triangles[i][v]];
        colours[i].m_Colors[v] = {channelByte(c[0]), channelByte(c[1]), channelByte(c[2]), 255};
      }
    check(lib3mf_propertyhandler_setgradientcolorarray(properties.p, colours.data()), path, "setgradientcolorarray");
    Handle fallback;  // 3MF requires an object-level default with triangle properties: mid grey
    check(lib3mf_object_createdefaultpropertyhandler(mesh.p, &fallback.p), path, "createdefaultpropertyhandler");
    check(lib3mf_defaultpropertyhandler_setcolorrgb(fallback.p, 128, 128, 128), path, "setcolorrgb");
  }
  // The production extension's UUIDs (random by default) from a hash of the content: the same
  // mesh gives the same file, different meshes different UUIDs.
  const std::string objectId = uuidOf(m, 1), buildId = uuidOf(m, 2), itemId = uuidOf(m, 3);
  check(lib3mf_object_setuuidutf8(mesh.p, objectId.c_str()), path, "setuuid");
  check(lib3mf_model_setbuilduuidutf8(model.p, buildId.c_str()), path, "setbuilduuid");
  check(lib3mf_model_addbuilditem(model.p, mesh.p, nullptr, &build.p), path, "addbuilditem");
  check(lib3mf_builditem_setuuidutf8(build.p, itemId.c_str()), path, "setbuilditemuuid");
  if (!options.comment.empty())
    check(lib3mf_model_addmetadatautf8(model.p, "Description", oneLine(options.comment).c_str()), path, "addmetadata");
  check(lib3mf_model_querywriter(model.p, "3mf", &writer.p), path, "querywriter");
  // Through callbacks, not lib3mf's own file writer: when a write of that one fails (a full disk)
  // lib3mf throws, and throws again from its package writer's destructor while unwinding, which
  // ends the process (std::terminate: exit 134, the temporary left behind). The callbacks never
  // fail: they keep the first error, drop what follows, and the error is thrown here once lib3mf
  // has returned.
  FileSink sink;
  sink.fd = ::open(path.c_str(), O_WRONLY | O_TRUNC | O_NOFOLLOW | O_CLOEXEC);
  if (sink.fd < 0) throw ioError("cannot write " + path + ": " + std::strerror(errno));
  const LIB3MFRESULT r = lib3mf_writer_writetocallback(writer.p, reinterpret_cast<void*>(&FileSink::write),
                                                       reinterpret_cast<void*>(&FileSink::seek), &sink);
  const int closed = ::close(sink.fd);
  if (sink.error == 0 && closed != 0) sink.error = errno;
  if (sink.error != 0) throw ioError("cannot write " + path + ": " + std::strerror(sink.error));
  check(r, path, "writetocallback");
}
}  // namespace

// lib3mf 1.8 lets some of its own C++ exceptions out through its C interface: any that does
// becomes an I/O error (exit 3), so the output's temporary is removed as for any other writer.
void write3mf(const std::string& path, const Mesh& m, const MeshWriteOptions& options) {
  try {
    write3mfOrThrow(path, m, options);
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw ioError("cannot write " + path + ": lib3mf: " + e.what() + " (a full disk?)");
  } catch (...) {
    throw ioError("cannot write " + path + ": lib3mf failed");
  }
}

}  // namespace frep::io::detail
