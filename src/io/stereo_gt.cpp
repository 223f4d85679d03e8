#include "sg/io/stereo_gt.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <utility>

#include "sg/core/error.hpp"
#include "sg/io/gt_formats.hpp"

namespace sg::io {
namespace fs = std::filesystem;
namespace {

bool little_endian_host() {
  const std::uint16_t one = 1;
  unsigned char b;
  std::memcpy(&b, &one, 1);
  return b == 1;
}

/// `"text"` -> text; false when `word` is not one quoted run of [0-9.].
bool quoted_number_text(const std::string& word, std::string& text) {
  if (word.size() < 3 || word.front() != '"' || word.back() != '"') return false;
  text = word.substr(1, word.size() - 2);
  return text.find_first_not_of("0123456789.") == std::string::npos;
}

/// Scales listed in an OpenCV datasets.xml (lines `name "scale" "unknown"`; other lines are
/// ignored); empty if none. Throws InputError naming the file and line when a scale is not a
/// finite number > 0 (e.g. "." or "1.2.3").
std::map<std::string, double> read_dataset_scales(const fs::path& xml) {
  std::map<std::string, double> out;
  std::ifstream in(xml);
  std::string text;
  for (int line_no = 1; std::getline(in, text); ++line_no) {
    std::istringstream words(text);
    std::string name, scale_word, unknown_word, extra, scale_text, unknown_text;
    if (!(words >> name >> scale_word >> unknown_word) || (words >> extra)) continue;
    if (name.find_first_not_of(
            "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_-") !=
            std::string::npos ||
        !quoted_number_text(scale_word, scale_text) ||
        !quoted_number_text(unknown_word, unknown_text)) {
      continue;
    }
    char* end = nullptr;
    const double scale = std::strtod(scale_text.c_str(), &end);
    if (end != scale_text.c_str() + scale_text.size() || !std::isfinite(scale) || !(scale > 0)) {
      throw core::InputError(xml.string() + ":" + std::to_string(line_no) + ": scale \"" +
                             scale_text + "\" of '" + name + "' is not a number > 0");
    }
    out[name] = scale;
  }
  return out;
}

double scale_for(const fs::path& scene_dir, double fallback) {
  for (const fs::path& xml :
       {scene_dir / "datasets.xml", scene_dir.parent_path() / "datasets.xml"}) {
    if (!fs::exists(xml)) continue;
    const auto scales = read_dataset_scales(xml);
    const auto it = scales.find(scene_dir.filename().string());
    if (it != scales.end()) return it->second;
  }
  return fallback;
}

/// Pairs of one folder (no recursion).
void pairs_in(const fs::path& dir, double scale, std::vector<StereoGtPair>& out) {
  auto has = [&](const char* f) { return fs::exists(dir / f); };
  const std::string name = dir.filename().string();
  if (has("im2.png") && has("im6.png") && has("disp2.png")) {
    out.push_back(
        {name, dir / "im2.png", dir / "im6.png", dir / "disp2.png", scale_for(dir, scale)});
  } else if (has("view1.png") && has("view5.png") && has("disp1.png")) {
    out.push_back(
        {name, dir / "view1.png", dir / "view5.png", dir / "disp1.png", scale_for(dir, scale)});
  } else if (has("im0.png") && has("im1.png") && (has("disp0GT.pfm") || has("disp0.pfm"))) {
    out.push_back({name, dir / "im0.png", dir / "im1.png",
                   dir / (has("disp0GT.pfm") ? "disp0GT.pfm" : "disp0.pfm"), 0});
  }
  // KITTI: the first matching camera and GT folders.
  fs::path left_dir, right_dir, gt_dir;
  for (const char* l : {"image_2", "image_0"})
    if (fs::is_directory(dir / l) && left_dir.empty()) left_dir = dir / l;
  for (const char* r : {"image_3", "image_1"})
    if (fs::is_directory(dir / r) && right_dir.empty()) right_dir = dir / r;
  for (const char* g : {"disp_noc_0", "disp_noc"})
    if (fs::is_directory(dir / g) && gt_dir.empty()) gt_dir = dir / g;
  if (left_dir.empty() || right_dir.empty() || gt_dir.empty()) return;
  for (const auto& e : fs::directory_iterator(gt_dir)) {
    const fs::path file = e.path().filename();
    if (file.extension() != ".png") continue;
    if (fs::exists(left_dir / file) && fs::exists(right_dir / file))
      out.push_back({file.stem().string(), left_dir / file, right_dir / file, e.path(), 0});
  }
}

/// Skips whitespace and '#' comments of a PGM header from `at`; the offset of the next token.
size_t skip_pgm_space(const std::string& bytes, size_t at) {
  while (at < bytes.size()) {
    if (bytes[at] == '#') {
      while (at < bytes.size() && bytes[at] != '\n') ++at;
    } else if (std::isspace(static_cast<unsigned char>(bytes[at]))) {
      ++at;
    } else {
      break;
    }
  }
  return at;
}

/// Reads a decimal header field of at most 6 digits at `at` (after skip_pgm_space); -1 if none.
long pgm_number(const std::string& bytes, size_t& at) {
  at = skip_pgm_space(bytes, at);
  long value = 0;
  int digits = 0;
  while (at < bytes.size() && std::isdigit(static_cast<unsigned char>(bytes[at])) && digits < 7) {
    value = value * 10 + (bytes[at++] - '0');
    ++digits;
  }
  return digits == 0 || digits > 6 ? -1 : value;
}

/// A binary (P5) or ASCII (P2) PGM, parsed here rather than by cv::imread: imread picks its
/// decoder by content, and a file that starts like a PGM can carry another format's mark too
/// ("DICM" at byte 128 sent one to the GDCM decoder, which aborted; found by fuzz_stereo_gt).
/// CV_8U for maxval <= 255, else CV_16U (big-endian samples, as the format says).
cv::Mat read_pgm(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw core::InputError("cannot read GT disparity " + path.string());
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto bad = [&](const std::string& why) {
    return core::InputError(path.string() + ": not a valid PGM image (" + why + ")");
  };
  const bool ascii = bytes.size() >= 2 && bytes[1] == '2';
  size_t at = 2;
  if (at >= bytes.size() || !std::isspace(static_cast<unsigned char>(bytes[at])))
    throw bad("no whitespace after the magic number");
  const long width = pgm_number(bytes, at), height = pgm_number(bytes, at);
  const long maxval = pgm_number(bytes, at);
  if (width < 1 || height < 1 || width > 65536 || height > 65536)
    throw bad("width and height must be whole numbers in 1..65536");
  if (maxval < 1 || maxval > 65535) throw bad("maxval must be in 1..65535");
  if (at >= bytes.size() || !std::isspace(static_cast<unsigned char>(bytes[at])))
    throw bad("no whitespace after maxval");
  ++at;
  const size_t samples = static_cast<size_t>(width) * static_cast<size_t>(height);
  const int sample_bytes = maxval > 255 ? 2 : 1;
  // The header alone must not make us allocate: every sample needs at least one byte.
  const size_t needed = ascii ? 2 * samples - 1 : samples * sample_bytes;
  if (bytes.size() - at < needed) throw bad("truncated: " + std::to_string(samples) + " samples");
  cv::Mat out(static_cast<int>(height), static_cast<int>(width),
              sample_bytes == 2 ? CV_16U : CV_8U);
  for (size_t i = 0; i < samples; ++i) {
    long v = 0;
    if (ascii) {
      v = pgm_number(bytes, at);
      if (v < 0) throw bad("sample " + std::to_string(i) + " is not a number");
    } else if (sample_bytes == 2) {
      v = static_cast<unsigned char>(bytes[at]) << 8 | static_cast<unsigned char>(bytes[at + 1]);
      at += 2;
    } else {
      v = static_cast<unsigned char>(bytes[at++]);
    }
    if (v > maxval) throw bad("sample " + std::to_string(i) + " exceeds maxval");
    const int y = static_cast<int>(i / static_cast<size_t>(width));
    const int x = static_cast<int>(i % static_cast<size_t>(width));
    if (sample_bytes == 2) {
      out.at<std::uint16_t>(y, x) = static_cast<std::uint16_t>(v);
    } else {
      out.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(v);
    }
  }
  return out;
}

/// A GT disparity image: PNG (decoded by cv::imread) or PGM (read_pgm), as some Middlebury
/// 2001 files are. cv::imread picks its decoder by content, not by name (a 22-byte OpenEXR
/// header named disp2.png kept it busy for seconds, found by fuzz_stereo_gt), so anything else
/// is refused before decoding.
cv::Mat read_gt_image(const fs::path& path) {
  static constexpr unsigned char kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  unsigned char head[sizeof kPng] = {};
  std::ifstream in(path, std::ios::binary);
  if (!in) throw core::InputError("cannot read GT disparity " + path.string());
  in.read(reinterpret_cast<char*>(head), sizeof head);
  const bool png = in.gcount() == sizeof head && std::memcmp(head, kPng, sizeof head) == 0;
  const bool pgm = in.gcount() >= 2 && head[0] == 'P' && (head[1] == '2' || head[1] == '5');
  if (pgm) return read_pgm(path);
  if (!png) throw core::InputError(path.string() + ": GT disparity is not a PNG or PGM image");
  cv::Mat raw = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
  if (raw.empty()) throw core::InputError("cannot read GT disparity " + path.string());
  return raw;
}

}  // namespace

cv::Mat read_pfm(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw core::InputError("cannot open PFM file " + path.string());
  std::string tag;
  int width = 0, height = 0;
  double scale = 0;
  in >> tag >> width >> height >> scale;
  if (tag != "Pf" || !in || width <= 0 || height <= 0 || width > 65536 || height > 65536 ||
      scale == 0) {
    throw core::InputError(path.string() + ": not a one-channel PFM file (\"Pf\" header)");
  }
  in.get();  // the single whitespace byte after the scale
  // The header alone must not make us allocate: 17 bytes can announce 65536 x 65536 floats.
  const std::streamoff data_at = in.tellg();
  in.seekg(0, std::ios::end);
  const std::streamoff file_size = in.tellg();
  in.seekg(data_at);
  const std::streamoff needed = static_cast<std::streamoff>(width) * height * 4;
  if (data_at < 0 || file_size - data_at < needed) {
    throw core::InputError(path.string() + ": PFM file is truncated (" + std::to_string(width) +
                           "x" + std::to_string(height) + " needs " + std::to_string(needed) +
                           " bytes of data, the file holds " +
                           std::to_string(std::max<std::streamoff>(0, file_size - data_at)) + ")");
  }
  cv::Mat out(height, width, CV_32F);
  const bool swap = (scale < 0) != little_endian_host();
  std::vector<unsigned char> row(static_cast<size_t>(width) * 4);
  for (int y = height - 1; y >= 0; --y) {  // bottom row first
    if (!in.read(reinterpret_cast<char*>(row.data()), static_cast<std::streamsize>(row.size())))
      throw core::InputError(path.string() + ": PFM file is truncated");
    float* dst = out.ptr<float>(y);
    for (int x = 0; x < width; ++x) {
      unsigned char* b = &row[static_cast<size_t>(x) * 4];
      if (swap) {
        std::swap(b[0], b[3]);
        std::swap(b[1], b[2]);
      }
      float v;
      std::memcpy(&v, b, 4);
      dst[x] = std::isfinite(v) && v > 0 ? v : 0.0f;
    }
  }
  return out;
}

void write_pfm(const fs::path& path, const cv::Mat& disparity) {
  CV_Assert(disparity.type() == CV_32F);
  std::ofstream out(path, std::ios::binary);
  if (!out) throw core::InputError("cannot write " + path.string());
  const bool le = little_endian_host();
  out << "Pf\n" << disparity.cols << " " << disparity.rows << "\n" << (le ? "-1.0" : "1.0") << "\n";
  for (int y = disparity.rows - 1; y >= 0; --y)
    out.write(reinterpret_cast<const char*>(disparity.ptr<float>(y)),
              static_cast<std::streamsize>(disparity.cols * sizeof(float)));
}

namespace {

/// A decoded 8-bit Middlebury GT image (read_gt_image of `path`) divided by its scale (> 0).
cv::Mat middlebury_disparity(cv::Mat raw, double scale, const fs::path& path) {
  if (raw.depth() != CV_8U)
    throw core::InputError(path.string() + ": Middlebury GT must be an 8-bit PNG");
  if (raw.channels() != 1) cv::extractChannel(raw, raw, 0);
  cv::Mat out;
  raw.convertTo(out, CV_32F, 1.0 / scale);
  return out;
}

}  // namespace

cv::Mat read_middlebury_png(const fs::path& path, double scale) {
  if (!(scale > 0)) throw core::InputError("gt_scale=" + std::to_string(scale) + ": must be > 0");
  return middlebury_disparity(read_gt_image(path), scale, path);
}

cv::Mat read_stereo_gt(const fs::path& path, double scale) {
  if (path.extension() == ".pfm") return read_pfm(path);
  cv::Mat raw = read_gt_image(path);
  if (raw.depth() == CV_16U) return read_disparity_png(path);
  if (!(scale > 0)) {
    throw core::InputError(path.string() +
                           ": 8-bit GT needs its scale (disparity = value / scale): give "
                           "--gt-scale or a datasets.xml");
  }
  return middlebury_disparity(std::move(raw), scale, path);  // decoded once
}

std::vector<StereoGtPair> find_stereo_gt_pairs(const fs::path& dir, double scale) {
  if (!fs::is_directory(dir)) throw core::InputError(dir.string() + " is not a folder");
  std::vector<StereoGtPair> out;
  pairs_in(dir, scale, out);
  std::vector<fs::path> subdirs;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_directory()) subdirs.push_back(e.path());
  std::sort(subdirs.begin(), subdirs.end());
  for (const auto& d : subdirs) pairs_in(d, scale, out);
  if (out.empty()) {
    throw core::InputError(dir.string() +
                           " holds no stereo pair with GT (im2/im6/disp2.png, im0/im1.png + "
                           "disp0GT.pfm, or KITTI image_2/image_3/disp_noc_0)");
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const auto& a, const auto& b) { return a.name < b.name; });
  return out;
}

}  // namespace sg::io
