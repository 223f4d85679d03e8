#include "sg/io/calibration.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "gray.hpp"
#include "sg/core/error.hpp"
#include "sg/core/yaml_text.hpp"
#include "sg/io/file_kinds.hpp"
#include "sg/io/stereo_folder.hpp"

namespace sg::io {
namespace fs = std::filesystem;
namespace {

/// An image size read as two numbers: whole numbers of pixels in 1..100000, checked before the
/// cast (a double beyond int's range is undefined behaviour as an int; found by fuzz_euroc_calib
/// and fuzz_kitti_calib).
cv::Size image_size(const std::vector<double>& wh, const std::string& field, const fs::path& path) {
  for (const double v : wh)
    if (!(v >= 1.0 && v <= 100000.0 && v == std::floor(v)))
      throw core::InputError(path.string() + ": " + field +
                             " must be two whole numbers of pixels in 1..100000");
  return {static_cast<int>(wh[0]), static_cast<int>(wh[1])};
}

bool all_finite(const cv::Mat& m) { return cv::checkRange(m, true, nullptr, -1e300, 1e300); }

void check_matrix(std::vector<std::string>& out, const char* name, const cv::Mat& m, int rows,
                  int cols) {
  if (m.rows != rows || m.cols != cols) {
    out.push_back(std::string("calib.") + name + ": must be " + std::to_string(rows) + "x" +
                  std::to_string(cols) + ", is " + std::to_string(m.rows) + "x" +
                  std::to_string(m.cols));
  } else if (!all_finite(m)) {
    out.push_back(std::string("calib.") + name + ": has a value that is not finite (NaN or inf)");
  }
}

void check_camera_matrix(std::vector<std::string>& out, const char* name, const cv::Mat& m) {
  const size_t before = out.size();
  check_matrix(out, name, m, 3, 3);
  if (out.size() != before) return;
  if (!(m.at<double>(0, 0) > 0 && m.at<double>(1, 1) > 0) || std::abs(cv::determinant(m)) < 1e-9) {
    out.push_back(std::string("calib.") + name +
                  ": not an invertible camera matrix (focal lengths must be positive)");
  }
}

void check_distortion(std::vector<std::string>& out, const char* name, const cv::Mat& d) {
  const int n = static_cast<int>(d.total());
  if (d.empty() || (d.rows != 1 && d.cols != 1) ||
      (n != 4 && n != 5 && n != 8 && n != 12 && n != 14)) {
    out.push_back(std::string("calib.") + name +
                  ": must hold 4, 5, 8, 12 or 14 coefficients, has " + std::to_string(n));
  } else if (!all_finite(d)) {
    out.push_back(std::string("calib.") + name + ": has a value that is not finite (NaN or inf)");
  }
}

/// False when an opencv-matrix node states rows, cols or sizes that are not small non-negative
/// integers: OpenCV allocates what they say before reading the data (found by fuzz_calibration:
/// a garbled `rows:` made it allocate 16 GiB). Calibration matrices are at most 4x4 or 1x14.
bool small_matrix_node(const cv::FileNode& node) {
  if (!node.isMap()) return true;
  auto small = [](const cv::FileNode& n) {
    return n.isInt() && static_cast<int>(n) >= 0 && static_cast<int>(n) <= 64;
  };
  for (const char* key : {"rows", "cols"}) {
    const cv::FileNode n = node[key];
    if (!n.empty() && !small(n)) return false;
  }
  const cv::FileNode sizes = node["sizes"];
  if (!sizes.empty()) {
    if (!sizes.isSeq() || sizes.size() > 3) return false;
    for (const cv::FileNode& n : sizes)
      if (!small(n)) return false;
  }
  return true;
}

/// A field of a FileStorage file as a CV_64F matrix; InputError when missing or not a matrix.
cv::Mat fs_matrix(const cv::FileStorage& file, const char* name, const fs::path& path,
                  bool required) {
  const cv::FileNode node = file[name];
  if (node.empty() || node.isNone()) {
    if (!required) return {};
    throw core::InputError(path.string() + ": missing field '" + name + "'");
  }
  if (!small_matrix_node(node)) {
    throw core::InputError(path.string() + ": field '" + name +
                           "' states rows/cols that are not integers from 0 to 64");
  }
  cv::Mat m;
  try {
    node >> m;
  } catch (const std::exception&) {  // cv::Exception, or a standard one from OpenCV's reader
    m.release();
  }
  if (m.empty()) throw core::InputError(path.string() + ": field '" + name + "' is not a matrix");
  cv::Mat d;
  m.convertTo(d, CV_64F);
  return d;
}

/// YAML without OpenCV's "%YAML:1.0" directive, which yaml-cpp rejects; InputError when invalid.
YAML::Node load_yaml(const fs::path& path);

/// True for a file OpenCV reads as YAML: a .yml or .yaml name, or text starting with "%YAML".
bool is_yaml_file(const fs::path& path) {
  const std::string ext = lower_extension(path);
  if (ext == ".yml" || ext == ".yaml") return true;
  std::string head(5, '\0');
  std::ifstream(path, std::ios::binary).read(head.data(), 5);
  return head == "%YAML";
}

/// The InputError for a YAML calibration file that yaml-cpp refuses (`why`: load_yaml's message).
core::InputError invalid_yaml(const fs::path& path, const std::string& why) {
  return core::InputError("cannot parse calibration file " + path.string() +
                          " (not valid YAML: " + why + ")");
}

/// `yaml_checked`: the caller has already run load_yaml on the file and thrown invalid_yaml if it
/// failed on a YAML file, so the file need not be parsed a second time here.
cv::FileStorage open_storage(const fs::path& path, bool yaml_checked) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) {
    throw core::InputError("calibration file not found: " + path.string());
  }
  // OpenCV 4.6's YAML reader loops for hours on some malformed text (found by fuzz_calibration:
  // 40 bytes, "  xx:3\n : [-0, 0 [-0, 0]"); yaml-cpp refuses such text at once, so a YAML file
  // must pass it first.
  if (!yaml_checked && is_yaml_file(path)) {
    try {
      (void)load_yaml(path);
    } catch (const core::InputError& e) {
      throw invalid_yaml(path, e.what());
    }
  }
  cv::FileStorage file;
  try {
    file.open(path.string(), cv::FileStorage::READ);
  } catch (const std::exception&) {
    // cv::Exception, and std::length_error that OpenCV 4.6's YAML reader lets out for a key
    // like ":dtd" in a matrix (found by fuzz_calibration).
    throw core::InputError("cannot parse calibration file " + path.string() +
                           " (not OpenCV YAML/XML)");
  }
  if (!file.isOpened()) {
    throw core::InputError("cannot parse calibration file " + path.string() +
                           " (not OpenCV YAML/XML)");
  }
  // Fields are looked up by name, which OpenCV asserts on (cv::Exception) unless the top level is
  // a mapping (found by fuzz_calibration: a file whose top level is a list).
  if (!file.root().isMap()) {
    throw core::InputError("cannot parse calibration file " + path.string() +
                           ": the top level is not a mapping of fields (M1, D1, ...)");
  }
  return file;
}

