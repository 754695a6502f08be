// hfp's command line, `frep model.hf -g 60 -stl out.stl` (no verb), translated to the frep mesh
// command it means: -a -b -g -o -x -i as they are, -wrl/-stl/-stlb/-pov/-cli/-gs/-t to frep
// mesh's --wrl/--stl/--stlb/--pov/--cli/--gs/--timing, hfp's grid default (-g 30) when no grid
// is given, the viewer's display options ignored with a note, frep's own --options passed on.
#pragma once

#include <string>
#include <vector>

namespace frep::cli {

// Whether argv[1] is a model file given without a verb (it ends in .hf, any case).
bool isHfpInvocation(int argc, char** argv);

struct HfpTranslation {
  std::vector<std::string> args;   // "mesh", the model, the translated options
  std::vector<std::string> notes;  // ignored options, said on stderr
  bool help = false;               // -h: print hfpHelp()
};

// Throws CliError(kExitBadArgs) for an unknown single-dash option (with a hint) or a missing value.
HfpTranslation translateHfp(int argc, char** argv);
std::string hfpHelp();

}  // namespace frep::cli
