// Memory limits for large outputs: estimate before allocating, refuse with a clear message.
#pragma once

#include <cstdint>
#include <string>

#include "core/result.h"

namespace dpoint {

// Half of physical memory: the default for --max-memory.
uint64_t defaultMemoryLimit();

// Parses sizes such as 512M, 8G, 1.5GiB, 1000000 (bytes). Error names the flag and the text.
Result<uint64_t> parseMemorySize(const std::string& flag, const std::string& text);

// kResourceLimit error when `needed` exceeds `limit` (0: the default limit).
Status checkMemory(const std::string& what, uint64_t needed, uint64_t limit);

std::string formatBytes(uint64_t bytes);

}  // namespace dpoint
