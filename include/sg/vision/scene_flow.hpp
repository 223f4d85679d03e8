#pragma once
/// Stereo-Flow labelling (DESIGN 3.2): the 3D motion of each pixel, from the current disparity, the
/// backward flow and a past disparity, heads into the safety envelope or not.
#include <cstdint>
#include <limits>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "sg/core/camera.hpp"
#include "sg/core/params.hpp"

namespace sg::vision {

// The labelling settings live in core (DetectorParams.scene_flow).
using core::GroundParams;
using core::SceneFlowParams;
using core::validate;

/// Bilinear sample of a CV_32F disparity map (invalid < 0) at (x, y), px. Neighbours with zero
/// weight are not used (so integer coordinates read one pixel, and x = w-1 is inside). False when
/// (x, y) is outside [0, w-1] x [0, h-1] or not finite, when a neighbour used is invalid, or when
/// the neighbours used differ by more than max_step px (a depth edge). `out` is untouched on false.
bool sample_disparity_bilinear(const cv::Mat& disp, float x, float y, float& out,
                               float max_step = std::numeric_limits<float>::infinity());

/// Bilinear sample of a CV_32FC2 flow at (x, y), px, same rules as sample_disparity_bilinear
/// (a neighbour with a non-finite component is invalid).
bool sample_flow_bilinear(const cv::Mat& flow, float x, float y, cv::Vec2f& out);

/// 3D velocity relative to the camera, m/s, of the point seen at p with disparity d_cur now and
/// at q with disparity d_prev `dt` seconds earlier: V = (P(p, d_cur) - P(q, d_prev)) / dt.
/// position = P(p, d_cur), m. False (outputs untouched) when a disparity is <= 0 or dt <= 0.
bool point_velocity(cv::Point2f p, float d_cur, cv::Point2f q, float d_prev,
                    const core::Camera& camera, double dt, cv::Vec3d& velocity,
                    cv::Point3d& position);

/// DESIGN 3.2: the point P moving at V (m, m/s) approaches (V_z <= -v_min) and at
/// t_c = (P_z - z_contact) / (-V_z), with 0 < t_c <= horizon, lies inside the envelope:
/// |X(t_c)| <= half_width, y_top <= Y(t_c) <= y_bottom. t_contact = t_c, s, when true.
bool heads_into_envelope(const cv::Point3d& P, const cv::Vec3d& V, const core::Envelope& e,
                         double v_min, double& t_contact);

/// heads_into_envelope for a platform turning at yaw_rate_rps (rad/s, + = the camera turns right,
/// +Z towards +X; 0 = heads_into_envelope itself). V is the point's velocity without the camera's
/// rotation (the derotated fit); in the camera's frame the point then circles the fixed point C
/// of dP/dt = V - w (P_z, 0, -P_x), C = (-V_z / w, V_x / w) in (X, Z), while Y moves at V_y.
/// True when V_z <= -v_min, P_z > z_contact and the point's first crossing of the contact plane
/// Z = z_contact, at t_c <= horizon, lies inside the envelope; t_contact = t_c, s. A static point
/// beside a bend thus passes the platform, which follows the bend, and one on the arc ahead
/// does not.
bool heads_into_envelope_turning(const cv::Point3d& P, const cv::Vec3d& V, double yaw_rate_rps,
                                 const core::Envelope& e, double v_min, double& t_contact);

/// 255 where p lies within margin_px of a depth edge: the largest and smallest valid (>= 0)
/// disparities of the (2 margin + 1)^2 window around p differ by more than step_px; 0 elsewhere
/// (everywhere when margin_px <= 0). disp: CV_32F, invalid < 0; mask: CV_8U, allocated.
void mark_depth_edges(const cv::Mat& disp, int margin_px, double step_px, cv::Mat& mask);

/// Gap-1 Stereo-Flow labelling of frame i. disp_cur = D_i, disp_prev = D_{i-1} (CV_32F, invalid
/// < 0), flow = B_i (CV_32FC2 backward flow i -> i-1), all the same size; dt = frame period, s.
/// A pixel p is a candidate when D_i(p) > 0, Z_i <= z_max, p is not within edge_margin_px of a
/// depth edge of D_i (mark_depth_edges) and, with use_envelope_band, y_top <= Y_i <= y_bottom.
/// A candidate's velocity is known when q = p + B_i(p) samples D_{i-1}(q) > 0 bilinearly (with
/// max_disparity_step_px); it is dangerous when moreover D_i(p) - D_{i-1}(q) >= min_delta_d_px,
/// |V| <= max_speed, round(q) is not within edge_margin_px of a depth edge of D_{i-1}, and
/// heads_into_envelope. p.gaps is not used. Outputs (allocated): danger CV_8U 0/255; ttc CV_32F
/// s, NaN where safe; velocity CV_32FC3 m/s, NaN where unknown or not a candidate.
void label_stereo_flow(const cv::Mat& disp_cur, const cv::Mat& disp_prev, const cv::Mat& flow,
                       const core::Camera& cam, const core::Envelope& env, const SceneFlowParams& p,
                       double dt, cv::Mat& danger, cv::Mat& ttc, cv::Mat& velocity);

/// Stereo-Flow labelling over several frame gaps (sampled_gaps(p)). past_disps[j] = D_{i-1-j} and
/// past_flows[j] = B_{i-j} (newest first: past_flows[0] is the current frame's flow). For gap k
/// the point is followed back along the chained flow q_0 = p, q_{m+1} = q_m + B_{i-m}(q_m)
/// (bilinear) to q_k, and V = (P_i(p) - P_{i-k}(q_k, D_{i-k}(q_k))) / (k dt); the test is that of
/// label_stereo_flow. A gap needs k past disparities and k flows; longer gaps are skipped. With
/// p.longest_gap_decides the longest gap that knows the pixel's velocity gives its verdict, TTC
/// and velocity. Otherwise a pixel flagged by any gap is dangerous; its TTC is the smallest over
/// the flagging gaps and its velocity that of the gap giving it; a safe pixel's velocity comes
/// from the largest gap that gives one. edges_cur / edges_past (optional): mark_depth_edges of
/// D_i / of past_disps (same order, same margin and step), when the caller keeps them from frame to
/// frame; computed here (at q only, for the past) when null.
void label_stereo_flow_window(const cv::Mat& disp_cur,
                              const std::vector<const cv::Mat*>& past_disps,
                              const std::vector<const cv::Mat*>& past_flows,
                              const core::Camera& cam, const core::Envelope& env,
                              const SceneFlowParams& p, double dt, cv::Mat& danger, cv::Mat& ttc,
                              cv::Mat& velocity, const cv::Mat* edges_cur = nullptr,
                              const std::vector<const cv::Mat*>* edges_past = nullptr);

/// The frame gaps the labelling samples: p.gaps, or with p.fit_velocity every gap from 1 to the
/// longest of p.gaps (the fit uses each frame of the chain).
std::vector<int> sampled_gaps(const SceneFlowParams& p);

/// One gap of the Stereo-Flow labelling: the past frame whose disparity the chained flow reaches
/// after `steps` flows, and the time between it and the current frame.
struct GapSource {
  int steps = 1;                       ///< flows chained from the current frame, >= 1
  const cv::Mat* disparity = nullptr;  ///< D of that past frame, CV_32F, invalid < 0
  const cv::Mat* edges = nullptr;      ///< its mark_depth_edges, or null (checked at q only)
  double span_s = 0.0;                 ///< time from that frame to the current one, s (> 0)
  /// Turns camera coordinates of that past frame into the current frame's orientation (the
  /// camera's own rotation over the gap, vision/ego_motion.hpp), applied to P_{i-k} before V is
  /// formed; null = no rotation.
  const cv::Matx33d* derotate = nullptr;
};

/// Allocates the outputs of label_stereo_flow_rows at `size` (danger CV_8U, ttc CV_32F, velocity
/// CV_32FC3), so that row tiles can then fill them independently.
void allocate_stereo_flow_outputs(cv::Size size, cv::Mat& danger, cv::Mat& ttc, cv::Mat& velocity);

/// The grid of pixels label_stereo_flow_rows follows back along the chain when
/// p.pool_surface_motion and p.chain_stride > 1 (SceneFlowParams::chain_stride): every pixel
/// farther than p.chain_stride_z_m, nearer only every sx-th column and sy-th row by absolute
/// position, (sx, sy) = (chain_stride, chain_stride) doubled once per factor sqrt(2) nearer,
/// columns first, up to 16 each.
class ChainStrides {
 public:
  ChainStrides(const core::Camera& cam, const SceneFlowParams& p);
  /// (sx, sy) at disparity d: (1, 1) where every pixel is followed.
  cv::Size at(float d) const;
  /// Whether pixel (x, y) with disparity d is followed.
  bool followed(int x, int y, float d) const {
    const cv::Size s = at(d);
    return x % s.width == 0 && y % s.height == 0;
  }
  /// The pixels a followed pixel with disparity d stands for, sx * sy: pool_surface_motion
  /// weighs its velocity by them, so that the near part of a surface, followed sparsely, counts
  /// as much as its far part.
  int weight(float d) const { return at(d).area(); }

