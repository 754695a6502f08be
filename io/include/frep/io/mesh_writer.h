// Mesh files. Positions and normals are written as 32-bit floats (text formats print the same
// float values with 9 significant digits, so every format reads back the same numbers); a
// mesh's per-vertex colours (Mesh::colours, red/green/blue in [0, 1]) go into every format that
// can hold them. docs/cli.md lists the formats, docs/mesh.md their details.
//
//   .ply  binary little-endian PLY: x y z nx ny nz [red green blue as uchar]
//   .obj  OBJ: v x y z [r g b] (the common vertex-colour extension: MTL colours only whole
//         materials, not vertices), vn, f v//vn
//   .stl  binary STL with unit facet normals (no colours: STL has no standard for them);
//         StlAscii is the ASCII form (hfp's -stl)
//   .wrl  VRML 2.0 IndexedFaceSet with per-vertex normals [and colours] (hfp's -wrl)
//   .inc/.pov  POV-Ray mesh2 declared as frep_mesh [with a texture per vertex] (hfp's -pov)
//   .3mf  3D Manufacturing Format (lib3mf) [per-vertex colours as a colour group]
//   .glb  glTF 2.0 binary (tinygltf): POSITION, NORMAL [, COLOR_0], uint32 indices
#pragma once

#include <string>

#include "frep/meshing/mesh.h"

namespace frep::io {

enum class MeshFormat { Ply, Obj, Stl, StlAscii, Pov, Wrl, ThreeMf, Glb };

// Which axis of the file is "up". Models are Z-up (HyperFun's z, as hfp shows it); glTF is Y-up
// by its specification, so .glb defaults to Y. With Y the file gets (x, z, -y): a rotation
// about the x axis, so orientations and outward normals are kept.
enum class UpAxis { Default, Z, Y };

// From the output file's extension (.ply, .obj, .stl, .wrl, .inc/.pov, .3mf, .glb; any case).
// Throws Error(kExitBadArgs) naming `field`.
MeshFormat meshFormatFromPath(const std::string& field, const std::string& path);
// From a name (--format): ply, obj, stl, stl-ascii, pov, wrl, 3mf, glb. Throws like the above.
MeshFormat meshFormatFromName(const std::string& field, const std::string& name);
const char* meshFormatName(MeshFormat format);
// `#declare name = mesh2 { ... }` of the mesh (the .inc/.pov format's text; frep pov's
// tridiscsphere pieces).
std::string povMesh2(const Mesh& mesh, const std::string& name);
bool formatHoldsColours(MeshFormat format);
// The up axis a format gets for UpAxis::Default: Y for .glb, Z for the others.
UpAxis resolvedUpAxis(MeshFormat format, UpAxis up);

struct MeshWriteOptions {
  std::string comment;  // into the header (PLY/OBJ/VRML/POV comments, the STL header, glTF asset extras)
  std::string name = "frep_mesh";  // object name (VRML DEF, STL solid, 3MF object, glTF node)
  UpAxis up = UpAxis::Default;
};

// Loads now what writing `format` needs (frep loads the 3MF and glTF writers on demand,
// frep/io/program_module.h), so that a broken install fails before a job, not after it.
// Throws Error(kExitInternal) naming the paths tried.
void requireMeshWriter(MeshFormat format);
// Writes `mesh` to `path` (the caller's temporary file). Throws Error(kExitIoError).
void writeMesh(const std::string& path, const Mesh& mesh, MeshFormat format, const MeshWriteOptions& options);
inline void writeMesh(const std::string& path, const Mesh& mesh, MeshFormat format, const std::string& comment) {
  MeshWriteOptions o;
  o.comment = comment;
  writeMesh(path, mesh, format, o);
}

}  // namespace frep::io
