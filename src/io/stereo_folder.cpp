#include "sg/io/stereo_folder.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <system_error>

#include "sg/core/error.hpp"
#include "sg/core/yaml_text.hpp"
#include "sg/io/file_kinds.hpp"
#include "gray.hpp"
#include "sg/io/gt_formats.hpp"

namespace sg::io {
namespace fs = std::filesystem;
using detail::size_text;
namespace {

cv::Mat load_gray(const fs::path& path) { return detail::read_gray(path); }

/// Shortest text that reads back as exactly `v`.
std::string number_text(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

/// One line: messages from libraries may carry newlines.
std::string one_line(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  return s;
}

/// Sorted .png files of `dir`; throws when `dir` is not a folder.
std::vector<fs::path> list_pngs(const fs::path& dir, const fs::path& root, const char* name) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    throw core::InputError(std::string("missing ") + name + "/ folder in stereo folder " +
                           root.string() + ": " + dir.string());
  }
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (entry.is_regular_file(ec) && lower_extension(entry.path()) == ".png")
      files.push_back(entry.path());
  }
  if (ec) throw core::InputError("cannot list folder " + dir.string() + ": " + ec.message());
  std::sort(files.begin(), files.end(),
            [](const fs::path& a, const fs::path& b) { return a.filename() < b.filename(); });
  return files;
}

/// 8- or 16-bit single channel PNG of a truth map; `type` is the required cv type.
cv::Mat load_map(const fs::path& path, int type, const char* what) {
  cv::Mat raw;
  try {
    raw = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception&) {
    raw.release();
  }
  if (raw.empty()) throw core::InputError(std::string("cannot read ") + what + ": " + path.string());
  if (raw.type() != type) {
    throw core::InputError(std::string(what) + " has the wrong pixel type (need " +
                           (type == CV_8UC1 ? "8-bit" : "16-bit") +
                           " single channel): " + path.string());
  }
  return raw;
}

void write_png(const fs::path& path, const cv::Mat& image) {
  bool ok = false;
  try {
    ok = cv::imwrite(path.string(), image);
  } catch (const cv::Exception&) {
    ok = false;
  }
  if (!ok) throw core::InputError("cannot write image: " + path.string());
}

void make_dir(const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) {
    throw core::InputError("cannot create folder " + dir.string() +
                           (ec ? ": " + ec.message() : std::string()));
  }
}

double field_number(const YAML::Node& root, const char* field, const fs::path& path) {
  const YAML::Node node = root[field];
  if (!node || node.IsNull()) {
    throw core::InputError(path.string() + ": missing field '" + field + "' (a number)");
  }
  if (!node.IsScalar()) {
    throw core::InputError(path.string() + ": field '" + field + "' is not a number");
  }
  try {
    return node.as<double>();
  } catch (const YAML::Exception&) {
    throw core::InputError(path.string() + ": field '" + field + "' is not a number ('" +
                           node.Scalar() + "')");
  }
}

}  // namespace

std::string frame_file_name(int index, const char* extension) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%06d", index);
  return std::string(buf) + extension;
}

core::Camera read_camera_yaml(const fs::path& path, cv::Size size) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) {
    throw core::InputError("missing camera file: " + path.string());
  }
  const std::string text = core::read_yaml_text(path, "cannot parse " + path.string());
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw core::InputError("cannot parse " + path.string() + ": " + one_line(e.what()));
  }
  if (!root.IsMap()) {
    throw core::InputError("cannot parse " + path.string() +
                           ": expected a mapping with focal_px, baseline_m, cx, cy, fps");
  }
  core::Camera camera;
  camera.width = size.width;
  camera.height = size.height;
  camera.focal_px = field_number(root, "focal_px", path);
  camera.baseline_m = field_number(root, "baseline_m", path);
  camera.cx = field_number(root, "cx", path);
  camera.cy = field_number(root, "cy", path);
  camera.fps = field_number(root, "fps", path);
  core::throw_if_invalid(core::validate(camera), "invalid camera in " + path.string());
  return camera;
}

void write_camera_yaml(const fs::path& path, const core::Camera& camera) {
  std::ofstream out(path, std::ios::trunc);
  if (!out) throw core::InputError("cannot write camera file: " + path.string());
  out << "# stereoguard camera; width/height are informational (readers take them from the "
         "images)\n"
      << "focal_px: " << number_text(camera.focal_px) << "\n"
      << "baseline_m: " << number_text(camera.baseline_m) << "\n"
      << "cx: " << number_text(camera.cx) << "\n"
      << "cy: " << number_text(camera.cy) << "\n"
      << "fps: " << number_text(camera.fps) << "\n"
      << "width: " << camera.width << "\n"
      << "height: " << camera.height << "\n";
  out.flush();
  if (!out) throw core::InputError("cannot write camera file: " + path.string());
}

