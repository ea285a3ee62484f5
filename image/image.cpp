// PNG output, encoded here on all cores with zlib (level 1, run-length matches only, the Sub
// filter; opaque pictures as RGB): the rows are cut into pieces of a fixed size (about 64 KiB of
// filtered bytes, whatever the thread count, so the file is the same on every machine), each
// deflated on its own and ended with a sync flush, which byte-aligns it and leaves no reference
// into the next, so that the pieces in order are one zlib stream (its Adler-32 combined from
// theirs). libpng, which did the same on one thread, took 23-29 ms of a 1024x768 render's picture
// and 63 ms at 1920x1080. core/atomic_file.h puts the bytes in place, so a failed encode or write
// leaves no file (and no half-written one) behind.
#include "image/image.h"

#include <zlib.h>

#include <algorithm>
#include <cassert>
#include <climits>
#include <cstring>
#include <vector>

#include "core/atomic_file.h"
#include "core/parallel.h"

namespace dpoint {
namespace {

// Filtered bytes a piece holds at most (whole rows, at least one).
constexpr size_t kPieceBytes = size_t{1} << 16;

void appendBigEndian(std::vector<unsigned char>& out, uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back(static_cast<unsigned char>(v >> shift));
}

// A chunk: length, type, data, CRC-32 of type and data.
void appendChunk(std::vector<unsigned char>& out, const char (&type)[5], const unsigned char* data, size_t size) {
  appendBigEndian(out, static_cast<uint32_t>(size));
  const size_t type_at = out.size();
  out.insert(out.end(), type, type + 4);
  if (size) out.insert(out.end(), data, data + size);
  uLong crc = crc32(0L, out.data() + type_at, 4);
  if (size) crc = crc32(crc, data, static_cast<uInt>(size));
  appendBigEndian(out, static_cast<uint32_t>(crc));
}

// Rows [first, last) filtered with Sub (filter byte 1; each byte less the one a pixel before),
// `channels` bytes a pixel (4, or 3 with the alpha dropped).
void filterRows(const Image& image, uint32_t first, uint32_t last, int channels, unsigned char* out) {
  const size_t width = image.width;
  for (uint32_t y = first; y < last; ++y) {
    const uint8_t* in = image.rgba.data() + size_t{y} * width * 4;
    *out++ = 1;
    unsigned char previous[4] = {0, 0, 0, 0};
    for (size_t x = 0; x < width; ++x, in += 4)
      for (int c = 0; c < channels; ++c) {
        *out++ = static_cast<unsigned char>(in[c] - previous[c]);
        previous[c] = in[c];
      }
  }
}

struct Piece {
  std::vector<unsigned char> deflated;
  uLong adler = 1;
  size_t raw_bytes = 0;
  bool ok = false;
};

// The encoded file, or false when zlib reports an error.
bool encodePng(const Image& image, std::vector<unsigned char>& out) {
  // An opaque picture (every render's) is written as RGB: a quarter less to compress.
  bool opaque = true;
  for (size_t i = 3; i < image.rgba.size() && opaque; i += 4) opaque = image.rgba[i] == 255;
  const int channels = opaque ? 3 : 4;
  const size_t row_bytes = 1 + size_t{image.width} * static_cast<size_t>(channels);
  const uint32_t rows_per_piece = static_cast<uint32_t>(std::max<size_t>(1, kPieceBytes / row_bytes));
  const size_t pieces = (image.height + rows_per_piece - 1) / rows_per_piece;
  std::vector<Piece> done(pieces);
  parallelFor(pieces, 0, [&](size_t k, unsigned) {
    const uint32_t first = static_cast<uint32_t>(k * rows_per_piece);
    const uint32_t last = std::min(image.height, first + rows_per_piece);
    Piece& piece = done[k];
    piece.raw_bytes = (last - first) * row_bytes;
    std::vector<unsigned char> raw(piece.raw_bytes);
    filterRows(image, first, last, channels, raw.data());
    piece.adler = adler32(1L, raw.data(), static_cast<uInt>(raw.size()));
    z_stream z{};
    // Raw deflate (no header of its own): the stream's header and checksum are written below.
    if (deflateInit2(&z, 1, Z_DEFLATED, -15, 8, Z_RLE) != Z_OK) return;
    piece.deflated.resize(deflateBound(&z, static_cast<uLong>(raw.size())) + 16);
    z.next_in = raw.data();
    z.avail_in = static_cast<uInt>(raw.size());
    z.next_out = piece.deflated.data();
    z.avail_out = static_cast<uInt>(piece.deflated.size());
    // The last piece ends the stream; every other ends byte-aligned, its blocks not final.
    const int result = deflate(&z, k + 1 == pieces ? Z_FINISH : Z_SYNC_FLUSH);
    piece.ok = (k + 1 == pieces ? result == Z_STREAM_END : result == Z_OK) && z.avail_in == 0;
    piece.deflated.resize(piece.deflated.size() - z.avail_out);
    deflateEnd(&z);
  });
  if (!std::all_of(done.begin(), done.end(), [](const Piece& p) { return p.ok; })) return false;

  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  out.insert(out.end(), kSignature, kSignature + 8);
  unsigned char header[13];
  for (int i = 0; i < 4; ++i) {
    header[i] = static_cast<unsigned char>(image.width >> (24 - 8 * i));
    header[4 + i] = static_cast<unsigned char>(image.height >> (24 - 8 * i));
  }
  header[8] = 8;                 // bits a channel
  header[9] = opaque ? 2 : 6;    // RGB or RGBA
  header[10] = header[11] = header[12] = 0;  // deflate, adaptive filtering, no interlace
  appendChunk(out, "IHDR", header, sizeof header);
  // One IDAT a piece (a decoder reads their data as one stream): the zlib header (deflate, 32 KiB
  // window, the fastest level) before the first, the Adler-32 of all the filtered bytes after the
  // last.
  uLong adler = 1;
  for (size_t k = 0; k < pieces; ++k) {
    Piece& piece = done[k];
    adler = k == 0 ? piece.adler : adler32_combine(adler, piece.adler, static_cast<z_off_t>(piece.raw_bytes));
    if (k == 0) piece.deflated.insert(piece.deflated.begin(), {0x78, 0x01});
    if (k + 1 == pieces)
      for (int shift = 24; shift >= 0; shift -= 8) piece.deflated.push_back(static_cast<unsigned char>(adler >> shift));
    appendChunk(out, "IDAT", piece.deflated.data(), piece.deflated.size());
  }
  appendChunk(out, "IEND", nullptr, 0);
  return true;
}

}  // namespace

Result<std::vector<unsigned char>> pngBytes(const Image& image, const std::string& name) {
  assert(image.rgba.size() == size_t(image.width) * image.height * 4);
  if (image.width == 0 || image.height == 0) {
    return Error{"cannot write '" + name + "': the image is empty (" + std::to_string(image.width) + "x" +
                     std::to_string(image.height) + ")",
                 ExitCode::kUsage};
  }
  // PNG sizes are 31-bit.
  if (image.width > INT_MAX / 4 || image.height > INT_MAX) {
    return Error{"cannot write '" + name + "': " + std::to_string(image.width) + "x" +
                     std::to_string(image.height) + " is too large for PNG encoding",
                 ExitCode::kResourceLimit};
  }
  std::vector<unsigned char> png;
  png.reserve(image.rgba.size() / 4);
  if (!encodePng(image, png)) return Error{"cannot write '" + name + "': PNG encoding failed", ExitCode::kResourceLimit};
  return png;
}

Status writePng(const std::string& path, const Image& image) {
  Result<std::vector<unsigned char>> png = pngBytes(image, path);
  if (!png) return png.error();
  Result<AtomicFile> file = AtomicFile::create(path);
  if (!file) return file.error();
  if (Status status = file->write(png->data(), png->size()); !status) return status;
  return file->commit();
}

size_t countDifferingPixels(const Image& a, const Image& b) {
  assert(a.width == b.width && a.height == b.height);
  assert(a.rgba.size() == size_t(a.width) * a.height * 4 && b.rgba.size() == a.rgba.size());
  size_t differing = 0;
  for (size_t pixel = 0; pixel < a.rgba.size() / 4; ++pixel) {
    if (!std::equal(a.rgba.begin() + static_cast<ptrdiff_t>(pixel * 4),
                    a.rgba.begin() + static_cast<ptrdiff_t>(pixel * 4 + 4),
                    b.rgba.begin() + static_cast<ptrdiff_t>(pixel * 4))) {
      ++differing;
    }
  }
  return differing;
}

DrawnPixels drawnPixels(const Image& image, uint32_t background_rgba8) {
  DrawnPixels d;
  d.pixels = size_t(image.width) * image.height;
  d.min_side = std::min(image.width, image.height);
  d.x0 = image.width, d.y0 = image.height;
  const uint32_t background = background_rgba8 & 0xffffffu;
  for (uint32_t y = 0; y < image.height; ++y) {
    for (uint32_t x = 0; x < image.width; ++x) {
      const uint8_t* p = &image.rgba[4 * (size_t(y) * image.width + x)];
      if ((uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16) == background) continue;
      ++d.count;
      d.x0 = std::min(d.x0, x), d.x1 = std::max(d.x1, x), d.y0 = std::min(d.y0, y), d.y1 = std::max(d.y1, y);
    }
  }
  return d;
}

}  // namespace dpoint
