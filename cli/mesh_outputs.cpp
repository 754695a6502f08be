// frep mesh's output files (mesh_outputs.h).
#include "mesh_outputs.h"

#include <algorithm>
#include <cctype>

#include "arg_parse.h"
#include "exit_codes.h"
#include "frep/io/cli_slices.h"

namespace frep::cli {

namespace {

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool hasCliExtension(const std::string& path) {
  auto dot = path.find_last_of('.');
  return dot != std::string::npos && path.find('/', dot) == std::string::npos && lower(path.substr(dot + 1)) == "cli";
}

MeshOutput resolve(const std::string& field, const std::string& path, const std::string& format) {
  MeshOutput o;
  o.path = path;
  const std::string f = lower(format);
  if (f == "cli" || f == "cli-ascii" || f == "cli-binary" || (f.empty() && hasCliExtension(path))) {
    o.slices = true;
    o.binarySlices = f == "cli-binary";
    return o;
  }
  o.format = f.empty() ? io::meshFormatFromPath(field, path) : io::meshFormatFromName(field, format);
  io::requireMeshWriter(o.format);  // a missing writer module fails now, not after the job
  return o;
}

// -gs: D, Dxy,Dz or Dx,Dy,Dz (hfp); the layer thickness is the z step.
double sliceThickness(const std::string& text, double voxel) {
  if (text.empty()) return voxel;
  std::vector<double> v = parseNumbers("-gs", text, "1, 2 or 3");
  if (v.empty() || v.size() > 3) throw badArgs("-gs: expected D, Dxy,Dz or Dx,Dy,Dz (the z step is the layer thickness), got '" + text + "'");
  if (!(v.back() > 0)) throw badArgs("-gs: the layer thickness must be positive, got " + formatNumber(v.back()));
  return v.back();
}

}  // namespace

std::string MeshOutput::describe() const {
  if (slices) return binarySlices ? "CLI slices, binary" : "CLI slices, ASCII";
  return io::meshFormatName(format);
}

io::UpAxis upAxisOf(const MeshRequest& request) {
  const std::string u = lower(request.up);
  if (u.empty()) return io::UpAxis::Default;
  if (u == "z") return io::UpAxis::Z;
  if (u == "y") return io::UpAxis::Y;
  throw badArgs("--up: expected z or y, got '" + request.up + "'");
}

std::vector<MeshOutput> resolveMeshOutputs(const MeshRequest& request) {
  upAxisOf(request);
  if (!request.sliceStep.empty()) sliceThickness(request.sliceStep, 1.0);
  std::vector<MeshOutput> outputs;
  outputs.push_back(resolve("-O/--out", request.region.out, request.format));
  for (const auto& e : request.extraOutputs) outputs.push_back(resolve("-" + e.format, e.path, e.format));
  for (size_t i = 0; i < outputs.size(); ++i)
    for (size_t j = 0; j < i; ++j)
      if (outputs[i].path == outputs[j].path) throw badArgs("'" + outputs[i].path + "' is given as two outputs");
  return outputs;
}

void openMeshOutputFiles(std::vector<MeshOutput>& outputs) {
  for (auto& o : outputs) o.file = std::make_unique<io::AtomicOutput>("-O/--out", o.path);
}

bool wantsColours(const std::vector<MeshOutput>& outputs) {
  return std::any_of(outputs.begin(), outputs.end(),
                     [](const MeshOutput& o) { return !o.slices && io::formatHoldsColours(o.format); });
}

std::vector<std::string> writeMeshOutputs(std::vector<MeshOutput>& outputs, const Mesh& mesh, const MeshRequest& request,
                                          const std::string& name, const std::string& comment,
                                          const std::array<double, 6>& box, double voxel) {
  std::vector<std::string> lines;
  io::MeshWriteOptions options;
  options.comment = comment;
  options.name = name;
  options.up = upAxisOf(request);
  for (auto& o : outputs) {
    if (o.slices) {
      const double thickness = sliceThickness(request.sliceStep, voxel);
      std::vector<io::SliceLayer> layers = io::sliceMesh(mesh, box[2], box[5], thickness);
      io::CliOptions cli;
      cli.binary = o.binarySlices;
      cli.dimension = box;
      cli.label = name;
      io::writeCli(o.file->tempPath(), layers, cli);
      size_t contours = 0;
      for (const auto& l : layers) contours += l.contours.size();
      lines.push_back("wrote " + o.path + " (" + o.describe() + "): " + std::to_string(layers.size()) + " layers of " +
                      formatNumber(thickness) + ", " + std::to_string(contours) + " contours");
    } else {
      io::writeMesh(o.file->tempPath(), mesh, o.format, options);
      const bool y = io::resolvedUpAxis(o.format, options.up) == io::UpAxis::Y;
      lines.push_back("wrote " + o.path + " (" + o.describe() + (y ? ", Y-up" : "") +
                      (!mesh.colours.empty() && io::formatHoldsColours(o.format) ? ", vertex colours" : "") +
                      "): " + std::to_string(mesh.positions.size()) + " vertices, " +
                      std::to_string(mesh.triangles.size()) + " triangles");
    }
  }
  for (auto& o : outputs) o.file->commit();
  return lines;
}

}  // namespace frep::cli
