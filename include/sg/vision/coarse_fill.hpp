#pragma once
/// Holes of a disparity map filled from the half-size pair (DESIGN 2.1, `stereo.coarse_fill`).
/// A block matcher leaves a surface invalid where its block holds too little texture for the
/// sensor's noise (the texture threshold, the uniqueness ratio and the speckle filter reject it):
/// a car's plain door under noise keeps only its outline. Matched at half size, the same block
/// covers twice the angle and each pixel averages four, halving the noise, so such a surface is
/// matched there. The half-size map is coarser (1/8 px steps at full size) and fattens the
/// foreground twice as far, so it only fills pixels far from anything the full-size map matched.
#include <opencv2/core.hpp>

#include "sg/core/params.hpp"
#include "sg/vision/left_band.hpp"

namespace sg::vision {

/// How far from a valid pixel of the full-size map a hole must lie to be filled, px (city-block
/// distance): half a block, rounded up. Closer holes are the full-size map's own fattening and
/// occlusion band, where the half-size map fattens a foreground object further (into the
/// background beside it: it would join the object to its background).
int coarse_fill_reach(const core::BmParams& p);

/// The narrowest half-size image the fill runs on, px (320 px at full size, the smallest the
/// random suite draws). On a 122 x 94 camera the half-size block spans a sixth of the view, wider
/// than the objects it would fill: the fill raised still-camera alarms there.
inline constexpr int kCoarseFillMinHalfWidth = 160;

/// Fills, in place, every invalid pixel of `disp` (CV_32F of left's size, invalid < 0) that lies
/// more than coarse_fill_reach(p) from a valid one with twice the disparity `match` finds at
/// (x / 2, y / 2) on the pair shrunk to half size (pixel areas averaged), where that one is
/// valid. The half-size match uses p with half the disparity range (a multiple of 16), and the
/// same block and speckle window (a mismatch's blob is about a block, in the matcher's own pixels,
/// at either size); with p.left_band, its left band too. Valid pixels
/// are untouched. A hole inside one surface keeps to it: where the nearest valid pixels left and
/// right of it on its row agree (within 1 px or a quarter of the larger), the fill must agree
/// with them as well (a periodic texture that the full-size matcher rightly found ambiguous is
/// often matched a period off at half size). Does nothing on a half-size image narrower than
/// kCoarseFillMinHalfWidth or too narrow for that range and block.
void fill_from_half_size(const cv::Mat& left, const cv::Mat& right, const core::BmParams& p,
                         RowMatcher match, cv::Mat& disp);

}  // namespace sg::vision
