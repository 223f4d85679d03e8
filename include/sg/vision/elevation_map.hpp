#pragma once
/// Elevation map (thesis 3.2.1, DESIGN 3.4, after the thesis' [25]): the point cloud of the
/// disparity map, a quadratic road model fitted to its near lower points by RANSAC, and an XZ grid
/// of cells classified by point density (against what a flat road would give the cell) and by
/// height above the road. Meant for platforms on a road or a floor; a drone has no road.
///
/// Camera coordinates (core::Camera): X right, Y down, Z forward, metres. The road is
///   Y = M(X, Z) = a2 X^2 + a1 X + b2 Z^2 + b1 Z + c,
/// so a point's height above the road is M(X, Z) - Y.
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "sg/core/camera.hpp"
#include "sg/core/surveyed_params.hpp"

namespace sg::vision {

using ElevationParams = core::ElevationParams;

using core::validate;

struct RoadModel {
  double a2 = 0.0, a1 = 0.0, b2 = 0.0, b1 = 0.0, c = 0.0;
  int inliers = 0;
  bool found = false;
  /// The road's Y at (X, Z), m.
  double y(double X, double Z) const { return a2 * X * X + a1 * X + b2 * Z * Z + b1 * Z + c; }
};

/// Fits the road to the fit region's points (ElevationParams: fit_*, iterations, tolerance_m,
/// min_inliers, seed): RANSAC over 5-point samples, then a least-squares refit to the inliers.
/// found = false when too few points or inliers. Throws core::InputError unless disp is CV_32F.
RoadModel fit_road(const cv::Mat& disp, const core::Camera& cam, const ElevationParams& p);

/// Cell classes.
enum class Cell : std::uint8_t { kEmpty = 0, kRoad = 1, kSmallObstacle = 2, kObstacle = 3 };

/// The grid: row r covers Z in (r L, (r + 1) L], column c covers X in [-half_width + c L, ...).
struct ElevationMap {
  double cell_m = 0.5, half_width_m = 5.0;
  cv::Mat count;     ///< CV_32S, points per cell
  cv::Mat expected;  ///< CV_32F, points a flat road would give the cell (Erd)
  cv::Mat height;    ///< CV_32F, mean height above the road, m (NaN where empty)
  cv::Mat cell;      ///< CV_8U, Cell
  /// The cell of (X, Z); false outside the grid.
  bool locate(double X, double Z, int& row, int& col) const;
};

/// Builds and classifies the grid (thesis' two classifiers fused): obstacle when the mean height
/// exceeds height_min_m or the density reaches density_ratio times the road's; small obstacle
/// (a traffic isle) when above the road but neither; road otherwise; empty with fewer than
/// min_points points. `road` must be found.
ElevationMap build_elevation_map(const cv::Mat& disp, const core::Camera& cam,
                                 const RoadModel& road, const ElevationParams& p);

/// 255 where a pixel's point lies in an obstacle cell and above the road by more than the fit's
/// tolerance; CV_8U, allocated.
void mark_elevation_obstacles(const cv::Mat& disp, const core::Camera& cam, const RoadModel& road,
                              const ElevationMap& map, const ElevationParams& p, cv::Mat& mask);

}  // namespace sg::vision
