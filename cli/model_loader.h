// Turns a .hf file and the model options (-o, -a, -i, -x) into one field ready to compile:
// parameters bound, the isovalue subtracted and model coordinates mapped to the view's axes.
#pragma once

#include <string>
#include <vector>

#include "frep/expressions/expr.h"
#include "frep/lang/field.h"
#include "frep/lang/hyperfun.h"

namespace frep::cli {

struct ModelRequest {
  std::string path;
  std::string object;   // -o: "" lets the front end choose (my_model, else the first)
  std::string params;   // -a: "" = all parameters 0, as in hfp
  std::string mapping;  // -x: "" = x[1..3] are the axes
  double iso = 0.0;     // -i: the solid is f >= iso
};

struct LoadedModel {
  std::string source;                    // the file's text (sent to farm workers)
  std::vector<std::pair<std::string, std::string>> files;  // files the model read (sent too)
  lang::Model model;                     // as compiled, before binding
  lang::FieldSpec spec;                  // -a, -i and -x as resolved against the model
  std::vector<lang::ObjectInfo> objects;
  Expr field;                            // f - iso over `dims` coordinates, parameters bound
  std::vector<Expr> colour;              // s[1..3] over the same coordinates; empty: no colour
  int dims = 0;
};

// Reads and compiles the file, printing every diagnostic to stderr. Throws CliError: kExitIoError
// (unreadable file), kExitModelError (errors in the model), kExitBadArgs (-a/-x do not fit it).
// With `toView`, coordinates x[4..] are fixed (at 0 unless -x says otherwise) so that at most 3
// remain; without it and without -x the field keeps all the model's coordinates.
LoadedModel loadModel(const ModelRequest& request, bool toView);

// The model options as resolved, for provenance in output files: "object=NAME params=... iso=...
// map=..." (numbers exact, %.17g). The same text however the command was spelt (argv[0], the
// model's path, option order), so files that carry it do not depend on the spelling.
std::string canonicalModel(const LoadedModel& m);

}  // namespace frep::cli