/// YAML without OpenCV's "%YAML:1.0" directive, which yaml-cpp rejects.
YAML::Node load_yaml(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw core::InputError("cannot open " + path.string());
  std::stringstream text;
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("%YAML", 0) == 0) continue;
    text << line << "\n";
  }
  const std::string yaml = text.str();
  core::check_flow_nesting(yaml, "cannot parse " + path.string());
  try {
    return YAML::Load(yaml);
  } catch (const YAML::Exception& e) {
    std::string what = e.what();
    std::replace(what.begin(), what.end(), '\n', ' ');
    throw core::InputError("cannot parse " + path.string() + ": " + what);
  }
}

std::vector<double> yaml_numbers(const YAML::Node& root, const char* field, const fs::path& path,
                                 size_t count) {
  const YAML::Node node = root[field];
  if (!node) throw core::InputError(path.string() + ": missing field '" + field + "'");
  std::vector<double> v;
  try {
    v = node.as<std::vector<double>>();
  } catch (const YAML::Exception&) {
    throw core::InputError(path.string() + ": field '" + field + "' is not a list of numbers");
  }
  if (count != 0 && v.size() != count) {
    throw core::InputError(path.string() + ": field '" + field + "' must hold " +
                           std::to_string(count) + " numbers, holds " + std::to_string(v.size()));
  }
  for (double x : v) {
    if (!std::isfinite(x)) {
      throw core::InputError(path.string() + ": field '" + field +
                             "' has a value that is not finite");
    }
  }
  return v;
}

struct EurocCamera {
  cv::Mat K, D, T_BS;
  cv::Size size;
  double fps = 0;
};

