// Measurement only: a dpoint binary PLY (x,y,z double, red,green,blue uchar) rewritten as
// vertices only, once in its order and once with its 1024-point groups sorted nearest first for
// the default fit direction (0.6, 0.5, 1).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <numeric>
#include <string>
#include <vector>
int main(int argc, char** argv) {
  if (argc != 4) { std::cerr << "usage: IN ORIG SORTED\n"; return 2; }
  std::ifstream in(argv[1], std::ios::binary);
  std::string line; uint64_t n = 0;
  while (std::getline(in, line)) {
    if (line.rfind("element vertex ", 0) == 0) n = std::stoull(line.substr(15));
    if (line == "end_header") break;
  }
  const size_t row = 27;
  std::vector<char> v(n * row);
  in.read(v.data(), static_cast<std::streamsize>(v.size()));
  if (!in) { std::cerr << "short read\n"; return 1; }
  const double len = std::sqrt(0.36 + 0.25 + 1.0);
  const double d[3] = {0.6 / len, 0.5 / len, 1.0 / len};
  const uint64_t g = 1024, groups = (n + g - 1) / g;
  std::vector<double> key(groups);
  for (uint64_t k = 0; k < groups; ++k) {
    double s = 0; uint64_t c = 0;
    for (uint64_t i = k * g; i < std::min(n, (k + 1) * g); ++i, ++c) {
      double p[3]; std::memcpy(p, &v[i * row], 24);
      s += p[0] * d[0] + p[1] * d[1] + p[2] * d[2];
    }
    key[k] = s / double(c);
  }
  std::vector<uint64_t> order(groups);
  std::iota(order.begin(), order.end(), 0);
  // The last group may be partial: keep it last so every other group stays whole.
  std::stable_sort(order.begin(), order.end() - 1, [&](uint64_t a, uint64_t b) { return key[a] > key[b]; });
  auto header = [&](std::ofstream& o) {
    o << "ply\nformat binary_little_endian 1.0\nelement vertex " << n
      << "\nproperty double x\nproperty double y\nproperty double z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
  };
  std::ofstream a(argv[2], std::ios::binary); header(a); a.write(v.data(), static_cast<std::streamsize>(v.size()));
  std::ofstream b(argv[3], std::ios::binary); header(b);
  for (uint64_t k : order) {
    const uint64_t first = k * g, count = std::min(n, first + g) - first;
    b.write(&v[first * row], static_cast<std::streamsize>(count * row));
  }
  return a && b ? 0 : 1;
}
