#pragma once
/// Stereo calibration files and rectification (docs/inputs.md, "Calibration").
///
/// Conventions are OpenCV's (stereoCalibrate / stereoRectify): M1, M2 are 3x3 camera matrices, D1,
/// D2 distortion coefficients (radial-tangential, 4, 5, 8, 12 or 14 numbers), and a point X1 in the
/// left camera frame is X2 = R * X1 + T in the right camera frame; T is in metres when the
/// calibration pattern was measured in metres. The rectified pair is horizontal: the right camera
/// lies to the right of the left one (T.x < 0 before rectification).
#include <filesystem>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "sg/core/camera.hpp"

namespace sg::io {

/// A raw (unrectified) stereo calibration. All matrices CV_64F.
struct StereoCalibration {
  cv::Size image_size;     ///< size the calibration was made for, px; (0,0) = not stated
  cv::Mat M1, D1, M2, D2;  ///< camera matrices (3x3) and distortion rows (1xN)
  cv::Mat R, T;            ///< rotation (3x3) and translation (3x1, m) from left to right camera
  /// Optional rectification (stereoRectify output): when R1, R2, P1, P2 are all present they are
  /// used as given; else they are computed. Q is kept for the record only.
  cv::Mat R1, R2, P1, P2, Q;
  double fps = 0.0;  ///< nominal frame rate the file states (EuRoC rate_hz), Hz; 0 = not stated
};

/// What a calibration file says about a stream: either the images are already rectified and
/// `camera` is all that depth needs, or they must be rectified with `stereo`.
struct Calibration {
  std::optional<core::Camera> rectified;    ///< focal, baseline, cx, cy (fps when the file has it)
  std::optional<StereoCalibration> stereo;  ///< raw calibration to rectify with
};

/// Every problem as text ("calib.M1: not invertible", "calib.D2: not finite", ...); empty when
/// valid. Checks shapes, finiteness, invertible camera matrices, R a rotation, T non-zero, and the
/// optional R1 R2 P1 P2 (all or none, right shapes, finite).
std::vector<std::string> validate(const StereoCalibration& calib);

/// OpenCV FileStorage YAML or XML with M1 D1 M2 D2 R T (and optionally R1 R2 P1 P2 Q,
/// image_width, image_height). Throws core::InputError naming the file and the missing or bad
/// field.
StereoCalibration read_opencv_calibration(const std::filesystem::path& path);
/// Writes the fields read_opencv_calibration reads (plus image_width/image_height).
void write_opencv_calibration(const std::filesystem::path& path, const StereoCalibration& calib);

/// KITTI calib_cam_to_cam.txt. KITTI raw "synced+rectified" images are already rectified, so this
/// gives the rectified camera of the pair (`left_cam`, `right_cam`) = (0, 1) gray or (2, 3)
/// colour from P_rect_0X and S_rect_0X: focal P(0,0), centre P(0,2), P(1,2), baseline
/// (P_left(0,3) - P_right(0,3)) / focal. fps is left 0. Throws InputError naming the file and key.
core::Camera read_kitti_calibration(const std::filesystem::path& path, int left_cam, int right_cam);

/// EuRoC cam0/sensor.yaml + cam1/sensor.yaml (intrinsics fu fv cu cv, radial-tangential
/// distortion, T_BS body-from-sensor 4x4, resolution, rate_hz). R, T come from
/// T_BS1^-1 * T_BS0. Throws InputError naming the file and field.
StereoCalibration read_euroc_calibration(const std::filesystem::path& left_yaml,
                                         const std::filesystem::path& right_yaml);

/// Any calibration file `--calib` accepts, told apart by content: a stereoguard camera.yaml
/// (focal_px, ...: rectified), an OpenCV stereo calibration (M1, ...: raw) or a KITTI
/// calib_cam_to_cam.txt (rectified, cameras 0 and 1, or 2 and 3 when `kitti_color`).
Calibration read_calibration(const std::filesystem::path& path, bool kitti_color = false);

/// Rectification maps for one image size, computed once (initUndistortRectifyMap, fixed-point
/// CV_16SC2 maps) and shared read-only by every frame.
struct Rectification {
  cv::Mat left_map1, left_map2, right_map1, right_map2;
  core::Camera camera;  ///< the rectified camera: focal, cx, cy from P1; baseline from P2; size
};

/// Validates `calib` (InputError listing its problems), checks that `image_size` matches the
/// calibration's when it states one, runs stereoRectify (CALIB_ZERO_DISPARITY, alpha 0: only valid
/// pixels) unless R1..P2 are given, and builds the maps. fps of the camera is left to the caller.
/// Throws InputError when the rectified pair is vertical or the right camera is on the left.
std::shared_ptr<const Rectification> make_rectification(const StereoCalibration& calib,
                                                        cv::Size image_size,
                                                        const std::string& where);

/// Chessboard stereo calibration (`stereoguard calibrate`).
struct ChessboardParams {
  cv::Size board{9, 6};     ///< inner corners per row and column
  double square_m = 0.025;  ///< side of one square, m (sets the unit of T and the baseline)
};
std::vector<std::string> validate(const ChessboardParams& params);

struct ChessboardResult {
  StereoCalibration calib;           ///< with R1 R2 P1 P2 Q from stereoRectify
  double rms_px = 0.0;               ///< stereoCalibrate RMS reprojection error, px
  double epipolar_px = 0.0;          ///< mean |distance| of corners to their epipolar lines, px
  int pairs_used = 0;                ///< pairs where both views showed the whole board
  std::vector<std::string> skipped;  ///< image pairs without a board found in both views
};

/// Finds the board in each pair (findChessboardCorners + cornerSubPix), then stereoCalibrate and
/// stereoRectify. Throws InputError for unreadable images, sizes that differ, or fewer than 3
/// usable pairs.
ChessboardResult calibrate_chessboard(const std::vector<std::filesystem::path>& left,
                                      const std::vector<std::filesystem::path>& right,
                                      const ChessboardParams& params);

}  // namespace sg::io