EurocCamera read_euroc_camera(const fs::path& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec))
    throw core::InputError("missing EuRoC file: " + path.string());
  const YAML::Node root = load_yaml(path);
  if (!root.IsMap()) throw core::InputError("cannot parse " + path.string() + ": not a mapping");
  EurocCamera cam;
  const auto in = yaml_numbers(root, "intrinsics", path, 4);
  cam.K = (cv::Mat_<double>(3, 3) << in[0], 0, in[2], 0, in[1], in[3], 0, 0, 1);
  const auto d = yaml_numbers(root, "distortion_coefficients", path, 0);
  // An empty list stays an empty matrix (validate() names it); reshape would throw on it.
  if (!d.empty()) cam.D = cv::Mat(d, true).reshape(1, 1);
  cam.size = image_size(yaml_numbers(root, "resolution", path, 2), "resolution", path);
  if (!root["T_BS"] || !root["T_BS"].IsMap()) {
    throw core::InputError(path.string() + ": missing field 'T_BS' (a 4x4 matrix with data:)");
  }
  const auto t = yaml_numbers(root["T_BS"], "data", path, 16);
  cam.T_BS = cv::Mat(t, true).reshape(1, 4);
  if (const YAML::Node rate = root["rate_hz"]) {
    try {
      cam.fps = rate.as<double>();
    } catch (const YAML::Exception&) {
      throw core::InputError(path.string() + ": field 'rate_hz' is not a number");
    }
  }
  if (root["distortion_model"] && root["distortion_model"].Scalar() != "radial-tangential") {
    throw core::InputError(path.string() + ": distortion_model '" +
                           root["distortion_model"].Scalar() +
                           "' is not supported (radial-tangential only)");
  }
  return cam;
}

/// KITTI "KEY: n n n ..." lines.
std::map<std::string, std::vector<double>> read_kitti_lines(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw core::InputError("cannot open KITTI calibration " + path.string());
  std::map<std::string, std::vector<double>> out;
  std::string line;
  while (std::getline(in, line)) {
    const size_t colon = line.find(':');
    if (colon == std::string::npos) continue;
    const std::string key = line.substr(0, colon);
    if (key == "calib_time") continue;
    std::istringstream values(line.substr(colon + 1));
    std::vector<double> v;
    std::string word;
    while (values >> word) {
      char* end = nullptr;
      const double x = std::strtod(word.c_str(), &end);
      if (end == word.c_str() || *end != '\0') {
        throw core::InputError(path.string() + ": key '" + key +
                               "' has a value that is not a number ('" + word + "')");
      }
      v.push_back(x);
    }
    out[key] = std::move(v);
  }
  return out;
}

const std::vector<double>& kitti_key(const std::map<std::string, std::vector<double>>& lines,
                                     const std::string& key, size_t count, const fs::path& path) {
  const auto it = lines.find(key);
  if (it == lines.end()) throw core::InputError(path.string() + ": missing key '" + key + "'");
  if (it->second.size() != count) {
    throw core::InputError(path.string() + ": key '" + key + "' must hold " +
                           std::to_string(count) + " numbers, holds " +
                           std::to_string(it->second.size()));
  }
  for (double x : it->second) {
    if (!std::isfinite(x)) {
      throw core::InputError(path.string() + ": key '" + key + "' has a value that is not finite");
    }
  }
  return it->second;
}

std::string kitti_name(const char* prefix, int cam) {
  return std::string(prefix) + (cam < 10 ? "0" : "") + std::to_string(cam);
}

}  // namespace

std::vector<std::string> validate(const StereoCalibration& c) {
  std::vector<std::string> out;
  check_camera_matrix(out, "M1", c.M1);
  check_camera_matrix(out, "M2", c.M2);
  check_distortion(out, "D1", c.D1);
  check_distortion(out, "D2", c.D2);
  const size_t before = out.size();
  check_matrix(out, "R", c.R, 3, 3);
  if (out.size() == before) {
    const cv::Mat should_be_identity = c.R * c.R.t();
    if (cv::norm(should_be_identity, cv::Mat::eye(3, 3, CV_64F), cv::NORM_INF) > 1e-3 ||
        cv::determinant(c.R) < 0) {
      out.push_back("calib.R: not a rotation matrix (R * R^T must be I, det R = 1)");
    }
  }
  const size_t before_t = out.size();
  check_matrix(out, "T", c.T.rows == 1 ? cv::Mat(c.T.t()) : c.T, 3, 1);
  if (out.size() == before_t && cv::norm(c.T) <= 0) {
    out.push_back("calib.T: the two cameras are at the same place (T = 0)");
  }
  const int given = !c.R1.empty() + !c.R2.empty() + !c.P1.empty() + !c.P2.empty();
  if (given != 0 && given != 4) {
    out.push_back("calib: R1 R2 P1 P2 must be given all together or not at all");
  } else if (given == 4) {
    check_matrix(out, "R1", c.R1, 3, 3);
    check_matrix(out, "R2", c.R2, 3, 3);
    check_matrix(out, "P1", c.P1, 3, 4);
    check_matrix(out, "P2", c.P2, 3, 4);
  }
  if (c.image_size.width < 0 || c.image_size.height < 0) {
    out.push_back("calib.image_size: must not be negative");
  }
  return out;
}

