// Text helpers shared by the subcommands: option values in, numbers and JSON out, help text laid out.
#pragma once

#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "core/result.h"
#include "core/text.h"  // formatNumber, jsonString

namespace dpoint {

// "X,Y,Z"-style option values: between min_count and max_count comma-separated finite numbers.
// The error (kUsage) names the flag and quotes the text.
Result<std::vector<double>> parseNumbers(const std::string& flag, const std::string& text, size_t min_count,
                                         size_t max_count);
inline Result<std::vector<double>> parseNumbers(const std::string& flag, const std::string& text, size_t count) {
  return parseNumbers(flag, text, count, count);
}
Result<glm::dvec3> parseVec3(const std::string& flag, const std::string& text);

// Help text as the subcommands lay it out: words greedily on lines of at most `width` characters
// (a longer word stands alone on its line), joined by '\n', no trailing newline.
inline constexpr size_t kHelpWidth = 102;
std::string wrapText(const std::string& text, size_t width);

}  // namespace dpoint