// ---------------------------------------------------------------------------------------------
// Truth lines

core::FrameTruth parse_truth_line(const std::string& line, const std::string& where) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(line);
  } catch (const nlohmann::json::exception& e) {
    throw core::InputError(where + ": malformed JSON: " + one_line(e.what()));
  }
  auto bad = [&where](const std::string& what) {
    return core::InputError(where + ": malformed truth line: " + what);
  };
  if (!j.is_object()) throw bad("expected a JSON object");
  core::FrameTruth truth;
  if (!j.contains("frame") || !j["frame"].is_number_integer()) throw bad("'frame' must be an integer");
  truth.frame = j["frame"].get<int>();
  if (!j.contains("alarm") || !j["alarm"].is_boolean()) throw bad("'alarm' must be true or false");
  truth.alarm = j["alarm"].get<bool>();
  if (!j.contains("obstacles") || !j["obstacles"].is_array()) {
    throw bad("'obstacles' must be an array");
  }
  for (const auto& o : j["obstacles"]) {
    if (!o.is_object()) throw bad("each obstacle must be an object");
    core::ObstacleTruth t;
    if (!o.contains("id") || !o["id"].is_number_integer()) throw bad("obstacle 'id' must be an integer");
    t.id = o["id"].get<int>();
    if (!o.contains("colliding") || !o["colliding"].is_boolean()) {
      throw bad("obstacle 'colliding' must be true or false");
    }
    t.colliding = o["colliding"].get<bool>();
    if (o.contains("ttc_s") && !o["ttc_s"].is_null()) {
      if (!o["ttc_s"].is_number()) throw bad("obstacle 'ttc_s' must be a number or null");
      t.ttc_s = o["ttc_s"].get<double>();
    }
    if (!o.contains("pixels") || !o["pixels"].is_number_integer()) {
      throw bad("obstacle 'pixels' must be an integer");
    }
    t.pixels = o["pixels"].get<int>();
    truth.obstacles.push_back(t);
  }
  return truth;
}

std::string truth_to_json_line(const core::FrameTruth& truth) {
  nlohmann::ordered_json j;
  j["frame"] = truth.frame;
  j["alarm"] = truth.alarm;
  j["obstacles"] = nlohmann::ordered_json::array();
  for (const auto& o : truth.obstacles) {
    nlohmann::ordered_json e;
    e["id"] = o.id;
    e["colliding"] = o.colliding;
    e["ttc_s"] = o.ttc_s ? nlohmann::ordered_json(*o.ttc_s) : nlohmann::ordered_json(nullptr);
    e["pixels"] = o.pixels;
    j["obstacles"].push_back(std::move(e));
  }
  return j.dump();
}

// ---------------------------------------------------------------------------------------------
// FolderSource

FolderSource::FolderSource(const fs::path& dir) : dir_(dir) {
  std::error_code ec;
  if (!fs::exists(dir_, ec)) throw core::InputError("stereo folder not found: " + dir_.string());
  if (!fs::is_directory(dir_, ec)) {
    throw core::InputError("stereo folder is not a folder: " + dir_.string());
  }
  const fs::path camera_file = dir_ / "camera.yaml";
  if (!fs::is_regular_file(camera_file, ec)) {
    throw core::InputError("missing camera file: " + camera_file.string());
  }
  left_ = list_pngs(dir_ / "left", dir_, "left");
  right_ = list_pngs(dir_ / "right", dir_, "right");
  if (left_.empty()) {
    throw core::InputError("no frames: no .png images in " + (dir_ / "left").string());
  }
  if (left_.size() != right_.size()) {
    throw core::InputError("left/ has " + std::to_string(left_.size()) + " images, right/ has " +
                           std::to_string(right_.size()) + ": " + dir_.string());
  }
  const cv::Mat left0 = load_gray(left_[0]);
  const cv::Mat right0 = load_gray(right_[0]);
  if (left0.size() != right0.size()) {
    throw core::InputError("size mismatch: " + left_[0].string() + " is " +
                           size_text(left0.size()) + " but " + right_[0].string() + " is " +
                           size_text(right0.size()));
  }
  camera_ = read_camera_yaml(camera_file, left0.size());

  const fs::path truth_file = dir_ / "gt" / "frames.jsonl";
  if (fs::is_regular_file(truth_file, ec)) {
    has_truth_ = true;
    std::ifstream in(truth_file);
    if (!in) throw core::InputError("cannot open " + truth_file.string());
    std::string line;
    for (int line_no = 1; std::getline(in, line); ++line_no) {
      if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
      truth_.push_back(parse_truth_line(line, truth_file.string() + ":" + std::to_string(line_no)));
    }
  }
}

