// "Did you mean …" for what a user mistyped: a command, a generate kind, an option or an option's
// value. The words are compared by edit distance (optimal string alignment: insertions, deletions,
// substitutions and swaps of neighbours, each 1), so "rendr", "mandlebulb", "natve" and "--colour"
// each find their word.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace dpoint {

// The edit distance between a and b (optimal string alignment: a swap of two neighbours counts 1).
size_t editDistance(const std::string& a, const std::string& b);
// The candidate `word` most likely stands for: the nearest at distance ≤ 2 (and less than the
// word's length, so a short word is not "corrected" into anything), else the first that starts
// with `word` (3 characters at least, leading dashes not counted). Ties go to the earlier one.
std::optional<std::string> closestMatch(const std::string& word, const std::vector<std::string>& candidates);
// "; did you mean 'X'?" for closestMatch's answer, or "".
std::string didYouMean(const std::string& word, const std::vector<std::string>& candidates);

// Before CLI11 parses: a word where a command or a generate kind belongs that is neither, as one
// line ("unknown command 'rendr'; did you mean 'render'? (commands: …)"); none when the words are
// known (or an option comes first, which CLI11 then reports).
std::optional<std::string> unknownCommandMessage(const CLI::App& app, int argc, const char* const* argv);
// No command at all where one is needed: "name a command (commands: generate, merge, …)".
std::string missingCommandMessage(const CLI::App& app);
// After CLI11 refused extra arguments: the first word of argv that looks like an option and that
// the chosen (sub)command does not have, as one line ("render: unknown option '--colour'; did you
// mean '--color'? (…)"); none when no such word is found.
std::optional<std::string> unknownOptionMessage(const CLI::App& app, int argc, const char* const* argv);

// A usage error CLI11 found, in dpoint's voice (issue #36): "--method voxl: not one of exact,
// voxel; did you mean 'voxel'?", "--count 1e6: must be from 1 to 1099511627776",
// "--width -100: not a valid value", "render: --output is required", each ending "(dpoint CMD
// --help)"; any other text (dpoint's own validators', which are in this voice already) as it is.
std::string usageMessage(const CLI::ParseError& error, const CLI::App& app, int argc, const char* const* argv);

}  // namespace dpoint
