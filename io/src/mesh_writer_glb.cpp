// glTF 2.0 binary (.glb) writer through tinygltf (Debian's libtinygltf-dev): one buffer with
// float32 POSITION and NORMAL, float32 COLOR_0 (when the mesh has colours; written as the
// model's values, which glTF reads as linear RGB) and uint32 indices, one mesh primitive
// (triangles, counter-clockwise from outside), one node, one scene. glTF is Y-up: writeMesh
// rotates Z-up models for it unless --up z is asked for (mesh_writer.h).
#include <tiny_gltf.h>

#include <cstring>
#include <fstream>
#include <limits>

#include "byte_sink.h"
#include "mesh_writers.h"

namespace frep::io::detail {

namespace {

// Appends `floats` (count × 3) as a view and an accessor of VEC3 floats; returns the accessor.
int addVec3(tinygltf::Model& g, std::vector<unsigned char>& data, const std::vector<float>& floats, bool bounds) {
  const size_t offset = data.size();
  data.resize(offset + floats.size() * 4);
  std::memcpy(data.data() + offset, floats.data(), floats.size() * 4);
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = offset;
  view.byteLength = floats.size() * 4;
  view.target = TINYGLTF_TARGET_ARRAY_BUFFER;
  g.bufferViews.push_back(view);
  tinygltf::Accessor a;
  a.bufferView = int(g.bufferViews.size()) - 1;
  a.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
  a.count = floats.size() / 3;
  a.type = TINYGLTF_TYPE_VEC3;
  if (bounds) {  // required for POSITION
    a.minValues.assign(3, std::numeric_limits<double>::infinity());
    a.maxValues.assign(3, -std::numeric_limits<double>::infinity());
    for (size_t i = 0; i < floats.size(); ++i) {
      a.minValues[i % 3] = std::min(a.minValues[i % 3], double(floats[i]));
      a.maxValues[i % 3] = std::max(a.maxValues[i % 3], double(floats[i]));
    }
  }
  g.accessors.push_back(a);
  return int(g.accessors.size()) - 1;
}

}  // namespace

void writeGlb(const std::string& path, const Mesh& m, const MeshWriteOptions& options) {
  tinygltf::Model g;
  g.asset.version = "2.0";
  g.asset.generator = "frepfarm";
  std::vector<unsigned char> data;
  tinygltf::Primitive prim;
  prim.mode = TINYGLTF_MODE_TRIANGLES;
  if (!m.positions.empty()) {
    std::vector<float> v;
    v.reserve(m.positions.size() * 3);
    for (const auto& p : m.positions)
      for (double c : p) v.push_back(float(c));
    prim.attributes["POSITION"] = addVec3(g, data, v, true);
    v.clear();
    for (const auto& n : m.normals)
      for (double c : n) v.push_back(float(c));
    prim.attributes["NORMAL"] = addVec3(g, data, v, false);
    if (!m.colours.empty()) {
      v.clear();
      for (const auto& c : m.colours) v.insert(v.end(), c.begin(), c.end());
      prim.attributes["COLOR_0"] = addVec3(g, data, v, false);
    }
    const size_t offset = data.size();
    data.resize(offset + m.triangles.size() * 12);
    unsigned char* out = data.data() + offset;
    for (const auto& t : m.triangles)
      for (uint32_t i : t) {
        for (int k = 0; k < 4; ++k) *out++ = static_cast<unsigned char>((i >> (8 * k)) & 0xff);
      }
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = offset;
    view.byteLength = m.triangles.size() * 12;
    view.target = TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER;
    g.bufferViews.push_back(view);
    tinygltf::Accessor a;
    a.bufferView = int(g.bufferViews.size()) - 1;
    a.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    a.count = m.triangles.size() * 3;
    a.type = TINYGLTF_TYPE_SCALAR;
    g.accessors.push_back(a);
    prim.indices = int(g.accessors.size()) - 1;
  }
  tinygltf::Buffer buffer;
  buffer.data = std::move(data);
  g.buffers.push_back(std::move(buffer));
  tinygltf::Mesh mesh;
  mesh.name = options.name;
  if (!prim.attributes.empty()) mesh.primitives.push_back(prim);
  g.meshes.push_back(mesh);
  tinygltf::Node node;
  node.name = options.name;
  node.mesh = 0;
  if (!options.comment.empty())
    node.extras = tinygltf::Value(tinygltf::Value::Object{{"comment", tinygltf::Value(oneLine(options.comment))}});
  g.nodes.push_back(node);
  tinygltf::Scene scene;
  scene.nodes.push_back(0);
  g.scenes.push_back(scene);
  g.defaultScene = 0;

  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  tinygltf::TinyGLTF writer;
  if (!file || !writer.WriteGltfSceneToStream(&g, file, false, true)) throw ioError("cannot write " + path);
  file.close();
  if (!file) throw ioError("cannot write " + path);
}

}  // namespace frep::io::detail
