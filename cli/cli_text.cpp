#include "cli/cli_text.h"

#include <charconv>
#include <cmath>
#include <cstdio>

namespace dpoint {

Result<std::vector<double>> parseNumbers(const std::string& flag, const std::string& text, size_t min_count,
                                         size_t max_count) {
  std::vector<double> values;
  const char* p = text.data();
  const char* end = p + text.size();
  while (true) {
    double v = 0.0;
    while (p < end && *p == ' ') ++p;
    if (p < end && *p == '+') ++p;
    auto r = std::from_chars(p, end, v);
    if (r.ec != std::errc() || !std::isfinite(v)) break;
    values.push_back(v);
    p = r.ptr;
    while (p < end && *p == ' ') ++p;
    if (p == end) {
      if (values.size() >= min_count && values.size() <= max_count) return values;
      break;
    }
    if (*p != ',') break;
    ++p;
  }
  if (min_count == 1 && max_count == 1) return Error{flag + " " + text + ": must be a finite number", ExitCode::kUsage};
  std::string count = min_count == max_count ? std::to_string(min_count)
                                             : std::to_string(min_count) + " to " + std::to_string(max_count);
  return Error{flag + " " + text + ": must be " + count + " comma-separated finite numbers", ExitCode::kUsage};
}

Result<glm::dvec3> parseVec3(const std::string& flag, const std::string& text) {
  Result<std::vector<double>> v = parseNumbers(flag, text, 3);
  if (!v) return v.error();
  return glm::dvec3((*v)[0], (*v)[1], (*v)[2]);
}

std::string wrapText(const std::string& text, size_t width) {
  std::string out, line;
  size_t at = 0;
  while (at < text.size()) {
    const size_t space = text.find(' ', at);
    const std::string word = text.substr(at, space == std::string::npos ? std::string::npos : space - at);
    at = space == std::string::npos ? text.size() : space + 1;
    if (word.empty()) continue;
    if (!line.empty() && line.size() + 1 + word.size() > width) {
      out += line + '\n';
      line.clear();
    }
    line += (line.empty() ? "" : " ") + word;
  }
  return out + line;
}

}  // namespace dpoint
