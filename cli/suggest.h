// "Did you mean" for a mistyped verb or option: the closest known name by edit distance, and the
// message of a command line CLI11 refused, with that suggestion added (docs/cli.md).
#pragma once

#include <CLI/CLI.hpp>

#include <string>
#include <vector>

namespace frep::cli {

// The candidate closest to `word` by Levenshtein distance (adjacent swaps count 1), if it is
// within a third of the word's length (at least 1, at most 3): "" when none is close.
std::string closestName(const std::string& word, const std::vector<std::string>& candidates);

// The message for a command line that did not parse: CLI11's `what`, naming the unknown verb or
// options, each with its closest verb or option of the verb given in argv[1] ("did you mean").
std::string parseErrorMessage(const CLI::App& app, const std::string& what, int argc, char** argv);

}  // namespace frep::cli
