// Geometry files named by models (frMesh, frVolume): the installed loader and the checked load
// (library.h). The bytes arrive with the request: the lowering read them (ObjectLowering::
// readModelFile), from the disk or from a farm job's model_files.
#include <exception>

#include "frep/lang/library/library.h"

namespace frep::lang {
namespace {
FileFieldLoader& loaderSlot() {
  static FileFieldLoader loader;
  return loader;
}
thread_local std::vector<std::string> tWarnings;
}  // namespace

void setFileFieldLoader(FileFieldLoader loader) { loaderSlot() = std::move(loader); }
const FileFieldLoader& fileFieldLoader() { return loaderSlot(); }

std::vector<std::string> takeFileWarnings() {
  std::vector<std::string> w;
  w.swap(tWarnings);
  return w;
}

LoadedFileField loadFileForCall(const std::string& fn, const FileFieldRequest& request, int argIndex) {
  if (!request.bytes) throw LibraryError(fn + ": '" + request.path + "' was not read", argIndex);
  const FileFieldLoader& loader = loaderSlot();
  if (!loader)
    throw LibraryError(fn + ": this program cannot read geometry files (no loader installed) for '" +
                           request.path + "'", argIndex);
  LoadedFileField loaded;
  try {
    loaded = loader(request);
  } catch (const std::exception& e) {
    throw LibraryError(fn + ": " + e.what(), argIndex);
  }
  if (!loaded.field) throw LibraryError(fn + ": '" + request.path + "' gave no field", argIndex);
  for (auto& w : loaded.warnings) tWarnings.push_back(fn + ": " + w);
  return loaded;
}

}  // namespace frep::lang
