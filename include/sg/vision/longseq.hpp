#pragma once
/// LongSeq stereo (thesis 3.2.3, DESIGN 3.4, after the pocket drone of the thesis' [33]): a
/// matching cost over one image row per pixel, a good/bad array over the disparity range, and the
/// disparity inside the longest run of good matches. Cheap enough for a 168 MHz processor; a pixel
/// nearer than a threshold fires the obstacle signal.
///
/// Per pixel x of a row, with C(x, d) the mean absolute difference between the left image's
/// window at x and the right image's at x - d (window_px pixels of the same row):
///   the pixel is matched at all when min_d C(x, d) <= best_max;
///   B(x, d) = 1 (bad) when C(x, d) > cost_max, 0 (good) otherwise;
///   the disparity is the middle of the longest run of zeros of B (the first such run on a tie);
///   a pixel with no bad entry at all (an untextured window, which matches everywhere) is left
///   unmatched: its run spans the whole range and says nothing (the thesis' rule would give the
///   range's middle, a near point, on every patch of sky or blank wall).
/// The thesis' example: B = [110001001] gives the run lengths [113331221] and a disparity inside
/// the run of three zeros, d = 3.
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace sg::vision {

struct LongSeqParams {
  int num_disparities = 64;  ///< disparities searched: 0 .. num_disparities - 1, px
  int window_px = 5;         ///< width of the one-row matching window, px, odd
  double cost_max = 6.0;     ///< tau_cost: a good match costs at most this, grey levels (0-255)
  double best_max = 3.0;     ///< tau_min: a pixel whose best cost exceeds this is left unmatched
  /// Also match the right image against the left and keep, per left pixel, the smaller of the two
  /// disparities (the thesis' optimisation step): a near value must be seen from both sides.
  bool both_ways = true;
};

/// Each invalid field, by name, with its value and the rule it breaks; empty when valid.
std::vector<std::string> validate(const LongSeqParams& p);

/// The thesis' intermediate array: out[d] = 1 where bad[d] != 0, else the length of the run of
/// zeros that d lies in. `bad` and `out` hold n entries.
void good_run_lengths(const std::uint8_t* bad, int n, int* out);

/// The disparity inside the longest run of zeros of bad[0 .. n): the run's middle index (rounded
/// down); the first run on a tie. -1 when every entry is bad.
int longest_good_run(const std::uint8_t* bad, int n);

/// LongSeq disparity of an 8-bit grey rectified pair of one size: CV_32F, px (whole pixels), -1
/// where unmatched or where the search range leaves the image. Each disparity's costs are running
/// window sums along the row. Throws core::InputError on a type or size mismatch or invalid
/// parameters.
void longseq_disparity(const cv::Mat& left, const cv::Mat& right, const LongSeqParams& p,
                       cv::Mat& disparity);

/// The rows `rows` of longseq_disparity (cv::Range::all(): every row); `disparity` is allocated
/// when it is not a CV_32F map of the images' size, its other rows are left as they are. Rows are
/// independent, so row tiles equal the whole image.
void longseq_disparity_rows(const cv::Mat& left, const cv::Mat& right, const LongSeqParams& p,
                            cv::Mat& disparity, cv::Range rows);

/// longseq_disparity with every cost summed pixel by pixel: the reference the running sums are
/// tested against (equal integers, so equal results).
void longseq_disparity_reference(const cv::Mat& left, const cv::Mat& right,
                                 const LongSeqParams& p, cv::Mat& disparity);

}  // namespace sg::vision
