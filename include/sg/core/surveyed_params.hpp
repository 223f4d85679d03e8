#pragma once
/// Parameters of the detectors the thesis surveys (chapter 3, DESIGN 3.4), beside ours: plain
/// aggregates with defaults, units in the comments, validated by name like params.hpp. The kernels
/// that use them live in sg::vision (relative_size.hpp, elevation_map.hpp, sceneflow_seg.hpp,
/// longseq.hpp) and the labelling around them in vision/surveyed.hpp.
#include <cstdint>
#include <string>
#include <vector>

namespace sg::core {

/// Motion parallax (vision/surveyed.hpp): moving blobs of the flow
/// and the expansion rate of each.
struct MotionParallaxParams {
  /// The flow is averaged over a box of this side before anything else, px, odd, 1..63.
  int smooth_px = 9;
  /// A pixel moves when its smoothed flow reaches this speed, px/s (0.2 px a frame at 30 fps).
  double flow_min_px_s = 6.0;
};

/// Proximity labelling (elevation-map and longseq detectors): a point is dangerous when it lies
/// within the envelope's width and vertical band and nearer than this.
struct ProximityParams {
  double alarm_distance_m = 4.0;  ///< m, > the envelope's z_contact_m
};

struct ElevationParams {
  int sample_step_px = 2;      ///< every n-th row and column makes the point cloud, >= 1
  // The road fit: points of the cloud in front of and below the camera (the thesis' "cubic region
  // with small Z and small Y").
  double fit_z_min_m = 1.0;    ///< nearest fitted point, m
  double fit_z_max_m = 12.0;   ///< farthest fitted point, m
  double fit_y_min_m = 0.2;    ///< fitted points lie at least this far below the optical axis, m
  int iterations = 300;        ///< RANSAC samples of 5 points, >= 1
  double tolerance_m = 0.04;   ///< inlier distance to the road (vertical), m
  int min_inliers = 100;       ///< fewer inliers: no road found
  std::uint64_t seed = 12345;  ///< fixed RANSAC seed (reproducible)
  // The grid.
  double cell_m = 0.5;        ///< side L of a square XZ cell, m
  double half_width_m = 5.0;  ///< the grid spans X in [-half_width, half_width], m
  double z_max_m = 20.0;      ///< and Z in (0, z_max], m
  double height_min_m = 0.25;  ///< Delta h: a cell's mean height above this is an obstacle, m
  /// Th: a cell holding at least this many times the points a flat road would give it is an
  /// obstacle (a surface facing the camera projects many more pixels into one cell than the road).
  double density_ratio = 3.0;
  int min_points = 6;  ///< a cell with fewer points is empty (no evidence either way)
};

struct SceneFlowSegParams {
  double sigma_disparity_px = 0.25;  ///< s_d: the disparity's standard deviation, px
  double sigma_flow_px = 0.5;        ///< s_u = s_v: the flow's, px
  double sigma_change_px = 0.35;     ///< s_c: the disparity change's, px
  double xi_static = 2.8;  ///< the static label's likelihood: sqrt(7.81), chi-square(3) at 95 %
  double lambda = 6.0;     ///< weight of the smoothness term
  /// a: keeps the smoothness finite across equal intensities, grey levels
  double contrast_a = 4.0;
  /// The detector cuts a grid of every grid_step_px-th pixel (the likelihood averaged over each
  /// cell): a full VGA grid is 300k nodes and 1.2M edges. 1..16.
  int grid_step_px = 4;
  /// A moving blob is dangerous when its median scene flow heads into the envelope
  /// (heads_into_envelope) approaching at least this fast, m/s.
  double v_min_mps = 0.3;
};

struct RelativeSizeParams {
  int max_features = 800;       ///< ORB features per frame
  double ratio_test = 0.8;      ///< Lowe's ratio: best Hamming distance / second best
  int template_px = 20;         ///< side of the resampled template grid (the thesis' 20 x 20), px
  double patch_factor = 1.2;    ///< template side = feature size * patch_factor, px
  double scale_max = 1.5;       ///< scales searched: 1 / scale_max .. scale_max
  double scale_step = 0.01;     ///< search step of the scale, before a parabolic refinement
  double s_min = 1.05;          ///< a feature expands when its scale reaches this (per frame)
  double max_error = 40.0;      ///< mean absolute template error above this: no scale, grey levels
  double cluster_radius_px = 60.0;  ///< features within this distance form a cluster, px
  int cluster_min = 4;              ///< expanding features a cluster needs to be an obstacle
  /// The detector compares frame i with the frame this many camera frames back (or the oldest
  /// kept after drops): one frame's growth is too small to see at a distance (an object 3 s away
  /// grows by 1 % a frame at 30 fps, by 11 % over 10 frames). Its TTC = span / (s - 1).
  int gap_frames = 10;
};

/// Each invalid field, by name ("<section>.<field>=<value>: <rule>"); empty when valid.
std::vector<std::string> validate(const MotionParallaxParams& p);
std::vector<std::string> validate(const ProximityParams& p);
std::vector<std::string> validate(const ElevationParams& p);
std::vector<std::string> validate(const SceneFlowSegParams& p);
std::vector<std::string> validate(const RelativeSizeParams& p);

}  // namespace sg::core
