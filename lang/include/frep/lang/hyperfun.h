// HyperFun front end: source text -> checked, lowered models (core expressions).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "frep/expressions/expr.h"

namespace frep::lang {

struct Diagnostic {
  enum class Severity { Error, Warning, Note } severity = Severity::Error;
  std::string file;
  int line = 0, column = 0;  // 1-based; 0 when not tied to a place
  std::string message;
  std::string sourceLine;    // the line's text, for the caret display
  // "file:line:column: error: message\n  <line>\n  ^"
  std::string format() const;
};

struct ObjectInfo {
  std::string name;  // lower-cased, as HyperFun compares names
  int xSize = 0, aSize = 0, sSize = 0;
  int line = 0;
};

struct Model {
  std::string objectName;  // the selected object
  int xSize = 0;           // dimension n of x[n]
  int aSize = 0;           // size of a[m]
  Expr field;              // f(x, a) with x as Expr::x(i), a as Expr::param(i) (0-based)
  // The attribute array s[1..k] at the end of the object's body, over the same x and a
  // (docs/language.md, "Attributes"): s[1..3] is the colour (red, green, blue in [0, 1], as
  // hfp writes it). hasAttributes: the object writes s (an assignment or an hfA_* call).
  std::vector<Expr> attributes;
  bool hasAttributes = false;
  uint64_t sourceHash = 0; // hash of the source text (metadata, caches)
};

struct CompileResult {
  std::vector<Diagnostic> diagnostics;  // errors and warnings in source order
  std::vector<ObjectInfo> objects;      // every object in the file
  bool ok = false;                      // no errors and a model was selected
  Model model;
  // Files the model read, by the path as written, in first-read order (for farm jobs).
  std::vector<std::pair<std::string, std::string>> files;
};

struct CompileOptions {
  std::string object;  // object to select: this name, else "my_model", else the first
  // Loop unrolling limit: total loop iterations per object before "loop does not terminate".
  long maxLoopIterations = 1000000;
  // Values of a[1..]: when given, a[i] is that constant at compile time (so loop conditions and
  // indices may depend on it) instead of Expr::param(i). Missing entries stay parameters.
  std::vector<double> params;
  // Contents of files the model reads (frVolumeSplineFile, frMesh, frVolume), by the path as
  // written in the model: used instead of the disk (farm workers get them with the job).
  std::map<std::string, std::string> files;
  // Where a file the model names that is not in `files` may come from (docs/farm.md, "Models
  // that read files"): Local, the disk relative to the model (frep on the user's own machine);
  // JobOnly, nowhere (a farm worker: the job ships every file, and a master must not make a
  // worker read its own files); DataDir, regular files inside `dataDir` only (frep-worker
  // --data-dir). Every file read from the disk is a regular file of at most maxFileBytes,
  // checked before anything is allocated; a FIFO or a device is refused, never waited on.
  enum class FileAccess { Local, JobOnly, DataDir };
  FileAccess fileAccess = FileAccess::Local;
  std::string dataDir;
  uint64_t maxFileBytes = uint64_t(1) << 30;
};

// Reads a model's file from the disk under `options`' policy (the rule above): `written` is the
// path as the model writes it, `modelFile` the model's own path (relative paths are relative to
// its directory for Local). Throws std::runtime_error with a message that names the path and
// never quotes the file's bytes.
std::string readModelFileFromDisk(const std::string& written, const std::string& modelFile,
                                  const CompileOptions& options);

// Reads a regular file of at most maxBytes bytes: opened without blocking (a FIFO never parks
// the caller), refused unless it is a regular file (devices, FIFOs, directories), its size
// checked before the buffer is allocated; noFollow: a symbolic link as the last component is
// refused. Throws std::runtime_error naming `path`.
std::string readRegularFile(const std::string& path, uint64_t maxBytes, bool noFollow = false);

CompileResult compile(const std::string& source, const std::string& fileName,
                      const CompileOptions& options = {});
CompileResult compileFile(const std::string& path, const CompileOptions& options = {});

}  // namespace frep::lang
