#include "sg/vision/stereo_sgbm.hpp"

#include <opencv2/calib3d.hpp>

namespace sg::vision {

void match_sgbm_rows(const cv::Mat& left, const cv::Mat& right, const core::BmParams& p,
                     cv::Mat& disp, cv::Range rows) {
  if (rows == cv::Range::all()) rows = cv::Range(0, left.rows);
  disp.create(left.size(), CV_32F);
  if (rows.empty()) return;
  const int area = p.block_size * p.block_size;
  cv::Ptr<cv::StereoSGBM> sgbm = cv::StereoSGBM::create(
      p.min_disparity, p.num_disparities, p.block_size, 8 * area, 32 * area, p.lr_max_diff,
      p.prefilter_cap, p.uniqueness_ratio, 0, 0, cv::StereoSGBM::MODE_SGBM_3WAY);
  cv::Mat raw;  // CV_16S, disparity * 16
  sgbm->compute(left, right, raw);
  const int min_raw = p.min_disparity * 16;
  for (int y = rows.start; y < rows.end; ++y) {
    const short* src = raw.ptr<short>(y);
    float* dst = disp.ptr<float>(y);
    for (int x = 0; x < disp.cols; ++x)
      dst[x] = src[x] < min_raw ? -1.0f : static_cast<float>(src[x]) / 16.0f;
  }
}

}  // namespace sg::vision