 private:
  int stride_ = 1;
  float d_stride_;  ///< the disparity of chain_stride_z_m; +inf: every pixel followed
};

/// The per-pixel test of label_stereo_flow_window on output rows `rows` only (cv::Range::all():
/// every row), for past frames given explicitly: flows[j] is the backward flow of the j-th newest
/// frame of the chain (flows[0] = B_i, from the current frame to the frame before it in the
/// chain); gap g follows g.steps flows and compares with g.disparity over g.span_s seconds. Frames
/// dropped from a stream make a chain step span several camera frames: the spans carry the real
/// times. Gaps whose steps exceed flows.size() or whose span is not positive are skipped; of
/// gaps with equal steps the first given is used. edges_cur = mark_depth_edges of disp_cur.
/// Outputs must be allocated (allocate_stereo_flow_outputs); only rows `rows` are written, so
/// tiles stitched give the same maps as one call over all rows. With p.pool_surface_motion and
/// p.chain_stride > 1, candidates nearer than p.chain_stride_z_m are followed only on every
/// chain_stride-th row and column (by absolute position); the others stay unlabelled, with an
/// unknown velocity, for pool_surface_motion to fill in. residuals (optional, p.fit_velocity
/// only): CV_32FC(1 + n) of disp_cur's size, n = the number of distinct steps among the gaps
/// used; per pixel whose fit gives a velocity, Z minus the fitted line at each sample (channel
/// 0: now; channel j: the j-th shortest chain's past frame), m, NaN where the chain gave no
/// sample; NaN at every other pixel (rows `rows` only).
void label_stereo_flow_rows(const cv::Mat& disp_cur, const cv::Mat& edges_cur,
                            const std::vector<const cv::Mat*>& flows,
                            const std::vector<GapSource>& gaps, const core::Camera& cam,
                            const core::Envelope& env, const SceneFlowParams& p, cv::Mat& danger,
                            cv::Mat& ttc, cv::Mat& velocity, cv::Range rows,
                            cv::Mat* residuals = nullptr);

/// A plane n . P + c = 0 in camera coordinates (|n| = 1, n pointing up, i.e. n_y < 0).
struct GroundPlane {
  cv::Vec3d normal{0.0, -1.0, 0.0};
  double offset = 0.0;  ///< c, m
  int inliers = 0;      ///< sample points within the tolerance
  bool found = false;
};

/// Fits the ground plane to the valid 3D points of the lower image by RANSAC (3-point samples,
/// then a least-squares refit to the inliers). Planes steeper than 45 degrees from horizontal
/// are rejected (walls). disp: CV_32F, invalid < 0.
GroundPlane fit_ground_plane(const cv::Mat& disp, const core::Camera& cam, const GroundParams& p);

/// 255 where the pixel's 3D point lies within `tolerance_m` of the plane or below it (under the
/// ground), 0 elsewhere and where the disparity is invalid. Clear `danger` with it to exclude the
/// ground when the camera is tilted. mask: CV_8U, allocated. With `only` (CV_8U, the
/// disparity's size) just its nonzero pixels are tested; the others stay 0.
void mark_ground(const cv::Mat& disp, const core::Camera& cam, const GroundPlane& plane,
                 double tolerance_m, cv::Mat& mask, const cv::Mat& only = cv::Mat());

/// 255 on the ground's side of the plane: where the pixel's 3D point lies within `tolerance_m`
/// of the plane or below it, or where its disparity exceeds the plane's disparity at that pixel
/// by at most `margin_px` (the matcher's error on the ground, which at a distance is more than
/// tolerance_m); 0 elsewhere, where the disparity is invalid, and everywhere when no plane was
/// found. mask: CV_8U, allocated. pool_surface_motion joins no pixel of this side with one off it:
/// an object standing on the ground meets it at one disparity.
void mark_ground_side(const cv::Mat& disp, const core::Camera& cam, const GroundPlane& plane,
                      double tolerance_m, double margin_px, cv::Mat& mask);

}  // namespace sg::vision
