#include "sg/io/gt_formats.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "sg/core/error.hpp"
#include "sg/io/file_kinds.hpp"

namespace sg::io {
namespace {

namespace fs = std::filesystem;

/// The pairs of one folder (find_flow_gt_pairs), appended to `out` in name order.
void find_flow_pairs_in(const fs::path& dir, std::vector<FlowGtPair>& out) {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_regular_file()) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  auto image = [&files](const std::string& stem) -> fs::path {
    for (const auto& f : files)
      if (f.stem().string() == stem && is_image_file(f)) return f;
    return {};
  };
  for (const auto& f : files) {
    if (f.extension() != ".flo") continue;
    const std::string stem = f.stem().string();
    const std::string suffix = "-gt";
    fs::path a, b;
    std::string name = stem;
    if (stem.size() > suffix.size() && stem.compare(stem.size() - 3, 3, suffix) == 0) {
      name = stem.substr(0, stem.size() - 3);
      a = image(name + "-img0");
      b = image(name + "-img1");
    } else {
      a = image(stem + "1");
      b = image(stem + "2");
    }
    if (!a.empty() && !b.empty()) out.push_back({name, a, b, f});
  }
}

constexpr float kFloTag = 202021.25f;
// Larger than any real image; rejects garbage headers before allocating.
constexpr std::int64_t kMaxFloSide = 1 << 16;
constexpr std::int64_t kMaxFloPixels = std::int64_t{1} << 28;

// .flo is little-endian; decode bytes explicitly so the reader does not depend on the host.
std::uint32_t load_le32(const unsigned char* b) {
  return std::uint32_t{b[0]} | (std::uint32_t{b[1]} << 8) | (std::uint32_t{b[2]} << 16) |
         (std::uint32_t{b[3]} << 24);
}

void store_le32(unsigned char* b, std::uint32_t v) {
  b[0] = static_cast<unsigned char>(v & 0xFF);
  b[1] = static_cast<unsigned char>((v >> 8) & 0xFF);
  b[2] = static_cast<unsigned char>((v >> 16) & 0xFF);
  b[3] = static_cast<unsigned char>((v >> 24) & 0xFF);
}

float bits_to_float(std::uint32_t u) {
  float f;
  std::memcpy(&f, &u, sizeof f);
  return f;
}

std::uint32_t float_to_bits(float f) {
  std::uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

std::string describe_type(const cv::Mat& m) {
  const int depth = m.depth();
  const char* d = depth == CV_8U ? "8-bit" : depth == CV_16U ? "16-bit" : "non-integer";
  return std::string(d) + " " + std::to_string(m.channels()) + "-channel";
}

}  // namespace

cv::Mat read_flo(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw core::InputError("cannot open .flo file: " + path.string());
  unsigned char header[12];
  in.read(reinterpret_cast<char*>(header), sizeof header);
  if (in.gcount() < 4 || bits_to_float(load_le32(header)) != kFloTag) {
    throw core::InputError("not a .flo file (bad header): " + path.string());
  }
  if (in.gcount() < static_cast<std::streamsize>(sizeof header)) {
    throw core::InputError("truncated .flo file (header cut short): " + path.string());
  }
  const auto w = static_cast<std::int32_t>(load_le32(header + 4));
  const auto h = static_cast<std::int32_t>(load_le32(header + 8));
  if (w <= 0 || h <= 0 || w > kMaxFloSide || h > kMaxFloSide ||
      std::int64_t{w} * h > kMaxFloPixels) {
    throw core::InputError("absurd .flo dimensions " + std::to_string(w) + "x" +
                           std::to_string(h) + ": " + path.string());
  }
  // Compare with the file's size before allocating: a 20-byte file must not claim (and get) 1.6 GB.
  const std::uintmax_t expected = sizeof header + std::uintmax_t{8} *
                                                      static_cast<std::uint64_t>(w) *
                                                      static_cast<std::uint64_t>(h);
  std::error_code ec;
  const std::uintmax_t actual = std::filesystem::file_size(path, ec);
  if (!ec && actual < expected) {
    throw core::InputError("truncated .flo file (" + std::to_string(w) + "x" + std::to_string(h) +
                           " needs " + std::to_string(expected) + " bytes, the file has " +
                           std::to_string(actual) + "): " + path.string());
  }
  cv::Mat flow(h, w, CV_32FC2);
  const std::size_t row_bytes = static_cast<std::size_t>(w) * 2 * sizeof(float);
  std::vector<unsigned char> row(row_bytes);
  for (int y = 0; y < h; ++y) {
    in.read(reinterpret_cast<char*>(row.data()), static_cast<std::streamsize>(row_bytes));
    if (in.gcount() != static_cast<std::streamsize>(row_bytes)) {
      throw core::InputError("truncated .flo file (" + std::to_string(w) + "x" +
                             std::to_string(h) + " expected, data ends in row " +
                             std::to_string(y) + "): " + path.string());
    }
    auto* out = flow.ptr<float>(y);
    for (int i = 0; i < 2 * w; ++i) out[i] = bits_to_float(load_le32(row.data() + 4 * i));
  }
  return flow;
}

void write_flo(const std::filesystem::path& path, const cv::Mat& flow) {
  if (flow.empty() || flow.type() != CV_32FC2) {
    throw core::InputError("write_flo: flow must be a non-empty CV_32FC2 image: " + path.string());
  }
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw core::InputError("cannot write .flo file: " + path.string());
  unsigned char header[12];
  store_le32(header, float_to_bits(kFloTag));
  store_le32(header + 4, static_cast<std::uint32_t>(flow.cols));
  store_le32(header + 8, static_cast<std::uint32_t>(flow.rows));
  out.write(reinterpret_cast<const char*>(header), sizeof header);
  std::vector<unsigned char> row(static_cast<std::size_t>(flow.cols) * 2 * sizeof(float));
  for (int y = 0; y < flow.rows; ++y) {
    const auto* in = flow.ptr<float>(y);
    for (int i = 0; i < 2 * flow.cols; ++i) store_le32(row.data() + 4 * i, float_to_bits(in[i]));
    out.write(reinterpret_cast<const char*>(row.data()), static_cast<std::streamsize>(row.size()));
  }
  out.flush();
  if (!out) throw core::InputError("cannot write .flo file: " + path.string());
}

cv::Mat read_disparity_png(const std::filesystem::path& path) {
  if (!std::filesystem::is_regular_file(path)) {
    throw core::InputError("disparity PNG not found: " + path.string());
  }
  // cv::imread picks a decoder by content, not by name: without this check a TIFF, EXR or
  // JPEG 2000 file named .png would be decoded (and a 16-bit TIFF accepted as a disparity map).
  {
    static constexpr unsigned char kPngSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    unsigned char head[sizeof kPngSignature] = {};
    std::ifstream in(path, std::ios::binary);
    in.read(reinterpret_cast<char*>(head), sizeof head);
    if (in.gcount() != sizeof head || std::memcmp(head, kPngSignature, sizeof head) != 0) {
      throw core::InputError("not a PNG file (bad signature): " + path.string());
    }
  }
  cv::Mat raw;
  try {
    raw = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception&) {
    raw.release();
  }
  if (raw.empty()) throw core::InputError("cannot decode disparity PNG: " + path.string());
  if (raw.type() != CV_16UC1) {
    throw core::InputError("disparity PNG must be 16-bit single channel, got " +
                           describe_type(raw) + ": " + path.string());
  }
  cv::Mat disparity;
  raw.convertTo(disparity, CV_32F, 1.0 / 256.0);
  return disparity;
}

void write_disparity_png(const std::filesystem::path& path, const cv::Mat& disparity) {
  if (disparity.empty() || disparity.type() != CV_32FC1) {
    throw core::InputError("write_disparity_png: disparity must be a non-empty CV_32F image: " +
                           path.string());
  }
  cv::Mat raw(disparity.size(), CV_16UC1);
  for (int y = 0; y < disparity.rows; ++y) {
    const auto* in = disparity.ptr<float>(y);
    auto* out = raw.ptr<std::uint16_t>(y);
    for (int x = 0; x < disparity.cols; ++x) {
      const float d = in[x];
      if (!std::isfinite(d) || d <= 0.0f) {
        out[x] = 0;
        continue;
      }
      // A known disparity stays known: tiny values map to 1 rather than to "unknown".
      const double v = std::min(65535.0, std::max(1.0, std::round(double{d} * 256.0)));
      out[x] = static_cast<std::uint16_t>(v);
    }
  }
  bool ok = false;
  try {
    ok = cv::imwrite(path.string(), raw);
  } catch (const cv::Exception&) {
    ok = false;
  }
  if (!ok) throw core::InputError("cannot write disparity PNG: " + path.string());
}

std::vector<FlowGtPair> find_flow_gt_pairs(const std::filesystem::path& dir) {
  if (!fs::is_directory(dir))
    throw core::InputError("flow folder " + dir.string() + " does not exist");
  std::vector<FlowGtPair> out;
  find_flow_pairs_in(dir, out);
  std::vector<fs::path> subdirs;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_directory()) subdirs.push_back(e.path());
  std::sort(subdirs.begin(), subdirs.end());
  for (const auto& d : subdirs) find_flow_pairs_in(d, out);
  if (out.empty())
    throw core::InputError("flow folder " + dir.string() +
                           ": no pair found (NAME1/NAME2 + NAME.flo, or ID-img0/ID-img1 + "
                           "ID-gt.flo)");
  return out;
}

}  // namespace sg::io
