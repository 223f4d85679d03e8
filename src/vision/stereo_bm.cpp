#include "sg/vision/stereo_bm.hpp"

#include <algorithm>
#include <opencv2/calib3d.hpp>

namespace sg::vision {
namespace {

/// OpenCV's StereoBM marks invalid pixels (minDisparity - 1) * 16 in its CV_16S output (4
/// fractional bits); anything below minDisparity * 16 is invalid.
constexpr int kDispScale = 16;
constexpr float kInvalid = -1.0f;

/// Rows the x-Sobel prefilter reads above and below an output row (a 3x3 kernel). We pin the
/// prefilter type to x-Sobel (OpenCV's default) so that this halo is known.
constexpr int kPrefilterHalo = 1;

cv::Ptr<cv::StereoBM> make_matcher(const core::BmParams& p) {
  cv::Ptr<cv::StereoBM> bm = cv::StereoBM::create(p.num_disparities, p.block_size);
  bm->setMinDisparity(p.min_disparity);
  bm->setPreFilterType(cv::StereoBM::PREFILTER_XSOBEL);
  bm->setPreFilterCap(p.prefilter_cap);
  bm->setTextureThreshold(p.texture_threshold);
  bm->setUniquenessRatio(p.uniqueness_ratio);
  bm->setDisp12MaxDiff(p.lr_max_diff);
  // Speckles are filtered over the whole stitched map (filter_speckles): a component can cross
  // tile borders, so filtering inside a tile would not be bit-identical to the whole image.
  bm->setSpeckleWindowSize(0);
  bm->setSpeckleRange(0);
  return bm;
}

}  // namespace

cv::Range bm_input_rows(cv::Range rows, const core::BmParams& p, int height) {
  if (rows == cv::Range::all()) return {0, height};
  const int halo = p.block_size / 2 + kPrefilterHalo;
  // The x-Sobel prefilter works on pairs of rows counted from the top of its input and sets the
  // last row to a constant when the input height is odd. Starting every tile on an even row keeps
  // the pairs (and so that last row at the image bottom) as in the whole image.
  int r0 = std::max(rows.start - halo, 0) & ~1;
  int r1 = std::min(rows.end + halo, height);
  // StereoBM refuses inputs that are not taller than the block; extra rows change nothing.
  const int min_rows = p.block_size + 1;
  if (r1 - r0 < min_rows) {
    r1 = std::min(height, r0 + min_rows);
    r0 = std::max(r1 - min_rows, 0) & ~1;
  }
  return {r0, r1};
}

void match_bm_rows(const cv::Mat& left, const cv::Mat& right, const core::BmParams& p,
                   cv::Mat& disp, cv::Range rows) {
  const int height = left.rows;
  if (rows == cv::Range::all()) rows = cv::Range(0, height);
  disp.create(left.size(), CV_32F);
  if (rows.empty()) return;

  const cv::Range in = bm_input_rows(rows, p, height);
  cv::Mat raw;  // CV_16S, disparity * 16
  make_matcher(p)->compute(left.rowRange(in), right.rowRange(in), raw);

  const short min_raw = static_cast<short>(p.min_disparity * kDispScale);
  for (int y = rows.start; y < rows.end; ++y) {
    const short* src = raw.ptr<short>(y - in.start);
    float* dst = disp.ptr<float>(y);
    for (int x = 0; x < disp.cols; ++x)
      dst[x] = src[x] < min_raw ? kInvalid : static_cast<float>(src[x]) / kDispScale;
  }
}

void filter_speckles(cv::Mat& disp, const core::BmParams& p) {
  if (p.speckle_window <= 0) return;
  // Back to OpenCV's fixed-point representation; exact since BM disparities are k / 16.
  const short invalid_raw = static_cast<short>((p.min_disparity - 1) * kDispScale);
  cv::Mat raw(disp.size(), CV_16S);
  for (int y = 0; y < disp.rows; ++y) {
    const float* src = disp.ptr<float>(y);
    short* dst = raw.ptr<short>(y);
    for (int x = 0; x < disp.cols; ++x)
      dst[x] = src[x] < 0 ? invalid_raw : static_cast<short>(cvRound(src[x] * kDispScale));
  }
  cv::filterSpeckles(raw, invalid_raw, p.speckle_window, p.speckle_range * kDispScale);
  for (int y = 0; y < disp.rows; ++y) {
    const short* src = raw.ptr<short>(y);
    float* dst = disp.ptr<float>(y);
    for (int x = 0; x < disp.cols; ++x)
      if (src[x] == invalid_raw) dst[x] = kInvalid;
  }
}

void match_bm(const cv::Mat& left, const cv::Mat& right, const core::BmParams& p, cv::Mat& disp) {
  match_bm_rows(left, right, p, disp, cv::Range::all());
  filter_speckles(disp, p);
}

}  // namespace sg::vision
