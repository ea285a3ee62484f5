#include "cli/cli_suggest.h"

#include <regex>

#include <algorithm>
#include <cctype>

namespace dpoint {
namespace {

std::string withoutDashes(const std::string& word) { return word.substr(std::min(word.find_first_not_of('-'), word.size())); }

std::string listed(const std::vector<std::string>& words) {
  std::string list;
  for (const std::string& w : words) list += (list.empty() ? "" : ", ") + w;
  return list;
}

std::vector<std::string> subcommandNames(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) names.push_back(sub->get_name());
  return names;
}

std::vector<std::string> optionNames(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::Option* option : app.get_options()) {
    for (const std::string& name : option->get_lnames()) names.push_back("--" + name);
    for (const std::string& name : option->get_snames()) names.push_back("-" + name);
  }
  return names;
}

const CLI::App* findSubcommand(const CLI::App& app, const std::string& name) {
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
    if (sub->check_name(name)) return sub;
  return nullptr;
}

// A word that stands where an option would: "-x", "--name" or "--name=value", not a negative number.
bool looksLikeOption(const std::string& word) {
  if (word.size() < 2 || word[0] != '-' || word == "--") return false;
  return !(std::isdigit(static_cast<unsigned char>(word[1])) || word[1] == '.');
}

// What a command is called in messages: "render", "generate mandelbulb".
std::string commandPath(const CLI::App& app) {
  std::string path;
  for (const CLI::App* at = &app; at != nullptr && at->get_parent() != nullptr; at = at->get_parent())
    path = at->get_name() + (path.empty() ? "" : " " + path);
  return path;
}

}  // namespace

