// CLI11 validators whose refusal is dpoint's own usage error: "dpoint: error: MESSAGE", exit 1,
// the message naming the flag as the commands' checks always have (main.cpp prints it). CLI11's
// own validators (CLI::Range, CLI::IsMember) word their refusals their own way and add their
// allowed values to --help; these add nothing to --help.
#pragma once

#include <functional>
#include <string>

#include <CLI/CLI.hpp>

#include "core/result.h"

namespace dpoint {

// Thrown by a check() validator; main.cpp reports it as reportError does.
class UsageError : public CLI::ParseError {
 public:
  explicit UsageError(const std::string& message)
      : CLI::ParseError("UsageError", message, static_cast<int>(ExitCode::kUsage)) {}
};

// A validator from `problem`: the empty string accepts the value, anything else is the message.
CLI::Validator check(std::function<std::string(const std::string& value)> problem);
// The same from a Status-returning check (its message; its code is kUsage for every such check).
CLI::Validator checkStatus(std::function<Status(const std::string& value)> problem);
// A Result's error, or ok.
template <typename T>
Status statusOf(const Result<T>& result) {
  return result ? okStatus() : Status(result.error());
}

// One of `allowed`, else "FLAG must be A, B or C, got 'VALUE'", and "; did you mean 'B'?" when
// VALUE is near one of them (cli_suggest.h).
CLI::Validator oneOf(const std::string& flag, std::vector<std::string> allowed);
// An option that takes one of `allowed` (checked by oneOf), the first of them by default.
CLI::Option* addChoiceOption(CLI::App& command, const std::string& flag, std::string& value, const std::string& help,
                             std::vector<std::string> allowed);
// A number CLI11 reads as double in [lo, hi] (or (lo, hi] with `open_low`), else
// "FLAG VALUE: must be in RANGE UNIT" (the value as typed). Text that is no number is
// left to CLI11's conversion.
CLI::Validator numberIn(const std::string& flag, double lo, double hi, bool open_low, const std::string& unit);
// "FLAG VALUE: must be a number above 0" / "…: must be 0 or more", in place of CLI11's
// PositiveNumber and NonNegativeNumber, whose refusal printed the largest double in 309 digits.
CLI::Validator positiveNumber(const std::string& flag);
CLI::Validator nonNegativeNumber(const std::string& flag);
// "FLAG VALUE: must be a whole number from 0 to 18446744073709551615" for a uint64 option, where
// CLI11 wrapped -1 and clamped 2^64 onto 2^64 − 1 (a review finding: five seeds, one set).
CLI::Validator wholeNumber64(const std::string& flag);

}  // namespace dpoint
