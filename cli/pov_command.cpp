// frep pov: Roerdink's preprocessor (Roerdink-Minkowski §IV.H). A scene text with `$ … <+> … $`
// Minkowski terms is written back with every term replaced by its union of POV primitives; a
// .hf model built from the basic set (fr*Line, fr*Disc, frBall, frBlock, frMinkowski, ...,
// combined by union, intersection and difference) is written as `#declare frep_model = ...;`.
// docs/pov.md.
#include <fstream>
#include <iostream>
#include <sstream>

#include "frep/io/atomic_output.h"
#include "commands.h"
#include "exit_codes.h"
#include "frep/io/input_file.h"
#include "frep/io/pov_scene.h"

namespace frep::cli {
namespace {

bool endsWith(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// A regular file of at most 1 GiB (a FIFO or a device is refused at once, exit 3).
std::string readFile(const std::string& path) { return io::readInputFile(path); }

// file:line:column of the object whose field is `part` (the first operand that is not a
// basic-set term), else of the selected object.
std::string locate(const LoadedModel& m, const std::string& path, const Expr& part) {
  const lang::ObjectInfo* hit = nullptr;
  for (const lang::ObjectInfo& o : m.objects) {
    lang::CompileOptions opt;
    opt.object = o.name;
    lang::CompileResult r = lang::compile(m.source, path, opt);
    if (r.ok && r.model.field.same(part)) {
      hit = &o;
      break;
    }
  }
  std::string name = hit ? hit->name : m.model.objectName;
  int line = hit ? hit->line : 0;
  if (!hit)
    for (const lang::ObjectInfo& o : m.objects)
      if (o.name == m.model.objectName) line = o.line;
  // The column of the object's name on its line.
  int col = 1;
  std::istringstream lines(m.source);
  std::string text;
  for (int i = 1; std::getline(lines, text); ++i)
    if (i == line) {
      std::string lower = text;
      for (char& c : lower) c = char(std::tolower(static_cast<unsigned char>(c)));
      size_t at = lower.find(name);
      if (at != std::string::npos) col = int(at) + 1;
      break;
    }
  return path + ":" + std::to_string(line) + ":" + std::to_string(col) + ": object '" + name + "'" +
         (hit ? "" : " (a part of it)");
}

}  // namespace

int runPov(const PovRequest& req) {
  if (req.out.empty()) throw badArgs("-O/--out: the output file is required");
  if (!(req.thin > 0)) throw badArgs("--thin: must be > 0");
  std::string text;
  if (endsWith(req.input, ".hf")) {
    ModelRequest mr;
    mr.path = req.input;
    mr.object = req.object;
    LoadedModel m = loadModel(mr, true);
    Expr part;
    try {
      text = "// frep pov " + req.input + ": Roerdink-Minkowski reduction, exact (no search)\n#declare frep_model =\n" +
             io::povFromField(m.field, req.thin, &part) + ";\n";
    } catch (const io::PovNonFinite& e) {
      std::cerr << req.input << ": " << e.what() << "\n";
      return kExitModelError;
    } catch (const io::PovError&) {
      std::cerr << locate(m, req.input, part)
                << " is not reducible to POV primitives: it is not a basic-set term (fr*Line, fr*Disc, frBall, "
                   "frBlock, their exact frMinkowski sums, block erosions) nor a union/intersection/difference of "
                   "such; export a POV mesh2 instead: frep mesh "
                << req.input << " -O model.inc\n";
      return kExitModelError;
    }
  } else {
    std::string scene = readFile(req.input);
    try {
      text = io::translateScene(scene, req.input, req.thin);
    } catch (const io::PovError& e) {
      std::cerr << e.what() << "\n";
      return kExitModelError;
    }
  }
  io::AtomicOutput out("-O/--out", req.out);
  {
    std::ofstream f(out.tempPath(), std::ios::binary);
    f << text;
    if (!f.flush()) throw ioError("-O/--out: cannot write '" + req.out + "'");
  }
  out.commit();
  return kExitOk;
}

}  // namespace frep::cli
