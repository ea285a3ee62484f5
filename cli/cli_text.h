// Text helpers shared by the subcommands: option values in, numbers and JSON out.
#pragma once

#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "core/result.h"

namespace dpoint {

// "X,Y,Z"-style option values: between min_count and max_count comma-separated finite numbers.
// The error (kUsage) names the flag and quotes the text.
Result<std::vector<double>> parseNumbers(const std::string& flag, const std::string& text, size_t min_count,
                                         size_t max_count);
inline Result<std::vector<double>> parseNumbers(const std::string& flag, const std::string& text, size_t count) {
  return parseNumbers(flag, text, count, count);
}
Result<glm::dvec3> parseVec3(const std::string& flag, const std::string& text);

// Shortest round-trip text; JSON has no infinity, so non-finite values become null there.
std::string formatNumber(double v, bool json = false);
std::string jsonString(const std::string& s);

}  // namespace dpoint