namespace {

/// read_opencv_calibration; `yaml_checked` as for open_storage.
StereoCalibration read_opencv_file(const fs::path& path, bool yaml_checked) {
  cv::FileStorage file = open_storage(path, yaml_checked);
  StereoCalibration c;
  c.M1 = fs_matrix(file, "M1", path, true);
  c.D1 = fs_matrix(file, "D1", path, true);
  c.M2 = fs_matrix(file, "M2", path, true);
  c.D2 = fs_matrix(file, "D2", path, true);
  c.R = fs_matrix(file, "R", path, true);
  c.T = fs_matrix(file, "T", path, true);
  if (c.T.rows == 1) c.T = c.T.t();
  if (c.R.total() == 3) {  // a Rodrigues vector
    cv::Mat r;
    cv::Rodrigues(c.R, r);
    c.R = r;
  }
  for (auto [name, m] :
       {std::pair{"R1", &c.R1}, {"R2", &c.R2}, {"P1", &c.P1}, {"P2", &c.P2}, {"Q", &c.Q}}) {
    *m = fs_matrix(file, name, path, false);
  }
  int width = 0, height = 0;
  try {
    if (!file["image_width"].empty()) file["image_width"] >> width;
    if (!file["image_height"].empty()) file["image_height"] >> height;
  } catch (const cv::Exception&) {
    throw core::InputError(path.string() + ": image_width and image_height must be integers");
  }
  c.image_size = cv::Size(width, height);
  core::throw_if_invalid(validate(c), "invalid calibration " + path.string());
  return c;
}

}  // namespace

StereoCalibration read_opencv_calibration(const fs::path& path) {
  return read_opencv_file(path, false);
}

void write_opencv_calibration(const fs::path& path, const StereoCalibration& c) {
  cv::FileStorage file;
  try {
    file.open(path.string(), cv::FileStorage::WRITE);
  } catch (const cv::Exception&) {
  }
  if (!file.isOpened()) throw core::InputError("cannot write calibration file " + path.string());
  file << "image_width" << c.image_size.width << "image_height" << c.image_size.height;
  file << "M1" << c.M1 << "D1" << c.D1 << "M2" << c.M2 << "D2" << c.D2 << "R" << c.R << "T" << c.T;
  for (auto [name, m] :
       {std::pair{"R1", &c.R1}, {"R2", &c.R2}, {"P1", &c.P1}, {"P2", &c.P2}, {"Q", &c.Q}}) {
    if (!m->empty()) file << name << *m;
  }
  file.release();
}

core::Camera read_kitti_calibration(const fs::path& path, int left_cam, int right_cam) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) {
    throw core::InputError("missing KITTI calibration file: " + path.string());
  }
  const auto lines = read_kitti_lines(path);
  const auto& pl = kitti_key(lines, kitti_name("P_rect_", left_cam), 12, path);
  const auto& pr = kitti_key(lines, kitti_name("P_rect_", right_cam), 12, path);
  const auto& size = kitti_key(lines, kitti_name("S_rect_", left_cam), 2, path);
  core::Camera cam;
  const cv::Size wh = image_size(size, kitti_name("S_rect_", left_cam), path);
  cam.width = wh.width;
  cam.height = wh.height;
  cam.focal_px = pl[0];
  cam.cx = pl[2];
  cam.cy = pl[6];
  cam.baseline_m = (pl[3] - pr[3]) / pl[0];
  cam.fps = 0.0;
  return cam;
}

