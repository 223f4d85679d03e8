#pragma once
/// Ego-motion of the camera between two frames from the backward flow and the disparity, so that
/// the Stereo-Flow labelling can remove the camera's own rotation (a robot turning in place sees
/// every static point sweep sideways).
#include <opencv2/core.hpp>

#include "sg/core/camera.hpp"

namespace sg::vision {

struct EgoMotionParams {
  int sample_step_px = 8;  ///< fit on every n-th row and column, >= 1
  int iterations = 6;      ///< reweighting rounds (Huber), >= 1
  double huber_px = 0.5;   ///< flow residual beyond which a sample is down-weighted, px, > 0
  int min_samples = 100;   ///< fewer valid samples: no estimate
};

/// Motion of a static point between frame i and frame i-1 to first order:
/// P_{i-1} = P_i + rotation x P_i + translation (camera frames, m; rotation in rad, small).
struct EgoMotion {
  cv::Vec3d rotation{0, 0, 0};     ///< rad per frame; +Y (yaw) = the camera turns right
  cv::Vec3d translation{0, 0, 0};  ///< m per frame
  int samples = 0;                 ///< samples used
  bool valid = false;              ///< enough samples for an estimate
};

/// Robust least-squares fit of the instantaneous motion model to the backward flow B_i (CV_32FC2,
/// frame i -> i-1) at pixels with a valid disparity D_i (CV_32F, invalid < 0): with x = u - cx,
/// y = v - cy and rho = D_i / (f B) (1 / Z),
///   B_u = -x y / f w_x + (f + x^2 / f) w_y - y w_z + f rho T_x - x rho T_z
///   B_v = -(f + y^2 / f) w_x + x y / f w_y + x w_z + f rho T_y - y rho T_z.
/// Given the depth the model is linear in (w, T): rotation flow does not depend on depth, so far
/// and near points separate it from translation. Moving objects are outliers (Huber weights).
EgoMotion estimate_ego_motion(const cv::Mat& flow, const cv::Mat& disp, const core::Camera& cam,
                              const EgoMotionParams& p = {});

/// The rotation that turns camera i-1 coordinates into camera i's orientation (removes the
/// camera's rotation, keeps its translation): R^T with R = Rodrigues(m.rotation); identity when
/// the estimate is not valid.
cv::Matx33d derotation(const EgoMotion& m);

}  // namespace sg::vision
