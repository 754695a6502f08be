// Suggestions for mistyped verbs and options; see suggest.h.
#include "suggest.h"

#include <algorithm>

namespace frep::cli {
namespace {

// Optimal string alignment distance: insertions, deletions, substitutions and adjacent swaps.
size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<std::vector<size_t>> d(a.size() + 1, std::vector<size_t>(b.size() + 1));
  for (size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (size_t i = 1; i <= a.size(); ++i)
    for (size_t j = 1; j <= b.size(); ++j) {
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + (a[i - 1] != b[j - 1])});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  return d[a.size()][b.size()];
}

// The long and short names of a verb's options, with their dashes ("--res", "-b").
std::vector<std::string> optionNames(const CLI::App& verb) {
  std::vector<std::string> names;
  for (const CLI::Option* o : verb.get_options()) {
    for (const std::string& n : o->get_lnames()) names.push_back("--" + n);
    for (const std::string& n : o->get_snames()) names.push_back("-" + n);
  }
  return names;
}

}  // namespace

std::string closestName(const std::string& word, const std::vector<std::string>& candidates) {
  const size_t limit = std::min<size_t>(3, std::max<size_t>(1, word.size() / 3));
  std::string best;
  size_t bestDistance = limit + 1;
  for (const std::string& c : candidates) {
    const size_t d = editDistance(word, c);
    if (d < bestDistance) best = c, bestDistance = d;
  }
  return best;
}

std::string parseErrorMessage(const CLI::App& app, const std::string& what, int argc, char** argv) {
  std::vector<std::string> verbs;
  const std::vector<const CLI::App*> subs = app.get_subcommands([](const CLI::App*) { return true; });
  for (const CLI::App* sub : subs) verbs.push_back(sub->get_name());
  std::string list;
  for (size_t i = 0; i < verbs.size(); ++i) list += (i ? i + 1 == verbs.size() ? " and " : ", " : "") + verbs[i];
  if (argc < 2) return what;
  const std::string first = argv[1];
  const CLI::App* verb = nullptr;
  for (const CLI::App* sub : subs)
    if (sub->get_name() == first) verb = sub;
  if (!verb && !first.empty() && first[0] != '-') {
    const std::string guess = closestName(first, verbs);
    return "unknown verb '" + first + "'" + (guess.empty() ? "" : " (did you mean '" + guess + "'?)") +
           "; the verbs are " + list;
  }
  if (!verb) return what;
  // Each argument that looks like an option the verb does not have, with its closest option.
  const std::vector<std::string> names = optionNames(*verb);
  std::string message = what;
  for (int i = 2; i < argc; ++i) {
    std::string arg = argv[i];
    if (arg.size() < 2 || arg[0] != '-' || (arg[1] >= '0' && arg[1] <= '9') || arg[1] == '.') continue;
    arg = arg.substr(0, arg.find('='));
    if (std::find(names.begin(), names.end(), arg) != names.end()) continue;
    const std::string guess = closestName(arg, names);
    message +=
        "\n  " + arg + ": not an option of frep " + first + (guess.empty() ? "" : " (did you mean " + guess + "?)");
  }
  return message;
}

}  // namespace frep::cli
