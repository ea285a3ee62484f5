#include "core/tile.h"

#include <cassert>

#include "core/text.h"

namespace dpoint {

Result<TileSpec> parseTileSpec(const std::string& flag, const std::string& text) {
  const size_t slash = text.find('/');
  uint64_t index = 0, count = 0;
  auto error = [&](const std::string& why) { return Error{flag + ": '" + text + "' " + why, ExitCode::kUsage}; };
  if (slash == std::string::npos || !parseDecimalU64(text.substr(0, slash), index) ||
      !parseDecimalU64(text.substr(slash + 1), count))
    return error("is not I/N (tile I of N, counted from 0)");
  if (count == 0 || count > kMaxTiles) return error("asks for N outside 1.." + std::to_string(kMaxTiles));
  if (index >= count) return error("asks for tile " + std::to_string(index) + ", but tiles are 0.." + std::to_string(count - 1));
  return TileSpec{static_cast<uint32_t>(index), static_cast<uint32_t>(count)};
}

TileRange tileRange(uint64_t items, TileSpec tile) {
  assert(tile.index < tile.count);
  // items·I < 2^64 for the sizes here (items < 2^44, N ≤ 2^20); 128-bit keeps it exact anyway.
  using u128 = unsigned __int128;
  return {static_cast<uint64_t>(static_cast<u128>(items) * tile.index / tile.count),
          static_cast<uint64_t>(static_cast<u128>(items) * (tile.index + 1) / tile.count)};
}

uint32_t nextNonEmptyTile(uint64_t items, TileSpec tile) {
  for (uint32_t next = tile.index + 1; next < tile.count; ++next)
    if (!tileRange(items, {next, tile.count}).empty()) return next;
  return tile.count;
}

uint32_t tileOfItem(uint64_t items, uint32_t count, uint64_t item) {
  assert(item < items);
  // The largest I with ⌊I·items/N⌋ ≤ item, found from an estimate and corrected.
  using u128 = unsigned __int128;
  uint64_t guess = static_cast<uint64_t>((static_cast<u128>(item) * count) / items);
  while (guess + 1 < count && tileRange(items, {static_cast<uint32_t>(guess + 1), count}).begin <= item) ++guess;
  while (tileRange(items, {static_cast<uint32_t>(guess), count}).begin > item) --guess;
  return static_cast<uint32_t>(guess);
}

}  // namespace dpoint
