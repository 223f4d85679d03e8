#include "sg/io/dump.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "sg/core/error.hpp"

namespace sg::io {
namespace {

namespace fs = std::filesystem;

/// The Middlebury colour wheel: 55 RGB hues from red through yellow, green, cyan, blue, magenta.
std::vector<cv::Vec3d> make_color_wheel() {
  const int kRY = 15, kYG = 6, kGC = 4, kCB = 11, kBM = 13, kMR = 6;
  std::vector<cv::Vec3d> wheel;
  for (int i = 0; i < kRY; ++i) wheel.push_back({255, 255.0 * i / kRY, 0});
  for (int i = 0; i < kYG; ++i) wheel.push_back({255 - 255.0 * i / kYG, 255, 0});
  for (int i = 0; i < kGC; ++i) wheel.push_back({0, 255, 255.0 * i / kGC});
  for (int i = 0; i < kCB; ++i) wheel.push_back({0, 255 - 255.0 * i / kCB, 255});
  for (int i = 0; i < kBM; ++i) wheel.push_back({255.0 * i / kBM, 0, 255});
  for (int i = 0; i < kMR; ++i) wheel.push_back({255, 0, 255 - 255.0 * i / kMR});
  return wheel;
}

/// BGR colour of the flow vector (u, v) already divided by the colour scale.
cv::Vec3b wheel_color(const std::vector<cv::Vec3d>& wheel, double u, double v) {
  const int n = static_cast<int>(wheel.size());
  const double rad = std::sqrt(u * u + v * v);
  const double a = std::atan2(-v, -u) / CV_PI;
  const double fk = (a + 1.0) / 2.0 * (n - 1);
  const int k0 = static_cast<int>(fk);
  const int k1 = (k0 + 1) % n;
  const double f = fk - k0;
  cv::Vec3b out;
  for (int c = 0; c < 3; ++c) {  // c: R, G, B
    double col = ((1 - f) * wheel[k0][c] + f * wheel[k1][c]) / 255.0;
    col = rad <= 1 ? 1 - rad * (1 - col) : col * 0.75;  // saturation grows with the magnitude
    out[2 - c] = cv::saturate_cast<uchar>(255.0 * col);
  }
  return out;
}

}  // namespace

cv::Mat colorize_disparity(const cv::Mat& disparity, double max_disparity_px) {
  CV_Assert(disparity.type() == CV_32F && max_disparity_px > 0);
  cv::Mat gray;
  disparity.convertTo(gray, CV_8U, 255.0 / max_disparity_px);  // saturates above the maximum
  cv::Mat color;
  cv::applyColorMap(gray, color, cv::COLORMAP_TURBO);
  color.setTo(cv::Scalar::all(0), disparity < 0);
  return color;
}

cv::Mat colorize_flow(const cv::Mat& flow, double max_radius_px) {
  CV_Assert(flow.type() == CV_32FC2);
  static const std::vector<cv::Vec3d> wheel = make_color_wheel();
  const double scale = max_radius_px > 0 ? max_radius_px : flow_color_scale(flow);
  cv::Mat color(flow.size(), CV_8UC3);
  for (int y = 0; y < flow.rows; ++y) {
    const cv::Vec2f* in = flow.ptr<cv::Vec2f>(y);
    cv::Vec3b* out = color.ptr<cv::Vec3b>(y);
    for (int x = 0; x < flow.cols; ++x) {
      const double u = in[x][0], v = in[x][1];
      out[x] = std::isfinite(u) && std::isfinite(v) ? wheel_color(wheel, u / scale, v / scale)
                                                    : cv::Vec3b(0, 0, 0);
    }
  }
  return color;
}

double flow_color_scale(const cv::Mat& flow, const cv::Mat& mask) {
  CV_Assert(flow.type() == CV_32FC2 && (mask.empty() || mask.size() == flow.size()));
  double scale = 1.0;
  for (int y = 0; y < flow.rows; ++y) {
    const cv::Vec2f* in = flow.ptr<cv::Vec2f>(y);
    const uchar* m = mask.empty() ? nullptr : mask.ptr<uchar>(y);
    for (int x = 0; x < flow.cols; ++x) {
      if (m && !m[x]) continue;
      const double r = std::hypot(in[x][0], in[x][1]);
      if (std::isfinite(r)) scale = std::max(scale, r);
    }
  }
  return scale;
}

DumpWriter::DumpWriter(const fs::path& dir, double max_disparity_px)
    : dir_(dir), max_disparity_px_(max_disparity_px) {
  std::error_code ec;
  if (fs::exists(dir_, ec) && !fs::is_directory(dir_, ec)) {
    throw core::InputError("--dump " + dir_.string() + ": exists and is not a directory");
  }
  fs::create_directories(dir_, ec);
  if (ec || !fs::is_directory(dir_)) {
    throw core::InputError("--dump " + dir_.string() + ": cannot create the directory (" +
                           ec.message() + ")");
  }
}

fs::path DumpWriter::path(const std::string& kind, int frame) const {
  char name[64];
  std::snprintf(name, sizeof name, "%s_%06d.png", kind.c_str(), frame);
  return dir_ / name;
}

void DumpWriter::write_png(const fs::path& file, const cv::Mat& image) const {
  bool ok = false;
  try {
    ok = cv::imwrite(file.string(), image);
  } catch (const cv::Exception&) {
    ok = false;
  }
  if (!ok) throw core::InputError("--dump: cannot write " + file.string());
}

void DumpWriter::write(const core::Detection& d) {
  if (!d.disparity.empty()) {
    write_png(path("disparity", d.frame), colorize_disparity(d.disparity, max_disparity_px_));
  }
  if (!d.flow.empty()) {
    const cv::Mat valid = d.disparity.empty() ? cv::Mat() : cv::Mat(d.disparity >= 0);
    write_png(path("flow", d.frame), colorize_flow(d.flow, flow_color_scale(d.flow, valid)));
  }
  if (!d.danger.empty()) write_png(path("danger", d.frame), d.danger);
}

}  // namespace sg::io
