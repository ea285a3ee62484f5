// A value of type T read from or written to bytes at any alignment (memcpy, so no aliasing or
// alignment rule is broken), in host order: the file formats' little-endian fields on the
// little-endian hosts dpoint builds for.
#pragma once

#include <cstring>

namespace dpoint {

template <typename T>
T loadUnaligned(const void* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

template <typename T>
void storeUnaligned(void* p, T v) {
  std::memcpy(p, &v, sizeof v);
}

}  // namespace dpoint