StereoCalibration read_euroc_calibration(const fs::path& left_yaml, const fs::path& right_yaml) {
  const EurocCamera l = read_euroc_camera(left_yaml);
  const EurocCamera r = read_euroc_camera(right_yaml);
  if (l.size != r.size) {
    throw core::InputError("EuRoC cameras differ in resolution: " + left_yaml.string() + " is " +
                           detail::size_text(l.size) + ", " + right_yaml.string() + " is " +
                           detail::size_text(r.size));
  }
  if (std::abs(cv::determinant(r.T_BS)) < 1e-9) {
    throw core::InputError(right_yaml.string() + ": T_BS is not invertible");
  }
  // Points in the left sensor frame to the right one: T_S1_B * T_B_S0.
  const cv::Mat right_from_left = r.T_BS.inv() * l.T_BS;
  StereoCalibration c;
  c.image_size = l.size;
  c.M1 = l.K;
  c.D1 = l.D;
  c.M2 = r.K;
  c.D2 = r.D;
  c.R = right_from_left(cv::Rect(0, 0, 3, 3)).clone();
  c.T = right_from_left(cv::Rect(3, 0, 1, 3)).clone();
  c.fps = l.fps;
  core::throw_if_invalid(validate(c),
                         "invalid EuRoC calibration " + left_yaml.parent_path().string());
  return c;
}

Calibration read_calibration(const fs::path& path, bool kitti_color) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) {
    throw core::InputError("calibration file not found: " + path.string());
  }
  Calibration out;
  const std::string ext = lower_extension(path);
  if (ext == ".txt") {
    out.rectified =
        kitti_color ? read_kitti_calibration(path, 2, 3) : read_kitti_calibration(path, 0, 1);
    return out;
  }
  if (ext != ".xml" && ext != ".gz") {
    // stereoguard's camera.yaml is plain YAML, which OpenCV's reader may refuse.
    YAML::Node root;
    std::string yaml_error;
    try {
      root = load_yaml(path);
    } catch (const core::InputError& e) {
      yaml_error = e.what();
    }
    if (root.IsMap() && root["focal_px"]) {
      out.rectified = read_camera_yaml(path, cv::Size(1, 1));  // size comes from the images
      return out;
    }
    // The file has been through yaml-cpp once; open_storage's check would parse it again.
    if (!yaml_error.empty() && is_yaml_file(path)) throw invalid_yaml(path, yaml_error);
    out.stereo = read_opencv_file(path, true);
    return out;
  }
  out.stereo = read_opencv_calibration(path);
  return out;
}

std::shared_ptr<const Rectification> make_rectification(const StereoCalibration& calib,
                                                        cv::Size image_size,
                                                        const std::string& where) {
  core::throw_if_invalid(validate(calib), "invalid calibration " + where);
  // Not image_size.area(): width * height overflows int for a stated size like 2147483647 x 48
  // (found by fuzz_calibration, UBSan).
  const bool size_stated = calib.image_size.width > 0 && calib.image_size.height > 0;
  if (size_stated && calib.image_size != image_size) {
    throw core::InputError("calibration " + where + " is for " +
                           detail::size_text(calib.image_size) + " images, the frames are " +
                           detail::size_text(image_size));
  }
  cv::Mat R1 = calib.R1, R2 = calib.R2, P1 = calib.P1, P2 = calib.P2;
  if (R1.empty()) {
    cv::Mat Q;
    try {
      cv::stereoRectify(calib.M1, calib.D1, calib.M2, calib.D2, image_size, calib.R, calib.T, R1,
                        R2, P1, P2, Q, cv::CALIB_ZERO_DISPARITY, 0.0);
    } catch (const cv::Exception& e) {
      throw core::InputError("cannot rectify with calibration " + where + ": " + e.err);
    }
  }
  const double f = P1.at<double>(0, 0);
  if (std::abs(P2.at<double>(1, 3)) > std::abs(P2.at<double>(0, 3))) {
    throw core::InputError("calibration " + where +
                           " describes a vertical stereo pair; only side-by-side pairs are "
                           "supported");
  }
  auto r = std::make_shared<Rectification>();
  r->camera.width = image_size.width;
  r->camera.height = image_size.height;
  r->camera.focal_px = f;
  r->camera.cx = P1.at<double>(0, 2);
  r->camera.cy = P1.at<double>(1, 2);
  r->camera.baseline_m = -P2.at<double>(0, 3) / P2.at<double>(0, 0);
  if (!(r->camera.baseline_m > 0)) {
    throw core::InputError("calibration " + where +
                           ": the right camera is not to the right of the left one (swap left and "
                           "right)");
  }
  try {
    cv::initUndistortRectifyMap(calib.M1, calib.D1, R1, P1, image_size, CV_16SC2, r->left_map1,
                                r->left_map2);
    cv::initUndistortRectifyMap(calib.M2, calib.D2, R2, P2, image_size, CV_16SC2, r->right_map1,
                                r->right_map2);
  } catch (const cv::Exception& e) {
    throw core::InputError("cannot rectify with calibration " + where + ": " + e.err);
  }
  return r;
}

}  // namespace sg::io
