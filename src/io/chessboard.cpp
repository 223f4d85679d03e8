// Chessboard stereo calibration, as in OpenCV's samples/cpp/stereo_calib.cpp.
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "gray.hpp"
#include "sg/core/error.hpp"
#include "sg/io/calibration.hpp"

namespace sg::io {
namespace fs = std::filesystem;
namespace {

std::vector<cv::Point2f> find_corners(const cv::Mat& gray, cv::Size board) {
  std::vector<cv::Point2f> corners;
  const bool found = cv::findChessboardCorners(
      gray, board, corners, cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE);
  if (!found) return {};
  cv::cornerSubPix(gray, corners, cv::Size(11, 11), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 30, 0.01));
  return corners;
}

/// Mean distance of each corner to the epipolar line of its partner, px (both directions).
double epipolar_error(const std::vector<std::vector<cv::Point2f>>& left,
                      const std::vector<std::vector<cv::Point2f>>& right,
                      const StereoCalibration& c, const cv::Mat& F) {
  double sum = 0;
  size_t count = 0;
  for (size_t i = 0; i < left.size(); ++i) {
    std::vector<cv::Point2f> l, r;
    cv::undistortPoints(left[i], l, c.M1, c.D1, cv::noArray(), c.M1);
    cv::undistortPoints(right[i], r, c.M2, c.D2, cv::noArray(), c.M2);
    std::vector<cv::Vec3f> lines_l, lines_r;
    cv::computeCorrespondEpilines(l, 1, F, lines_l);
    cv::computeCorrespondEpilines(r, 2, F, lines_r);
    for (size_t j = 0; j < l.size(); ++j) {
      sum += std::abs(r[j].x * lines_l[j][0] + r[j].y * lines_l[j][1] + lines_l[j][2]) +
             std::abs(l[j].x * lines_r[j][0] + l[j].y * lines_r[j][1] + lines_r[j][2]);
      count += 2;
    }
  }
  return count ? sum / static_cast<double>(count) : 0.0;
}

}  // namespace

std::vector<std::string> validate(const ChessboardParams& p) {
  std::vector<std::string> out;
  if (p.board.width < 2 || p.board.height < 2) {
    out.push_back("board=" + std::to_string(p.board.width) + "x" + std::to_string(p.board.height) +
                  ": needs at least 2x2 inner corners");
  }
  if (!(std::isfinite(p.square_m) && p.square_m > 0)) {
    out.push_back("square=" + std::to_string(p.square_m) + ": must be a positive length, m");
  }
  return out;
}

ChessboardResult calibrate_chessboard(const std::vector<fs::path>& left,
                                      const std::vector<fs::path>& right,
                                      const ChessboardParams& params) {
  core::throw_if_invalid(validate(params), "invalid calibrate options");
  if (left.empty()) throw core::InputError("no chessboard images given");
  if (left.size() != right.size()) {
    throw core::InputError("left has " + std::to_string(left.size()) + " images, right has " +
                           std::to_string(right.size()));
  }
  ChessboardResult result;
  std::vector<std::vector<cv::Point2f>> corners_l, corners_r;
  cv::Size size;
  for (size_t i = 0; i < left.size(); ++i) {
    const cv::Mat l = detail::read_gray(left[i]);
    const cv::Mat r = detail::read_gray(right[i]);
    if (size.area() == 0) size = l.size();
    detail::check_size(l, size, left[i].string(), "the first image");
    detail::check_size(r, size, right[i].string(), "the first image");
    auto cl = find_corners(l, params.board);
    auto cr = cl.empty() ? std::vector<cv::Point2f>{} : find_corners(r, params.board);
    if (cl.empty() || cr.empty()) {
      result.skipped.push_back(left[i].filename().string() + " / " + right[i].filename().string());
      continue;
    }
    corners_l.push_back(std::move(cl));
    corners_r.push_back(std::move(cr));
  }
  result.pairs_used = static_cast<int>(corners_l.size());
  if (result.pairs_used < 3) {
    throw core::InputError("the " + std::to_string(params.board.width) + "x" +
                           std::to_string(params.board.height) + " board was found in only " +
                           std::to_string(result.pairs_used) +
                           " image pairs; calibration needs at least 3");
  }
  std::vector<cv::Point3f> board_points;
  for (int y = 0; y < params.board.height; ++y)
    for (int x = 0; x < params.board.width; ++x)
      board_points.emplace_back(static_cast<float>(x * params.square_m),
                                static_cast<float>(y * params.square_m), 0.f);
  const std::vector<std::vector<cv::Point3f>> object(corners_l.size(), board_points);

  StereoCalibration& c = result.calib;
  c.image_size = size;
  c.M1 = cv::initCameraMatrix2D(object, corners_l, size, 0);
  c.M2 = cv::initCameraMatrix2D(object, corners_r, size, 0);
  cv::Mat E, F;
  result.rms_px = cv::stereoCalibrate(
      object, corners_l, corners_r, c.M1, c.D1, c.M2, c.D2, size, c.R, c.T, E, F,
      cv::CALIB_FIX_ASPECT_RATIO | cv::CALIB_ZERO_TANGENT_DIST | cv::CALIB_USE_INTRINSIC_GUESS |
          cv::CALIB_SAME_FOCAL_LENGTH | cv::CALIB_RATIONAL_MODEL | cv::CALIB_FIX_K3 |
          cv::CALIB_FIX_K4 | cv::CALIB_FIX_K5,
      cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-5));
  result.epipolar_px = epipolar_error(corners_l, corners_r, c, F);
  cv::stereoRectify(c.M1, c.D1, c.M2, c.D2, size, c.R, c.T, c.R1, c.R2, c.P1, c.P2, c.Q,
                    cv::CALIB_ZERO_DISPARITY, 0.0);
  return result;
}

}  // namespace sg::io
