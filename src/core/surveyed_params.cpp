#include "sg/core/surveyed_params.hpp"

#include <cmath>

#include "sg/core/checker.hpp"

namespace sg::core {

std::vector<std::string> validate(const MotionParallaxParams& p) {
  std::vector<std::string> out;
  Checker c(out, "motion_parallax");
  c.require(p.smooth_px >= 1 && p.smooth_px <= 63 && p.smooth_px % 2 == 1, "smooth_px",
            p.smooth_px, "must be odd and in 1..63 (px)");
  c.require(std::isfinite(p.flow_min_px_s) && p.flow_min_px_s > 0.0, "flow_min_px_s",
            p.flow_min_px_s, "must be > 0 (px/s)");
  return out;
}

std::vector<std::string> validate(const ProximityParams& p) {
  std::vector<std::string> out;
  Checker c(out, "proximity");
  c.require(std::isfinite(p.alarm_distance_m) && p.alarm_distance_m > 0.0, "alarm_distance_m",
            p.alarm_distance_m, "must be > 0 (m)");
  return out;
}

std::vector<std::string> validate(const ElevationParams& p) {
  std::vector<std::string> out;
  Checker c(out, "elevation");
  auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  c.require(p.sample_step_px >= 1 && p.sample_step_px <= 64, "sample_step_px", p.sample_step_px,
            "must be in 1..64");
  c.require(positive(p.fit_z_min_m), "fit_z_min_m", p.fit_z_min_m, "must be > 0 (m)");
  c.require(positive(p.fit_z_max_m) && p.fit_z_max_m > p.fit_z_min_m, "fit_z_max_m",
            p.fit_z_max_m, "must be > fit_z_min_m (m)");
  c.require(std::isfinite(p.fit_y_min_m), "fit_y_min_m", p.fit_y_min_m, "must be finite (m)");
  c.require(p.iterations >= 1 && p.iterations <= 100000, "iterations", p.iterations,
            "must be in 1..100000");
  c.require(positive(p.tolerance_m), "tolerance_m", p.tolerance_m, "must be > 0 (m)");
  c.require(p.min_inliers >= 5, "min_inliers", p.min_inliers, "must be >= 5");
  c.require(positive(p.cell_m), "cell_m", p.cell_m, "must be > 0 (m)");
  c.require(positive(p.half_width_m), "half_width_m", p.half_width_m, "must be > 0 (m)");
  c.require(positive(p.z_max_m), "z_max_m", p.z_max_m, "must be > 0 (m)");
  c.require(!positive(p.cell_m) || !positive(p.half_width_m) || !positive(p.z_max_m) ||
                (2.0 * p.half_width_m / p.cell_m) * (p.z_max_m / p.cell_m) <= 4.0e6,
            "cell_m", p.cell_m, "makes more than 4e6 cells of the grid");
  c.require(positive(p.height_min_m), "height_min_m", p.height_min_m, "must be > 0 (m)");
  c.require(std::isfinite(p.density_ratio) && p.density_ratio > 1.0, "density_ratio",
            p.density_ratio, "must be > 1");
  c.require(p.min_points >= 1, "min_points", p.min_points, "must be >= 1");
  return out;
}

std::vector<std::string> validate(const SceneFlowSegParams& p) {
  std::vector<std::string> out;
  Checker c(out, "sceneflow_seg");
  auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  c.require(positive(p.sigma_disparity_px), "sigma_disparity_px", p.sigma_disparity_px,
            "must be > 0 (px)");
  c.require(positive(p.sigma_flow_px), "sigma_flow_px", p.sigma_flow_px, "must be > 0 (px)");
  c.require(positive(p.sigma_change_px), "sigma_change_px", p.sigma_change_px,
            "must be > 0 (px)");
  c.require(std::isfinite(p.xi_static) && p.xi_static >= 0.0, "xi_static", p.xi_static,
            "must be >= 0");
  c.require(std::isfinite(p.lambda) && p.lambda >= 0.0, "lambda", p.lambda, "must be >= 0");
  c.require(positive(p.contrast_a), "contrast_a", p.contrast_a, "must be > 0 (grey levels)");
  c.require(p.grid_step_px >= 1 && p.grid_step_px <= 16, "grid_step_px", p.grid_step_px,
            "must be in 1..16 (px)");
  c.require(std::isfinite(p.v_min_mps) && p.v_min_mps >= 0.0, "v_min_mps", p.v_min_mps,
            "must be >= 0 (m/s)");
  return out;
}

std::vector<std::string> validate(const RelativeSizeParams& p) {
  std::vector<std::string> out;
  Checker c(out, "relative_size");
  auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  c.require(p.max_features >= 10 && p.max_features <= 100000, "max_features", p.max_features,
            "must be in 10..100000");
  c.require(positive(p.ratio_test) && p.ratio_test <= 1.0, "ratio_test", p.ratio_test,
            "must be in (0, 1]");
  c.require(p.template_px >= 4 && p.template_px <= 128, "template_px", p.template_px,
            "must be in 4..128 (px)");
  c.require(positive(p.patch_factor), "patch_factor", p.patch_factor, "must be > 0");
  c.require(std::isfinite(p.scale_max) && p.scale_max > 1.0 && p.scale_max <= 4.0, "scale_max",
            p.scale_max, "must be in (1, 4]");
  c.require(positive(p.scale_step) && p.scale_step <= 0.1, "scale_step", p.scale_step,
            "must be in (0, 0.1]");
  c.require(std::isfinite(p.s_min) && p.s_min > 1.0, "s_min", p.s_min, "must be > 1");
  c.require(positive(p.max_error), "max_error", p.max_error, "must be > 0 (grey levels)");
  c.require(positive(p.cluster_radius_px), "cluster_radius_px", p.cluster_radius_px,
            "must be > 0 (px)");
  c.require(p.cluster_min >= 1, "cluster_min", p.cluster_min, "must be >= 1");
  c.require(p.gap_frames >= 1 && p.gap_frames <= 120, "gap_frames", p.gap_frames,
            "must be in 1..120 (camera frames)");
  return out;
}

}  // namespace sg::core
