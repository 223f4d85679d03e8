#include "sg/vision/central_median.hpp"

#include <algorithm>
#include <opencv2/calib3d.hpp>
#include <vector>

namespace sg::vision {

cv::Rect central_box(cv::Size size) {
  return {size.width / 4, size.height / 4, size.width / 2, size.height / 2};
}

void match_sgbm_baseline(const cv::Mat& left, const cv::Mat& right, const core::BmParams& bm,
                         cv::Mat& disp) {
  const int area = bm.block_size * bm.block_size;
  cv::Ptr<cv::StereoSGBM> sgbm = cv::StereoSGBM::create(
      0, bm.num_disparities, bm.block_size, 8 * area, 32 * area,
      /*disp12MaxDiff=*/1, /*preFilterCap=*/63, /*uniquenessRatio=*/10,
      /*speckleWindowSize=*/100, /*speckleRange=*/2, cv::StereoSGBM::MODE_SGBM_3WAY);
  cv::Mat raw;  // CV_16S, disparity * 16; invalid = (minDisparity - 1) * 16
  sgbm->compute(left, right, raw);
  disp.create(left.size(), CV_32F);
  for (int y = 0; y < raw.rows; ++y) {
    const short* src = raw.ptr<short>(y);
    float* dst = disp.ptr<float>(y);
    for (int x = 0; x < raw.cols; ++x)
      dst[x] = src[x] < 0 ? -1.0f : static_cast<float>(src[x]) / 16.0f;
  }
}

CentralMedian central_median(const cv::Mat& disp, const core::Camera& camera) {
  CV_Assert(disp.type() == CV_32F);
  CentralMedian out;
  out.box = central_box(disp.size());
  std::vector<float> values;
  values.reserve(static_cast<std::size_t>(out.box.area()));
  for (int y = out.box.y; y < out.box.br().y; ++y) {
    const float* row = disp.ptr<float>(y);
    for (int x = out.box.x; x < out.box.br().x; ++x)
      if (row[x] > 0.0f) values.push_back(row[x]);
  }
  out.valid_px = static_cast<int>(values.size());
  if (values.empty()) return out;
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  double median = *mid;
  if (values.size() % 2 == 0) median = (median + *std::max_element(values.begin(), mid)) / 2.0;
  out.disparity_px = median;
  out.distance_m = camera.depth(median);
  return out;
}

}  // namespace sg::vision