namespace {

/// Decodes one pair of a stereo folder and checks it against the first frame's size.
core::StereoFrame load_pair(int index, double time_s, const fs::path& left, const fs::path& right,
                            cv::Size expected) {
  core::StereoFrame frame;
  frame.index = index;
  frame.time_s = time_s;
  frame.left = load_gray(left);
  frame.right = load_gray(right);
  for (const auto* side : {&frame.left, &frame.right}) {
    if (side->size() != expected) {
      const fs::path& file = side == &frame.left ? left : right;
      throw core::InputError("size mismatch: " + file.string() + " is " + size_text(side->size()) +
                             ", the first frame is " + size_text(expected));
    }
  }
  return frame;
}

}  // namespace

std::optional<core::StereoFrame> FolderSource::next() {
  std::optional<core::PendingFrame> pending = next_pending();
  if (!pending) return std::nullopt;
  return pending->load();
}

std::optional<core::PendingFrame> FolderSource::next_pending() {
  if (next_index_ >= size()) return std::nullopt;
  // Advance first: a broken frame is reported once, and a caller that goes on gets the next one.
  const int i = next_index_++;
  core::PendingFrame pending;
  pending.index = i;
  pending.time_s = i / camera_.fps;
  // The load copies what it needs, so it may run on any thread after the source moved on.
  pending.load = [i, time_s = pending.time_s, left = left_[i], right = right_[i],
                  expected = cv::Size(camera_.width, camera_.height)] {
    return load_pair(i, time_s, left, right, expected);
  };
  return pending;
}

bool FolderSource::has_truth() const { return has_truth_; }

const core::FrameTruth& FolderSource::truth(int index) const {
  // Lines are normally in frame order; fall back to a search when they are not.
  if (index >= 0 && index < static_cast<int>(truth_.size()) && truth_[index].frame == index) {
    return truth_[index];
  }
  for (const auto& t : truth_) {
    if (t.frame == index) return t;
  }
  throw core::InputError("no ground truth for frame " + std::to_string(index) + " in " +
                         (dir_ / "gt" / "frames.jsonl").string());
}

core::TruthMaps FolderSource::truth_maps(int index) const {
  core::TruthMaps maps;
  const fs::path gt = dir_ / "gt";
  std::error_code ec;
  const fs::path disp = gt / "disp" / frame_file_name(index, ".png");
  if (fs::is_regular_file(disp, ec)) maps.disparity = read_disparity_png(disp);
  const fs::path flow = gt / "flow" / frame_file_name(index, ".flo");
  if (fs::is_regular_file(flow, ec)) maps.flow = read_flo(flow);
  const fs::path danger = gt / "danger" / frame_file_name(index, ".png");
  if (fs::is_regular_file(danger, ec)) maps.danger = load_map(danger, CV_8UC1, "danger map");
  const fs::path ids = gt / "ids" / frame_file_name(index, ".png");
  if (fs::is_regular_file(ids, ec)) maps.ids = load_map(ids, CV_16UC1, "id map");
  return maps;
}

// ---------------------------------------------------------------------------------------------
// FolderWriter

FolderWriter::FolderWriter(const fs::path& dir, const core::Camera& camera, bool with_truth)
    : dir_(dir), with_truth_(with_truth) {
  make_dir(dir_);
  make_dir(dir_ / "left");
  make_dir(dir_ / "right");
  write_camera_yaml(dir_ / "camera.yaml", camera);
  if (with_truth_) {
    for (const char* sub : {"disp", "flow", "danger", "ids"}) make_dir(dir_ / "gt" / sub);
    const fs::path truth_file = dir_ / "gt" / "frames.jsonl";
    truth_out_.open(truth_file, std::ios::trunc);
    if (!truth_out_) throw core::InputError("cannot write " + truth_file.string());
  }
}

void FolderWriter::write(const core::StereoFrame& frame, const core::FrameTruth* truth,
                         const core::TruthMaps* maps) {
  const std::string png = frame_file_name(frames_, ".png");
  write_png(dir_ / "left" / png, frame.left);
  write_png(dir_ / "right" / png, frame.right);
  if (with_truth_ && truth != nullptr) {
    truth_out_ << truth_to_json_line(*truth) << '\n';
    truth_out_.flush();
    if (!truth_out_) throw core::InputError("cannot write " + (dir_ / "gt" / "frames.jsonl").string());
  }
  if (with_truth_ && maps != nullptr) {
    const fs::path gt = dir_ / "gt";
    if (!maps->disparity.empty()) write_disparity_png(gt / "disp" / png, maps->disparity);
    if (!maps->flow.empty()) write_flo(gt / "flow" / frame_file_name(frames_, ".flo"), maps->flow);
    if (!maps->danger.empty()) write_png(gt / "danger" / png, maps->danger);
    if (!maps->ids.empty()) write_png(gt / "ids" / png, maps->ids);
  }
  ++frames_;
}

}  // namespace sg::io
