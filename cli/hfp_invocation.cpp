// hfp-style invocation (hfp_invocation.h).
#include "hfp_invocation.h"

#include <cctype>
#include <map>
#include <set>

#include "exit_codes.h"

namespace frep::cli {

namespace {

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

bool isHfpInvocation(int argc, char** argv) {
  if (argc < 2) return false;
  const std::string first = argv[1];
  return first.size() > 3 && first[0] != '-' && lower(first.substr(first.size() - 3)) == ".hf";
}

HfpTranslation translateHfp(int argc, char** argv) {
  // hfp option -> frep mesh option (each takes one value).
  static const std::map<std::string, std::string> renamed = {
      {"-a", "-a"},         {"-b", "-b"},         {"-g", "-g"},       {"-o", "-o"},     {"-x", "-x"},
      {"-i", "-i"},         {"-gs", "--gs"},      {"-wrl", "--wrl"},  {"-stl", "--stl"}, {"-stlb", "--stlb"},
      {"-pov", "--pov"},    {"-cli", "--cli"},    {"-O", "-O"}};
  // hfp's viewer and mesher options that have no meaning for frep: ignored (value, or flag).
  static const std::map<std::string, std::string> ignoredWithValue = {
      {"-d", "display mode of hfp's viewer"},       {"-cf", "face colour of hfp's viewer"},
      {"-cl", "line colour of hfp's viewer"},       {"-w", "window size of hfp's viewer"},
      {"-s", "hfp's vertex search (frep finds every vertex by root finding on the model)"},
      {"-usedc", "hfp's choice of mesher (frep has one: marching tetrahedra, docs/mesh.md)"}};
  static const std::map<std::string, std::string> ignoredFlags = {
      {"-ct", "colours are written whenever the model sets s[] (docs/language.md)"},
      {"-sb", "hfp's viewer option"}, {"-sa", "hfp's viewer option"}, {"-r", "hfp's mesh reduction (frep simplifies adaptively, --tolerance)"}};
  HfpTranslation t;
  t.args = {"mesh", argv[1]};
  bool grid = false, output = false;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "-h" || a == "--help") {
      t.help = true;
      return t;
    }
    if (a == "-t") {
      t.args.push_back("--timing");
      continue;
    }
    if (a.rfind("--", 0) == 0) {  // frep's own options (--workers 2, --res=64, ...) pass on
      static const std::set<std::string> flags = {"--resume", "--json", "--no-progress", "--insecure", "--no-sharp", "--open-rim", "--strict",
                                                  "--timing"};
      t.args.push_back(a);
      if (!flags.count(a) && a.find('=') == std::string::npos && i + 1 < argc) t.args.push_back(argv[++i]);
      grid = grid || a == "--res" || a.rfind("--res=", 0) == 0;
      output = output || a == "--out" || a.rfind("--out=", 0) == 0;
      continue;
    }
    auto needValue = [&](const std::string& what) {
      if (i + 1 >= argc) throw badArgs(a + ": " + what + " needs a value (hfp style: " + a + " VALUE)");
      return std::string(argv[++i]);
    };
    if (auto it = renamed.find(a); it != renamed.end()) {
      const std::string v = needValue("option");
      t.args.push_back(it->second);
      t.args.push_back(v);
      grid = grid || a == "-g";
      output = output || a == "-O" || a == "-wrl" || a == "-stl" || a == "-stlb" || a == "-pov" || a == "-cli";
      continue;
    }
    if (auto it = ignoredWithValue.find(a); it != ignoredWithValue.end()) {
      const std::string v = needValue(it->second);
      t.notes.push_back(a + " " + v + " ignored: " + it->second);
      continue;
    }
    if (auto it = ignoredFlags.find(a); it != ignoredFlags.end()) {
      t.notes.push_back(a + " ignored: " + it->second);
      continue;
    }
    if (!a.empty() && a[0] == '-')
      throw badArgs("unknown hfp option '" + a +
                    "'; hfp's options are -a -b -g -gs -i -o -x -t and the outputs -wrl -stl -stlb -pov -cli "
                    "(viewer options -d -cf -cl -w are ignored); frep's own options are in 'frep mesh --help'");
    throw badArgs("unexpected argument '" + a + "' (hfp style: frep model.hf [-g N] -stl out.stl ...)");
  }
  if (!output)
    throw badArgs("no output: hfp opens its viewer here; frep writes files: give -wrl, -stl, -stlb, -pov or -cli "
                  "FILE (or -O FILE with any mesh extension), e.g. frep " + std::string(argv[1]) + " -stl out.stl");
  if (!grid) {  // hfp's default grid, so the same command gives the same resolution
    t.args.push_back("-g");
    t.args.push_back("30");
  }
  return t;
}

std::string hfpHelp() {
  return "hfp-style invocation: frep MODEL.hf [hfp options] [frep mesh options]\n"
         "  runs 'frep mesh' with hfp's options mapped to it (hfp's default grid -g 30):\n"
         "  -a P1,P2,..      parameters a[1..]\n"
         "  -b B             box: B | min,max | bx,by,bz | xmin,ymin,zmin,xmax,ymax,zmax (default 10)\n"
         "  -g N|Nx,Ny,Nz    grid cells per axis (default 30)\n"
         "  -o NAME          object (default my_model, else the first)\n"
         "  -x X,Y,Z,c..     coordinate mapping\n"
         "  -i ISO           isovalue\n"
         "  -wrl FILE        VRML 2.0 with per-vertex normals and colours\n"
         "  -stl FILE        ASCII STL        -stlb FILE   binary STL\n"
         "  -pov FILE        POV-Ray mesh2 (declares frep_mesh)\n"
         "  -cli FILE        layer slices in the Common Layer Interface format (ASCII)\n"
         "  -gs D|Dxy,Dz|Dx,Dy,Dz   CLI layer thickness: the z step (default one voxel)\n"
         "  -t               timing (frep always prints it)\n"
         "  -ct              accepted: colours are written whenever the model sets s[]\n"
         "  -d -cf -cl -w -s -usedc VALUE, -sb -sa -r   hfp viewer/mesher options: ignored with a note\n"
         "  -O FILE          any other mesh format by extension: .ply .obj .stl .wrl .pov .3mf .glb\n"
         "  --workers N, --up y|z, --tolerance E, ... as in 'frep mesh --help'\n";
}

}  // namespace frep::cli