size_t editDistance(const std::string& a, const std::string& b) {
  // Rows i-2, i-1 and i of the usual table; d[i][j] the distance of a's first i and b's first j.
  std::vector<size_t> before(b.size() + 1), previous(b.size() + 1), current(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) previous[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    current[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      current[j] = std::min({previous[j] + 1, current[j - 1] + 1, previous[j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        current[j] = std::min(current[j], before[j - 2] + 1);
    }
    before.swap(previous);
    previous.swap(current);
  }
  return previous[b.size()];
}

std::optional<std::string> closestMatch(const std::string& word, const std::vector<std::string>& candidates) {
  const std::string bare = withoutDashes(word);
  std::optional<std::string> best;
  size_t best_distance = 3;
  for (const std::string& candidate : candidates) {
    const size_t d = editDistance(bare, withoutDashes(candidate));
    if (d < best_distance && d < bare.size()) best = candidate, best_distance = d;
  }
  if (best || bare.size() < 3) return best;
  for (const std::string& candidate : candidates)
    if (withoutDashes(candidate).starts_with(bare)) return candidate;
  return std::nullopt;
}

std::string didYouMean(const std::string& word, const std::vector<std::string>& candidates) {
  std::optional<std::string> match = closestMatch(word, candidates);
  return match ? "; did you mean '" + *match + "'?" : std::string();
}

std::optional<std::string> unknownCommandMessage(const CLI::App& app, int argc, const char* const* argv) {
  const CLI::App* at = &app;
  for (int i = 1; i < argc; ++i) {
    const std::string word = argv[i];
    const std::vector<std::string> names = subcommandNames(*at);
    if (names.empty() || word.starts_with("-")) return std::nullopt;
    if (const CLI::App* sub = findSubcommand(*at, word)) {
      at = sub;
      continue;
    }
    const bool top = at == &app;
    return (top ? std::string("unknown command '") : commandPath(*at) + ": unknown kind '") + word + "'" +
           didYouMean(word, names) + " (" + (top ? "commands: " : "kinds: ") + listed(names) + ")";
  }
  return std::nullopt;
}

std::string missingCommandMessage(const CLI::App& app) {
  return "name a command (commands: " + listed(subcommandNames(app)) + ")";
}

std::optional<std::string> unknownOptionMessage(const CLI::App& app, int argc, const char* const* argv) {
  const CLI::App* chosen = &app;
  while (!chosen->get_subcommands().empty()) chosen = chosen->get_subcommands().front();
  for (int i = 1; i < argc; ++i) {
    const std::string word = argv[i];
    if (!looksLikeOption(word)) continue;
    const std::string name = word.substr(0, word.find('='));
    if (chosen->get_option_no_throw(name) != nullptr) continue;
    const std::string path = commandPath(*chosen);
    return (path.empty() ? std::string() : path + ": ") + "unknown option '" + name + "'" +
           didYouMean(name, optionNames(*chosen)) + " (`dpoint " + (path.empty() ? "" : path + " ") +
           "--help` lists them)";
  }
  return std::nullopt;
}

namespace {

// The (sub)command the words name: "render", "generate menger", or "" for dpoint itself.
std::string commandPath(const CLI::App& app, int argc, const char* const* argv) {
  std::string path;
  const CLI::App* at = &app;
  for (int i = 1; i < argc; ++i) {
    const std::string word = argv[i];
    if (word.empty() || word[0] == '-') continue;
    const CLI::App* next = nullptr;
    for (const CLI::App* sub : at->get_subcommands([](const CLI::App*) { return true; }))
      if (sub->get_name() == word) next = sub;
    if (!next) break;
    at = next;
    path += (path.empty() ? "" : " ") + word;
  }
  return path;
}

std::string trimmed(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ' || s.back() == '.')) s.pop_back();
  return s;
}

}  // namespace

std::string usageMessage(const CLI::ParseError& error, const CLI::App& app, int argc, const char* const* argv) {
  const std::string command = commandPath(app, argc, argv);
  const std::string help = " (dpoint " + (command.empty() ? std::string() : command + " ") + "--help)";
  const std::string what = trimmed(error.what());
  std::smatch m;
  // IsMember: "--method: voxl not in {exact,voxel}".
  static const std::regex kNotIn(R"(^(-[-\w]+): (.*) not in \{(.*)\}$)");
  if (std::regex_match(what, m, kNotIn)) {
    std::vector<std::string> allowed;
    std::string list;
    for (size_t start = 0; start <= m[3].str().size();) {
      size_t comma = m[3].str().find(',', start);
      if (comma == std::string::npos) comma = m[3].str().size();
      allowed.push_back(m[3].str().substr(start, comma - start));
      start = comma + 1;
    }
    for (size_t i = 0; i < allowed.size(); ++i) list += (i == 0 ? "" : ", ") + allowed[i];
    return m[1].str() + " " + m[2].str() + ": not one of " + list + didYouMean(m[2].str(), allowed) + help;
  }
  // Range: "--count: Value 1e6 not in range 1 to 1099511627776".
  static const std::regex kRange(R"(^(-[-\w]+): Value (.*) not in range (.*) to (.*)$)");
  if (std::regex_match(what, m, kRange))
    return m[1].str() + " " + m[2].str() + ": must be a number from " + m[3].str() + " to " + m[4].str() + help;
  // Conversion: "Could not convert: --width = -100".
  static const std::regex kConvert(R"(^Could not convert: (-[-\w]+) = (.*)$)");
  if (std::regex_match(what, m, kConvert))
    return m[1].str() + " " + m[2].str() + ": not a valid value for " + m[1].str() + help;
  const std::string prefix = command.empty() ? std::string() : command + ": ";
  // Required: "--output is required", or a positional "tiles is required" (named in capitals, as
  // the usage line shows it).
  static const std::regex kRequired(R"(^(-?[-\w]+) is required$)");
  if (std::regex_match(what, m, kRequired)) {
    std::string name = m[1].str();
    if (name[0] != '-')
      for (char& c : name) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    return prefix + name + " is required" + help;
  }
  // An option given more than once: "--frames: At Most 1 required but received 2".
  static const std::regex kRepeated(R"(^(-[-\w]+): At Most 1 required but received (\d+)$)");
  if (std::regex_match(what, m, kRepeated))
    return m[1].str() + ": given " + m[2].str() + " times; give it once" + help;
  // A check's own message that names its option again: "--tolerance: --tolerance -1: ..." once.
  static const std::regex kTwice(R"(^(-[-\w]+): (\1 .*)$)");
  if (std::regex_match(what, m, kTwice)) return m[2].str();
  // Extra words: "The following argument was not expected: extra" (or "arguments were").
  static const std::regex kExtra(R"(^The following arguments? (?:was|were) not expected: (.*)$)");
  if (std::regex_match(what, m, kExtra)) return prefix + "unexpected argument '" + m[1].str() + "'" + help;
  return what;  // dpoint's own validators' messages (cli_check.h) and shapes not known here
}

}  // namespace dpoint
