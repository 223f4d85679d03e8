#pragma once
/// The depth-edge margin of the Stereo-Flow labelling (mark_depth_edges) removes every pixel within
/// edge_margin_px of a depth step, because there block matching and flow pair an object's
/// disparity now with the background's before. Two consequences are repaired here:
///  * an object narrower than about twice the margin (a 5 cm pole 5 m away is 5 px wide, the
///    margin 8 px) vanishes whole: thin near structures are given back (unmark_thin_structures);
///  * a far object loses its rim: a car 30 m away is 36 x 30 px, the margin leaves 20 x 14 px and
///    min_area drops it; once found, a dangerous object is grown back over its rim
///    (grow_danger_into_edges) before min_area is applied.
#include <opencv2/core.hpp>

namespace sg::vision {

/// 255 at the pixels of thin near structures, 0 elsewhere (mask: CV_8U, allocated). A pixel p
/// with valid disparity d = disp(p) (CV_32F, invalid < 0) belongs to one when
///  * its run of similar disparity along its row, or along its column (neighbours differing by
///    at most step_px), is at most max_width_px long and is bounded at both ends by a farther
///    surface (disparity below the run's smallest minus step_px) or an invalid pixel, not by the
///    image border; and
///  * nothing nearer lies within margin_px of p: the largest valid disparity of the
///    (2 margin_px + 1)^2 window around p is at most d + step_px.
/// The second rule keeps the mask on the far side of every depth edge, where block matching and
/// flow mix a near object into the background (the case the depth-edge margin is for).
void mark_thin_structures(const cv::Mat& disp, int margin_px, double step_px, int max_width_px,
                          cv::Mat& mask);

/// Clears from a depth-edge mask (mark_depth_edges, CV_8U) the pixels of thin near structures
/// (mark_thin_structures with max_width_px = 2 margin_px + 1: the widths the margin would remove
/// whole). Wider objects keep the margin unchanged.
void unmark_thin_structures(const cv::Mat& disp, int margin_px, double step_px, cv::Mat& edges);

/// Grows the dangerous pixels of `danger` (CV_8U 0/255) back over the depth-edge margin: for up to
/// `iterations` rounds, a pixel of `edges` (CV_8U, 255 = excluded by the margin) with a valid
/// disparity joins the danger when one of its 8 neighbours is dangerous with a disparity within
/// step_px of its own; it takes that neighbour's TTC (`ttc`, CV_32F, NaN where safe) and velocity
/// (`velocity`, CV_32FC3, may be empty). Seeds are the dangerous pixels that survive a
/// open_size x open_size opening (1 = no opening), so a lone noisy pixel grows nothing. Pixels
/// outside the margin are never added: the labelling has already judged them.
void grow_danger_into_edges(const cv::Mat& disp, const cv::Mat& edges, int iterations,
                            double step_px, int open_size, cv::Mat& danger, cv::Mat& ttc,
                            cv::Mat& velocity);

}  // namespace sg::vision
