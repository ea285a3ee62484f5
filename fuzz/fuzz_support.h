// What every fuzz target checks beyond the sanitizers: a reader either returns a consistent point
// set or one clean error line (issue #12: "every finding becomes a regression test that expects a
// clean one-line error"). A broken rule aborts, which libFuzzer reports as a finding.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>

#include "core/point_set.h"
#include "core/result.h"

namespace dpoint::fuzz {

// --max-memory for every target: far under libFuzzer's 2 GB (-rss_limit_mb), so that what the
// readers allow themselves is never an out-of-memory finding, and what they must refuse is
// refused at this limit (exit 4) like a user's --max-memory.
constexpr uint64_t kMaxMemory = uint64_t{512} << 20;

// Readers used by `dpoint convert` get bytes as a file named `name`: only this name may start
// their messages.
inline std::string_view bytesOf(const uint8_t* data, size_t size) {
  return std::string_view(reinterpret_cast<const char*>(data), size);
}

[[noreturn]] inline void broken(const std::string& rule, const std::string& detail) {
  std::fprintf(stderr, "fuzz: broken rule: %s: %s\n", rule.c_str(), detail.c_str());
  std::abort();
}

// One printable line (bytes from the input quoted as \xNN), naming the input, with the exit code of
// bad input or of a resource limit.
inline void checkError(const Error& error, const std::string& name) {
  const std::string& m = error.message;
  if (m.empty()) broken("an error has a message", "empty");
  for (char c : m)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) broken("an error is one printable line", m);
  if (m.rfind(name, 0) != 0) broken("an error names the input first", m);
  if (error.code != ExitCode::kBadInput && error.code != ExitCode::kResourceLimit)
    broken("an error exits 2 or 4", std::to_string(static_cast<int>(error.code)) + ": " + m);
}

// colours: none or one per point; dimensions: one value per point; triangles: whole, and every
// index names a point.
inline void checkPoints(const PointSet& points) {
  if (!points.colors.empty() && points.colors.size() != points.positions.size())
    broken("one colour per point", std::to_string(points.colors.size()) + " for " + std::to_string(points.size()));
  if (points.triangles.size() % 3 != 0) broken("whole triangles", std::to_string(points.triangles.size()));
  for (const Dimension& d : points.dimensions.all())
    if (d.size() != points.size()) broken("one value per point in each dimension", d.name);
  for (uint32_t index : points.triangles)
    if (index >= points.positions.size())
      broken("triangle indices name points", std::to_string(index) + " of " + std::to_string(points.size()));
}

inline void checkOutcome(const Result<PointSet>& result, const std::string& name) {
  if (result) checkPoints(*result);
  else checkError(result.error(), name);
}

// One input read on one thread and on three: the same outcome, positions, colours and error.
inline void checkThreadCountsAgree(const Result<PointSet>& one, const Result<PointSet>& three, const std::string& name) {
  if (one.ok() != three.ok()) broken("the thread count does not change the outcome", name);
  const auto same = [](const auto& a, const auto& b) {
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(a[0])) == 0);
  };
  if (one && !(same(one->positions, three->positions) && same(one->colors, three->colors)))
    broken("the thread count does not change the points", std::to_string(one->size()));
  if (!one && one.error().message != three.error().message)
    broken("the thread count does not change the error", one.error().message + " | " + three.error().message);
}

}  // namespace dpoint::fuzz
