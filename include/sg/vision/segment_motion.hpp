#pragma once
/// Rigid-motion pooling of the Stereo-Flow labelling (DESIGN 3.2, docs/stereo-flow.md).
///
/// The per-pixel velocity of label_stereo_flow_rows is noisy: over a 20-frame gap the disparity
/// of a box 7 m away grows by about 1.4 px while block matching is off by about 0.1 px a pixel,
/// so per-pixel TTCs scatter by about 10 %. Tested pixel by pixel, a large object whose true TTC
/// is 10 % over the horizon still has hundreds of pixels under it (an early alarm), and a small
/// far one whose TTC is just under it has too few to pass min_area (a late one). The points of
/// one rigid object share one velocity (a translation; a turn adds a part that varies little
/// across an object), so the velocity is pooled over the surface a pixel lies on before the
/// envelope test: its noise then falls with the square root of the surface's pixel count.
#include <cstddef>
#include <opencv2/core.hpp>
#include <utility>
#include <vector>

#include "sg/core/camera.hpp"
#include "sg/core/params.hpp"

namespace sg::vision {

/// Interquartile mean of v (reordered; not empty): the mean of the middle half, ranks
/// [n/4, n - n/4) of the sorted values. Robust like the median to the pixels paired across an
/// occlusion, but not stuck to the 1/16 px grid of the matcher's disparities as a median of nearly
/// equal quantized values is (at 19 m the disparity grows by 0.55 px over 20 frames: a 1/32 px
/// offset is a 6 % TTC error). Two selections instead of a sort, O(n): a surface can be the whole
/// floor, and sorting it was a fifth of a Stereo-Flow run on EuRoC. Summed in another order than
/// the sorted one, so it may differ from that by a float rounding (the test's reference sorts).
float interquartile_mean(std::vector<float>& v);
/// The same over v[0, n) (reordered; n > 0).
float interquartile_mean(float* v, size_t n);

/// Interquartile mean of v[0, n) (n > 0) where v[i] counts as w[i] >= 1 copies of itself (a
/// followed pixel standing for the w[i] pixels of its stride cell, ChainStrides::weight):
/// floor(W / 4) of the total weight W is trimmed from each end of the sorted values, a value on
/// a border keeping the weight left of it. Equal to interquartile_mean of the values repeated
/// w[i] times (up to a float rounding). low and high (optional): the smallest and the largest
/// value kept. Reorders (value, weight) pairs in `scratch`: two weighted selections, O(n).
float weighted_interquartile_mean(const float* v, const int* w, size_t n,
                                  std::vector<std::pair<float, int>>& scratch,
                                  float* low = nullptr, float* high = nullptr);

/// The surfaces of pool_surface_motion: labels (CV_32S, 0 = none, 1..count-1, numbered in the
/// raster order of each surface's first pixel) the 8-connected components of the `member` pixels
/// (CV_8U nonzero) whose neighbours' disparities (disp, CV_32F) differ by at most `step`, also
/// joining a member to one of the last three runs of distinct disparity in its column when that
/// run ended at most bridge_rows_per_px * d rows above and its disparity was within `step`
/// (0 = no bridging). Returns count. A union-find over each row's runs of continuous members.
int label_surfaces(const cv::Mat& disp, const cv::Mat& member, float step,
                   double bridge_rows_per_px, cv::Mat& labels);

/// The same, pixel by pixel (a union-find over every member): the reference label_surfaces is
/// tested against.
int label_surfaces_reference(const cv::Mat& disp, const cv::Mat& member, float step,
                             double bridge_rows_per_px, cv::Mat& labels);

/// The velocity fit's residuals over a chain still short of its window (the first frames of a
/// stream): what the data show of the fit's error, for pool_surface_motion's doubt.
struct ChainResiduals {
  /// CV_32FC(times_s.size()): per pixel with a velocity, Z minus its fitted line at each sample
  /// time, m; NaN where its chain gave no sample (label_stereo_flow_rows' residuals). Empty: no
  /// doubt.
  cv::Mat residuals_m;
  /// The sample times of the channels, s relative to now (0 = now, then the past frames, < 0).
  std::vector<double> times_s;
};

/// The doubt of a surface's velocity: doubt_se standard errors of the slope of the line fitted
/// to (times_s[j], residuals[j]) over the samples with a finite residual (the scatter of the
/// surface's own positions about its fitted line), widened for few degrees of freedom as
/// Student's t is (t_0.975(m - 2) / 1.96 for m samples; doubt_se 2: about 95 %), m/s when the
/// residuals are m. Infinite with fewer than three samples (no scatter to measure yet) or when
/// they all share one time.
double slope_doubt(const std::vector<double>& times_s, const std::vector<double>& residuals,
                   double doubt_se);

/// Relabels a Stereo-Flow frame with pooled velocities. Surfaces are the 8-connected components
/// of the pixels with a valid disparity (disp, CV_32F, invalid < 0), Z <= p.z_max_m and, with
/// p.use_envelope_band, inside the envelope's vertical band now, where neighbours' disparities
/// differ by at most p.edge_step_px: a step separates objects at different depths. A surface
/// also continues down a column across at most p.surface_bridge_m (at its depth: that times
/// d / B rows) of other pixels where a disparity within p.edge_step_px resumes: a thin pole that
/// the matcher cut into pieces stays one surface. The
/// labelling's candidates are those off the depth-edge margin (`edges`, CV_8U, 255 = near a depth
/// edge: depth_edges()); margin pixels join their surface but give no velocity and are never
/// dangerous, so that the margin does not cut a small piece off an object (on overhang, with
/// area-integrated edges, a 17 x 13 px piece of the bar alone pooled -1.51 m/s for a true -1.40:
/// an early alarm). Each surface's velocity is the per-component interquartile mean of the
/// velocities its pixels know (finite in `velocity`, CV_32FC3 m/s): robust to the minority paired
/// across an occlusion, and unlike a median not stuck to the matcher's 1/16 px disparity grid.
/// Candidates whose own velocity is unknown (a source near a past depth edge) take it too.
/// Every pixel of a surface with a velocity is then tested with its own position P(p) and that
/// velocity: faster than p.max_speed_mps is a mismatch; the noise gate of the labelling applies
/// to the pooled motion, so the disparity that P(p) had `span_s` seconds ago at that velocity,
/// f B / (Z - V_z span_s), must be at least p.min_delta_d_px below disp(p) (span_s = the longest
/// gap's time: a motion too small to show over the gaps measured is noise, as at the start of a
/// stream with gap 1 only); then heads_into_envelope(P, V, env, p.v_min_mps). Outputs,
/// overwritten at every pixel: danger CV_8U 0/255, ttc CV_32F (s, NaN where safe), velocity =
/// the surface's velocity (NaN elsewhere). All maps the same size. With `startup` (a fit over a
/// chain still short of its window), each surface is doubted by the scatter of its own fit: its
/// mean residual at each sample time, over the pixels of the middle half of its V_z (those its
/// interquartile mean averages), gives sigma_V = slope_doubt(startup.times_s, those means,
/// p.startup_doubt_se), and the envelope test uses V (1 - sigma_V / -V_z) instead of V (nothing
/// when that is <= 0; nothing either with fewer than three samples); the TTC reported is that of
/// V itself. A large surface seen well is thus trusted from its first frames, a few pixels whose
/// disparity steps are not. yaw_rate_rps (rad/s, + = turning right): the platform's turn, which
/// the envelope test follows (heads_into_envelope_turning); 0 = straight ahead. ground_side
/// (optional, CV_8U of the maps' size; InputError otherwise; mark_ground_side): no surface joins
/// a nonzero pixel with a zero one. An object standing on the ground meets it at one disparity;
/// without it the two pool as one surface, and the larger ground's motion becomes the object's.
void pool_surface_motion(const cv::Mat& disp, const core::Camera& cam, const core::Envelope& env,
                         const core::SceneFlowParams& p, double span_s, const cv::Mat& edges,
                         cv::Mat& danger, cv::Mat& ttc, cv::Mat& velocity,
                         const ChainResiduals& startup = {}, double yaw_rate_rps = 0.0,
                         const cv::Mat& ground_side = cv::Mat());

}  // namespace sg::vision
