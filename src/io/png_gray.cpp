#include <libdeflate.h>

#include <cstdlib>
#include <cstring>
#include <memory>
#include <string_view>

#include "sg/io/gray_image.hpp"

namespace sg::io {
namespace {

std::uint32_t big_endian32(const std::uint8_t* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) |
         std::uint32_t{p[3]};
}

/// Chunks that do not change the pixels of a grayscale image as cv::imread decodes it.
bool harmless(std::string_view type) {
  return type == "tEXt" || type == "zTXt" || type == "iTXt" || type == "tIME" || type == "pHYs";
}

/// Undoes the filter of one row (bytes per pixel 1): `row` holds the filtered bytes and
/// receives the pixels; `above` is the previous row's pixels (zeros for the first row).
bool unfilter_row(int filter, std::uint8_t* row, const std::uint8_t* above, int width) {
  switch (filter) {
    case 0:  // None
      return true;
    case 1:  // Sub
      for (int x = 1; x < width; ++x) row[x] = static_cast<std::uint8_t>(row[x] + row[x - 1]);
      return true;
    case 2:  // Up
      for (int x = 0; x < width; ++x) row[x] = static_cast<std::uint8_t>(row[x] + above[x]);
      return true;
    case 3:  // Average
      row[0] = static_cast<std::uint8_t>(row[0] + (above[0] >> 1));
      for (int x = 1; x < width; ++x)
        row[x] = static_cast<std::uint8_t>(row[x] + ((row[x - 1] + above[x]) >> 1));
      return true;
    case 4: {  // Paeth
      row[0] = static_cast<std::uint8_t>(row[0] + above[0]);  // a = c = 0: the predictor is b
      for (int x = 1; x < width; ++x) {
        const int a = row[x - 1], b = above[x], c = above[x - 1];
        const int p = a + b - c;
        const int pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
        const int predictor = (pa <= pb && pa <= pc) ? a : (pb <= pc ? b : c);
        row[x] = static_cast<std::uint8_t>(row[x] + predictor);
      }
      return true;
    }
    default:
      return false;
  }
}

struct DecompressorDeleter {
  void operator()(libdeflate_decompressor* d) const { libdeflate_free_decompressor(d); }
};

}  // namespace

cv::Mat decode_gray8_png(const std::vector<std::uint8_t>& bytes) {
  static constexpr std::uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  const std::size_t size = bytes.size();
  if (size < 8 + 25 || std::memcmp(bytes.data(), kSignature, 8) != 0) return {};
  std::size_t at = 8;
  int width = 0, height = 0;
  std::vector<std::uint8_t> idat;
  bool ended = false;
  for (bool first = true; at + 12 <= size; first = false) {
    const std::uint32_t length = big_endian32(&bytes[at]);
    if (length > size - at - 12) return {};
    const std::uint8_t* type_and_data = &bytes[at + 4];
    const std::string_view type(reinterpret_cast<const char*>(type_and_data), 4);
    const std::uint8_t* data = type_and_data + 4;
    const std::uint32_t crc = big_endian32(data + length);
    if (libdeflate_crc32(0, type_and_data, length + 4) != crc) return {};
    at += 12 + std::size_t{length};
    if (first != (type == "IHDR")) return {};
    if (type == "IHDR") {
      if (length != 13) return {};
      const std::uint32_t w = big_endian32(data), h = big_endian32(data + 4);
      // Bit depth 8, colour type 0 (gray), compression 0, filter method 0, no interlace.
      if (w == 0 || h == 0 || w > 1U << 15 || h > 1U << 15 || data[8] != 8 || data[9] != 0 ||
          data[10] != 0 || data[11] != 0 || data[12] != 0)
        return {};
      width = static_cast<int>(w);
      height = static_cast<int>(h);
    } else if (type == "IDAT") {
      idat.insert(idat.end(), data, data + length);
    } else if (type == "IEND") {
      ended = true;
      break;
    } else if (!harmless(type)) {
      return {};
    }
  }
  if (!ended || idat.empty()) return {};

  const std::size_t stride = static_cast<std::size_t>(width) + 1;  // filter byte + pixels
  std::vector<std::uint8_t> raw(stride * static_cast<std::size_t>(height));
  const std::unique_ptr<libdeflate_decompressor, DecompressorDeleter> inflater(
      libdeflate_alloc_decompressor());
  if (!inflater) return {};
  std::size_t produced = 0;
  if (libdeflate_zlib_decompress(inflater.get(), idat.data(), idat.size(), raw.data(), raw.size(),
                                 &produced) != LIBDEFLATE_SUCCESS ||
      produced != raw.size())
    return {};

  cv::Mat image(height, width, CV_8UC1);
  const std::vector<std::uint8_t> zeros(static_cast<std::size_t>(width), 0);
  for (int y = 0; y < height; ++y) {
    std::uint8_t* filtered = &raw[stride * static_cast<std::size_t>(y)];
    std::uint8_t* row = image.ptr<std::uint8_t>(y);
    std::memcpy(row, filtered + 1, static_cast<std::size_t>(width));
    if (!unfilter_row(filtered[0], row, y > 0 ? image.ptr<std::uint8_t>(y - 1) : zeros.data(),
                      width))
      return {};
  }
  return image;
}

}  // namespace sg::io
