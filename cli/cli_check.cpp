#include "cli/cli_check.h"

#include <algorithm>
#include <charconv>
#include <cstdint>
#include <string_view>

#include "cli/cli_suggest.h"
#include "core/text.h"

namespace dpoint {

CLI::Validator check(std::function<std::string(const std::string& value)> problem) {
  // Empty description: nothing added to the option's line in --help.
  return CLI::Validator(
      [problem = std::move(problem)](std::string& value) -> std::string {
        const std::string message = problem(value);
        if (!message.empty()) throw UsageError(message);
        return std::string();
      },
      "");
}

CLI::Validator checkStatus(std::function<Status(const std::string& value)> problem) {
  return check([problem = std::move(problem)](const std::string& value) {
    Status status = problem(value);
    return status ? std::string() : status.error().message;
  });
}

CLI::Validator oneOf(const std::string& flag, std::vector<std::string> allowed) {
  std::string list;
  for (size_t i = 0; i < allowed.size(); ++i)
    list += (i == 0 ? "" : i + 1 == allowed.size() ? " or " : ", ") + allowed[i];
  return CLI::Validator(
      [flag, allowed = std::move(allowed), list](std::string& value) -> std::string {
        if (std::find(allowed.begin(), allowed.end(), value) != allowed.end()) return std::string();
        // Another case of exactly one choice is that choice (EDL, Z).
        const std::string folded = lowerAscii(value);
        const auto same = [&](const std::string& a) { return lowerAscii(a) == folded; };
        if (std::count_if(allowed.begin(), allowed.end(), same) == 1) {
          value = *std::find_if(allowed.begin(), allowed.end(), same);
          return std::string();
        }
        throw UsageError(flag + " " + value + ": must be " + list + didYouMean(value, allowed));
      },
      "");
}

CLI::Option* addChoiceOption(CLI::App& command, const std::string& flag, std::string& value, const std::string& help,
                             std::vector<std::string> allowed) {
  const std::string first = allowed.front();
  return command.add_option(flag, value, help)->check(oneOf(flag, std::move(allowed)))->default_val(first);
}

CLI::Validator numberIn(const std::string& flag, double lo, double hi, bool open_low, const std::string& unit) {
  const std::string range = (open_low ? "(" : "[") + formatNumber(lo) + ", " + formatNumber(hi) + "]" +
                            (unit.empty() ? "" : " " + unit);
  return check([flag, lo, hi, open_low, range](const std::string& value) {
    double v = 0.0;
    if (!CLI::detail::lexical_cast(value, v)) return std::string();  // CLI11's conversion error follows
    if ((open_low ? v > lo : v >= lo) && v <= hi) return std::string();
    return flag + " " + value + ": must be in " + range;  // as typed (1e+08 for 100000000 puzzled)
  });
}

CLI::Validator positiveNumber(const std::string& flag) {
  return check([flag](const std::string& value) {
    double v = 0.0;
    if (!CLI::detail::lexical_cast(value, v)) return std::string();  // CLI11's conversion error follows
    return v > 0.0 ? std::string() : flag + " " + value + ": must be a number above 0";
  });
}

CLI::Validator nonNegativeNumber(const std::string& flag) {
  return check([flag](const std::string& value) {
    double v = 0.0;
    if (!CLI::detail::lexical_cast(value, v)) return std::string();  // CLI11's conversion error follows
    return v >= 0.0 ? std::string() : flag + " " + value + ": must be 0 or more";
  });
}

CLI::Validator wholeNumber64(const std::string& flag) {
  return check([flag](const std::string& value) {
    uint64_t v = 0;
    std::string_view digits(value);
    if (!digits.empty() && digits.front() == '+') digits.remove_prefix(1);
    const bool digits_only = !digits.empty() && digits.find_first_not_of("0123456789") == std::string_view::npos;
    const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), v);  // refuses past 2^64 − 1
    return digits_only && error == std::errc() && end == digits.data() + digits.size()
               ? std::string()
               : flag + " " + value + ": must be a whole number from 0 to 18446744073709551615";
  });
}

}  // namespace dpoint
