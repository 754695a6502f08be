// The registry of callable library functions: HyperFun's hf* library and frepfarm's fr*
// extensions. Each function lowers its call to core expressions at compile time.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "frep/expressions/expr.h"

namespace frep::lang {

// One argument of a call: a scalar expression, an array of per-element expressions, or (signature
// letter 'O') the name of an object defined earlier in the file.
// Array arguments are passed by reference: transformations (hfShift3D, ...) mutate them in
// place and the caller sees the change for the rest of the object (HyperFun semantics).
struct Arg {
  bool isArray = false;
  Expr value;                          // when !isArray
  std::vector<Expr>* array = nullptr;  // when isArray
  std::string name;                    // array (or object) name as written, for messages
  // Object arguments: `value` holds the callee's field over its own coordinates x[0..objectDims)
  // (its a[] bound to the caller's a values, or zeros beyond the caller's a).
  bool isObject = false;
  int objectDims = 0;
  // File arguments (signature letter 'F', a string literal): `name` is the path as written,
  // `file` its contents (read relative to the model file's directory).
  const std::string* file = nullptr;
  // Text arguments (signature letter 'T', a string literal that is not a file: a grid name) are
  // in `name`.
  bool isText = false;
};

// Thrown by a library function on bad arguments (wrong array size, ...). The lowering turns it
// into a diagnostic at the call's (or the argument's, if argIndex >= 0) line and column.
struct LibraryError : std::runtime_error {
  int argIndex;
  LibraryError(const std::string& what, int arg = -1) : std::runtime_error(what), argIndex(arg) {}
};

struct LibraryFunction {
  std::string name;       // canonical spelling, e.g. "hfSphere" (lookup is case-insensitive)
  // One letter per argument: 'A' array, 'S' scalar, 'O' object name, 'F' file name (a string),
  // 'T' text (a string that is not a file, e.g. a grid name), e.g. "AAS"; "*": any arguments
  // (bare array names pass as arrays, earlier objects' names as objects, the first string as a
  // file 'F' and later ones as text 'T', the rest as scalars; the function checks them).
  std::string signature;
  std::string summary;    // one line: formula or effect (docs/language.md, `frep check` help)
  // Returns the call's value: a primitive's field, or 1 for transformations.
  std::function<Expr(std::vector<Arg>& args)> lower;
};

// Geometry read from files (frMesh, frVolume). lang does not link the readers (OpenVDB's headers
// are slow and large): the program installs a loader (frep::io::installGeometryLoader,
// io/geometry_files.h). The file's bytes come from the lowering (the disk relative to the model,
// or CompileOptions::files on a farm worker), so the loader never opens a file itself.
struct FileFieldRequest {
  std::string path;                    // as written in the model (messages)
  const std::string* bytes = nullptr;  // its contents
  std::string kind;                    // "mesh" or "volume"
  std::string grid;                    // volume: the grid's name ("": the file's first float grid)
};
struct LoadedFileField {
  std::shared_ptr<const FieldFunction> field;
  uint64_t fileHash = 0;              // FNV-1a of the bytes (the process cache's key)
  std::vector<std::string> warnings;  // e.g. open edges of a mesh, how its sign is then defined
};
// Throws std::exception (message naming the file) when the file cannot be used.
using FileFieldLoader = std::function<LoadedFileField(const FileFieldRequest&)>;
void setFileFieldLoader(FileFieldLoader loader);
const FileFieldLoader& fileFieldLoader();  // empty when none is installed
// Loads through the installed loader; throws LibraryError(message, argIndex). The loader's
// warnings are queued for the lowering, which reports them at the call (takeFileWarnings).
LoadedFileField loadFileForCall(const std::string& fn, const FileFieldRequest& request, int argIndex);
std::vector<std::string> takeFileWarnings();  // this thread's queued warnings, cleared

// Registration happens at static-init time from each library source file.
void registerLibraryFunction(LibraryFunction fn);
const LibraryFunction* findLibraryFunction(std::string_view name);  // case-insensitive
const std::vector<LibraryFunction>& libraryFunctions();             // sorted by name

// Helper for registration at namespace scope in a .cpp file:
//   static const bool reg = registerAll({ {...}, {...} });
bool registerAll(std::vector<LibraryFunction> fns);

}  // namespace frep::lang
