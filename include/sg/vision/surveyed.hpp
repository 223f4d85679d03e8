#pragma once
/// The per-pixel labelling of the five detectors the thesis surveys (chapter 3, DESIGN 3.4),
/// around the kernels of relative_size.hpp, elevation_map.hpp, sceneflow_seg.hpp and longseq.hpp
/// (motion parallax's is expansion_rate, here). Each writes what the Stereo and Stereo-Flow
/// labellings write (labelling.hpp, scene_flow.hpp): danger (CV_8U, 0/255) and ttc (CV_32F, s,
/// NaN where unknown), allocated here, so that the same clean-up, obstacles, tracking and signals
/// follow (Detector::finish). Pure functions: no threads, no state between frames.
#include <opencv2/core.hpp>

#include "sg/core/camera.hpp"
#include "sg/core/params.hpp"

namespace sg::vision {

/// The expansion rate k of a flow field over the pixels of `mask` (non-zero): the least-squares
/// fit of F(x, y) = (a + k x, b + k y), k = [cov(x, F_x) + cov(y, F_y)] / [var(x) + var(y)], with
/// F the forward flow (-backward) in px per frame. An approach at TTC tau seconds over frames dt
/// apart gives k = dt / tau wherever its focus lies; a translation gives 0. 0 for an empty mask.
double expansion_rate(const cv::Mat& forward_flow, const cv::Mat& mask);

/// Motion parallax: the pixels whose smoothed forward flow (-backward_flow, a box of
/// p.smooth_px) reaches p.flow_min_px_s make blobs (8-connected, at least min_area_px, with the
/// holes they enclose: the flow vanishes at an approaching object's focus of expansion); a blob
/// whose expansion rate k (expansion_rate) gives a TTC = dt_s / k within horizon_s is dangerous,
/// with that TTC. Monocular: no distance, so nothing tells a near slow object from a far fast one
/// of the same TTC, nor whether it passes beside the platform. Throws core::InputError unless
/// backward_flow is a non-empty CV_32FC2 and dt_s > 0.
void label_motion_parallax(const cv::Mat& backward_flow, double dt_s,
                           const core::MotionParallaxParams& p, int min_area_px, double horizon_s,
                           cv::Mat& danger, cv::Mat& ttc);

/// Relative size: the clusters of features expanding from `earlier` to `current` (8-bit grey,
/// span_s seconds apart; expanding_features) with a median scale s give TTC = span_s / (s - 1);
/// a cluster within horizon_s is dangerous over the convex hull of its features, each widened to
/// its template (p.template_px / 2 around it). Monocular, as motion parallax. Throws
/// core::InputError on bad images or span_s <= 0.
void label_relative_size(const cv::Mat& earlier, const cv::Mat& current, double span_s,
                         const core::RelativeSizeParams& p, double horizon_s, cv::Mat& danger,
                         cv::Mat& ttc);

/// Proximity: a pixel whose point (disparity > 0) lies within the envelope's width
/// (|X| <= half_width_m), within its vertical band (y_top_m <= Y <= y_bottom_m) and nearer than
/// p.alarm_distance_m is dangerous, where `allowed` (CV_8U of the disparity's size, or empty for
/// everywhere) is non-zero. ttc is NaN: one frame has no motion (the obstacle tracker's distance
/// fit gives the TTC). Throws core::InputError unless disp is a non-empty CV_32F map.
void label_proximity(const cv::Mat& disp, const cv::Mat& allowed, const core::Camera& cam,
                     const core::Envelope& envelope, const core::ProximityParams& p,
                     cv::Mat& danger, cv::Mat& ttc);

/// Elevation map: the road fitted to the disparity's points (fit_road), the classified grid
/// (build_elevation_map) and the pixels in its obstacle cells (mark_elevation_obstacles), kept
/// where they are near (label_proximity). No road found (no ground in view): nothing is
/// dangerous.
void label_elevation_map(const cv::Mat& disp, const core::Camera& cam,
                         const core::Envelope& envelope, const core::ElevationParams& p,
                         const core::ProximityParams& proximity, cv::Mat& danger, cv::Mat& ttc);

/// Scene-flow segmentation: the motion likelihood of each pixel (motion_likelihood: the
/// disparity now and dt_s earlier, the backward flow between them), cut into moving and static
/// (segment_moving) on a grid of every p.grid_step_px-th pixel (the likelihood and the image
/// averaged over each cell, a missing likelihood counting as xi_static); each moving blob
/// (8-connected, at least min_area_px) takes the median of its pixels' 3D positions and scene
/// flows (point_velocity) and is dangerous when that motion heads into the envelope
/// (heads_into_envelope at p.v_min_mps), with its time to contact. velocity (CV_32FC3, m/s, NaN
/// elsewhere) holds each tested blob's median velocity. Throws core::InputError on a type or
/// size mismatch or dt_s <= 0.
void label_sceneflow_seg(const cv::Mat& left, const cv::Mat& disp, const cv::Mat& disp_prev,
                         const cv::Mat& backward_flow, double dt_s, const core::Camera& cam,
                         const core::Envelope& envelope, const core::SceneFlowSegParams& p,
                         int min_area_px, cv::Mat& danger, cv::Mat& ttc, cv::Mat& velocity);

}  // namespace sg::vision
