#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iostream>
#include <map>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "gray.hpp"
#include "sg/core/error.hpp"
#include "sg/io/file_kinds.hpp"
#include "sg/io/sources.hpp"

namespace sg::io {
namespace fs = std::filesystem;
namespace {

/// Seconds since the epoch of "YYYY-MM-DD hh:mm:ss.fffffffff" (KITTI timestamps.txt), split in
/// whole seconds and a fraction so that nanoseconds survive.
bool parse_kitti_time(const std::string& text, std::int64_t& seconds, double& fraction) {
  int y = 0, mo = 0, d = 0, h = 0, mi = 0;
  double s = 0;
  if (std::sscanf(text.c_str(), "%d-%d-%d %d:%d:%lf", &y, &mo, &d, &h, &mi, &s) != 6) return false;
  // Fields out of range are not a timestamp (and would overflow the arithmetic below).
  if (y < 1 || y > 9999 || mo < 1 || mo > 12 || d < 1 || d > 31 || h < 0 || h > 23 || mi < 0 ||
      mi > 59 || !std::isfinite(s) || s < 0 || s >= 61) {
    return false;
  }
  // Days from the civil date (H. Hinnant's algorithm).
  y -= mo <= 2;
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const unsigned yoe = static_cast<unsigned>(y - era * 400);
  const unsigned doy = (153 * (mo + (mo > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  const std::int64_t days = era * 146097 + static_cast<std::int64_t>(doe) - 719468;
  const double whole = std::floor(s);
  seconds = days * 86400 + h * 3600 + mi * 60 + static_cast<std::int64_t>(whole);
  fraction = s - whole;
  return true;
}

}  // namespace

std::vector<double> read_kitti_times(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw core::InputError("cannot open " + path.string());
  std::vector<double> times;
  std::int64_t first = 0;
  std::string line;
  for (int line_no = 1; std::getline(in, line); ++line_no) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::int64_t sec = 0;
    double frac = 0;
    if (!parse_kitti_time(line, sec, frac)) {
      throw core::InputError(path.string() + ":" + std::to_string(line_no) +
                             ": not a timestamp 'YYYY-MM-DD hh:mm:ss.fff' ('" + line + "')");
    }
    if (times.empty()) first = sec;
    times.push_back(static_cast<double>(sec - first) + frac);
  }
  return times;
}

std::map<std::int64_t, fs::path> read_euroc_csv(const fs::path& cam_dir) {
  const fs::path csv = cam_dir / "data.csv";
  std::ifstream in(csv);
  if (!in) throw core::InputError("missing EuRoC file: " + csv.string());
  std::map<std::int64_t, fs::path> out;
  std::string line;
  for (int line_no = 1; std::getline(in, line); ++line_no) {
    if (line.empty() || line[0] == '#' || line.find_first_not_of(" \t\r") == std::string::npos) {
      continue;
    }
    const size_t comma = line.find(',');
    long long stamp = 0;
    char* end = nullptr;
    errno = 0;
    if (comma != std::string::npos) stamp = std::strtoll(line.c_str(), &end, 10);
    if (comma == std::string::npos || end != line.c_str() + comma) {
      throw core::InputError(csv.string() + ":" + std::to_string(line_no) +
                             ": expected 'timestamp_ns,file name'");
    }
    // Negative or overflowing stamps are not EuRoC's (ns since 1970); open_euroc subtracts them.
    if (errno == ERANGE || stamp < 0) {
      throw core::InputError(csv.string() + ":" + std::to_string(line_no) + ": timestamp '" +
                             line.substr(0, comma) + "' is not a time in ns (0 .. 2^63 - 1)");
    }
    std::string name = line.substr(comma + 1);
    name.erase(
        std::remove_if(name.begin(), name.end(), [](unsigned char c) { return std::isspace(c); }),
        name.end());
    out[stamp] = cam_dir / "data" / name;
  }
  return out;
}

size_t shorter_count(size_t left, size_t right, const std::string& left_name,
                     const std::string& right_name) {
  if (left != right) {
    std::cerr << "stereoguard: warning: " << left_name << " has " << left << " frames, "
              << right_name << " has " << right << "; using the first " << std::min(left, right)
              << "\n";
  }
  return std::min(left, right);
}

void centre_unknown_principal_point(core::Camera& camera) {
  if (!std::isfinite(camera.cx)) camera.cx = (camera.width - 1) / 2.0;
  if (!std::isfinite(camera.cy)) camera.cy = (camera.height - 1) / 2.0;
}

std::optional<core::StereoFrame> DeferredSource::next() {
  std::optional<core::PendingFrame> pending = next_pending();
  if (!pending) return std::nullopt;
  return pending->load();
}

// ---------------------------------------------------------------------------------------------

std::vector<fs::path> list_images(const std::string& folder_or_glob) {
  std::error_code ec;
  std::vector<fs::path> files;
  if (fs::is_directory(folder_or_glob, ec)) {
    for (const auto& entry : fs::directory_iterator(folder_or_glob, ec)) {
      if (entry.is_regular_file(ec) && is_image_file(entry.path())) files.push_back(entry.path());
    }
    if (files.empty()) throw core::InputError("no images in folder " + folder_or_glob);
  } else if (folder_or_glob.find_first_of("*?[") != std::string::npos) {
    std::vector<cv::String> matches;
    try {
      cv::glob(folder_or_glob, matches, false);
    } catch (const cv::Exception&) {
      matches.clear();
    }
    for (const auto& m : matches) {
      if (is_image_file(m)) files.emplace_back(m);
    }
    if (files.empty()) throw core::InputError("no images match " + folder_or_glob);
  } else {
    throw core::InputError("not found: " + folder_or_glob +
                           " (expected a video, an image folder or a glob pattern)");
  }
  std::sort(files.begin(), files.end());
  return files;
}

double fps_from_times(const std::vector<double>& times) {
  if (times.size() < 2) return 0.0;
  std::vector<double> intervals;
  for (size_t i = 1; i < times.size(); ++i) intervals.push_back(times[i] - times[i - 1]);
  const auto mid = intervals.begin() + static_cast<std::ptrdiff_t>(intervals.size() / 2);
  std::nth_element(intervals.begin(), mid, intervals.end());
  return *mid > 0 ? 1.0 / *mid : 0.0;
}

// ---------------------------------------------------------------------------------------------
// ImageListSource

ImageListSource::ImageListSource(std::vector<ImagePair> pairs, const core::Camera& camera)
    : pairs_(std::move(pairs)), camera_(camera) {
  if (pairs_.empty()) throw core::InputError("no frames");
  const cv::Mat left = detail::read_gray(pairs_[0].left);
  const cv::Mat right = detail::read_gray(pairs_[0].right);
  detail::check_size(right, left.size(), pairs_[0].right.string(), pairs_[0].left.string());
  camera_.width = left.cols;
  camera_.height = left.rows;
  centre_unknown_principal_point(camera_);
}

std::optional<core::PendingFrame> ImageListSource::next_pending() {
  if (next_index_ >= size()) return std::nullopt;
  const int i = next_index_++;
  core::PendingFrame pending;
  pending.index = i;
  pending.time_s = pairs_[i].time_s;
  pending.load = [pair = pairs_[i], i, size = cv::Size(camera_.width, camera_.height)] {
    core::StereoFrame frame;
    frame.index = i;
    frame.time_s = pair.time_s;
    frame.left = detail::read_gray(pair.left);
    frame.right = detail::read_gray(pair.right);
    detail::check_size(frame.left, size, pair.left.string(), "the first frame");
    detail::check_size(frame.right, size, pair.right.string(), "the first frame");
    return frame;
  };
  return pending;
}

// ---------------------------------------------------------------------------------------------
// Rectification

void rectify(const Rectification& r, core::StereoFrame& frame) {
  cv::Mat left, right;
  cv::remap(frame.left, left, r.left_map1, r.left_map2, cv::INTER_LINEAR);
  cv::remap(frame.right, right, r.right_map1, r.right_map2, cv::INTER_LINEAR);
  frame.left = left;
  frame.right = right;
}

RectifiedSource::RectifiedSource(std::unique_ptr<core::FrameSource> inner,
                                 const StereoCalibration& calib, const std::string& where)
    : inner_(std::move(inner)) {
  const core::Camera& raw = inner_->camera();
  auto r = make_rectification(calib, cv::Size(raw.width, raw.height), where);
  auto owned = std::const_pointer_cast<Rectification>(r);
  owned->camera.fps = raw.fps;
  rectification_ = std::move(r);
}

std::optional<core::PendingFrame> RectifiedSource::next_pending() {
  std::optional<core::PendingFrame> pending = inner_->next_pending();
  if (!pending) return std::nullopt;
  pending->load = [inner_load = std::move(pending->load), r = rectification_] {
    core::StereoFrame frame = inner_load();
    rectify(*r, frame);
    return frame;
  };
  return pending;
}

// ---------------------------------------------------------------------------------------------
// KITTI and EuRoC

std::unique_ptr<core::FrameSource> open_kitti(const fs::path& dir, bool color,
                                              const fs::path& calib) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw core::InputError("KITTI folder not found: " + dir.string());
  const int l = color ? 2 : 0, r = color ? 3 : 1;
  const fs::path left_dir = dir / ("image_0" + std::to_string(l));
  const fs::path right_dir = dir / ("image_0" + std::to_string(r));
  for (const auto& d : {left_dir, right_dir}) {
    if (!fs::is_directory(d / "data", ec)) {
      throw core::InputError("missing KITTI folder " + (d / "data").string() +
                             (color ? "" : " (colour drives: add --kitti-color)"));
    }
  }
  fs::path calib_file = calib;
  if (calib_file.empty()) {
    for (const auto& candidate :
         {dir / "calib_cam_to_cam.txt", dir.parent_path() / "calib_cam_to_cam.txt",
          fs::absolute(dir).parent_path() / "calib_cam_to_cam.txt"}) {
      if (fs::is_regular_file(candidate, ec)) {
        calib_file = candidate;
        break;
      }
    }
    if (calib_file.empty()) {
      throw core::InputError("no calib_cam_to_cam.txt in " + dir.string() +
                             " or its parent folder (give --calib FILE)");
    }
  }
  core::Camera camera = read_kitti_calibration(calib_file, l, r);
  const auto left = list_images((left_dir / "data").string());
  const auto right = list_images((right_dir / "data").string());
  const size_t n = shorter_count(left.size(), right.size(), left_dir.string(), right_dir.string());
  std::vector<double> times;
  const fs::path stamps = left_dir / "timestamps.txt";
  if (fs::is_regular_file(stamps, ec)) {
    times = read_kitti_times(stamps);
    if (times.size() < n) {
      throw core::InputError(stamps.string() + " has " + std::to_string(times.size()) +
                             " timestamps for " + std::to_string(n) + " images");
    }
    camera.fps = fps_from_times(times);
  } else {
    camera.fps = 10.0;  // KITTI raw is recorded at 10 Hz
  }
  std::vector<ImagePair> pairs(n);
  for (size_t i = 0; i < n; ++i) {
    pairs[i] = {left[i], right[i], times.empty() ? i / camera.fps : times[i]};
  }
  const cv::Size calib_size(camera.width, camera.height);
  auto source = std::make_unique<ImageListSource>(std::move(pairs), camera);
  if (cv::Size(source->camera().width, source->camera().height) != calib_size) {
    throw core::InputError("KITTI calibration " + calib_file.string() + " is for " +
                           detail::size_text(calib_size) + " images (S_rect), the images are " +
                           std::to_string(source->camera().width) + "x" +
                           std::to_string(source->camera().height));
  }
  core::throw_if_invalid(core::validate(source->camera()),
                         "invalid camera in " + calib_file.string());
  return source;
}

std::unique_ptr<core::FrameSource> open_euroc(const fs::path& dir_in) {
  std::error_code ec;
  if (!fs::is_directory(dir_in, ec)) {
    throw core::InputError("EuRoC folder not found: " + dir_in.string());
  }
  fs::path dir = dir_in;
  if (!fs::is_directory(dir / "cam0", ec) && fs::is_directory(dir / "mav0", ec)) dir = dir / "mav0";
  for (const char* cam : {"cam0", "cam1"}) {
    if (!fs::is_directory(dir / cam, ec)) {
      throw core::InputError("missing EuRoC folder " + (dir / cam).string());
    }
  }
  const StereoCalibration calib =
      read_euroc_calibration(dir / "cam0" / "sensor.yaml", dir / "cam1" / "sensor.yaml");
  const auto left = read_euroc_csv(dir / "cam0");
  const auto right = read_euroc_csv(dir / "cam1");
  std::vector<ImagePair> pairs;
  std::vector<double> times;
  std::int64_t first = 0;
  for (const auto& [stamp, file] : left) {
    const auto it = right.find(stamp);
    if (it == right.end()) continue;
    if (pairs.empty()) first = stamp;
    const double t = static_cast<double>(stamp - first) * 1e-9;
    pairs.push_back({file, it->second, t});
    times.push_back(t);
  }
  if (pairs.empty()) {
    throw core::InputError("no frames: cam0 and cam1 of " + dir.string() +
                           " share no timestamp in data.csv");
  }
  core::Camera camera;
  camera.fps = pairs.size() >= 2 ? fps_from_times(times) : calib.fps;
  camera.focal_px = calib.M1.at<double>(0, 0);
  auto raw = std::make_unique<ImageListSource>(std::move(pairs), camera);
  return std::make_unique<RectifiedSource>(std::move(raw), calib,
                                           (dir / "cam0" / "sensor.yaml").string() + " + cam1");
}

}  // namespace sg::io
