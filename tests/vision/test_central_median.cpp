// The baseline's per-frame kernel: the central quarter, the median of its valid disparities,
// and StereoSGBM on a textured plane at a known disparity.
#include <gtest/gtest.h>

#include "sg/vision/central_median.hpp"
#include "synthetic.hpp"

namespace sg::vision {
namespace {

TEST(CentralMedian, BoxIsTheCentreHalfOfEachSideOnOddSizes) {
  EXPECT_EQ(central_box({640, 480}), cv::Rect(160, 120, 320, 240));
  EXPECT_EQ(central_box({321, 241}), cv::Rect(80, 60, 160, 120));
  EXPECT_EQ(central_box({122, 94}), cv::Rect(30, 23, 61, 47));
}

TEST(CentralMedian, MedianOfValidPixelsInsideTheBoxOnly) {
  const core::Camera cam = test::camera();                         // f*B = 50
  cv::Mat disp(cam.height, cam.width, CV_32F, cv::Scalar(40.0f));  // outside: ignored
  const cv::Rect box = central_box(disp.size());
  disp(box).setTo(-1.0f);  // invalid
  // Four valid pixels: 5, 10, 20 and 0 (infinitely far: not valid); median of 5, 10, 20 = 10.
  disp.at<float>(box.y, box.x) = 5.0f;
  disp.at<float>(box.y + 1, box.x) = 10.0f;
  disp.at<float>(box.br().y - 1, box.br().x - 1) = 20.0f;
  disp.at<float>(box.y + 2, box.x + 2) = 0.0f;
  CentralMedian m = central_median(disp, cam);
  EXPECT_EQ(m.box, box);
  EXPECT_EQ(m.valid_px, 3);
  ASSERT_TRUE(m.disparity_px);
  EXPECT_DOUBLE_EQ(*m.disparity_px, 10.0);
  EXPECT_DOUBLE_EQ(*m.distance_m, 5.0);
  // An even count takes the mean of the two middle values.
  disp.at<float>(box.y + 3, box.x + 3) = 30.0f;
  m = central_median(disp, cam);
  EXPECT_DOUBLE_EQ(*m.disparity_px, 15.0);
}

TEST(CentralMedian, NoValidPixelGivesNoDistance) {
  const core::Camera cam = test::camera();
  cv::Mat disp(cam.height, cam.width, CV_32F, cv::Scalar(-1.0f));
  disp(cv::Rect(0, 0, 10, 10)).setTo(12.0f);  // outside the box
  const CentralMedian m = central_median(disp, cam);
  EXPECT_EQ(m.valid_px, 0);
  EXPECT_FALSE(m.disparity_px);
  EXPECT_FALSE(m.distance_m);
}

TEST(CentralMedian, SgbmOnATexturedPlaneGivesItsDistance) {
  core::Camera cam;
  cam.width = 321;
  cam.height = 241;
  cam.focal_px = 500.0;
  cam.baseline_m = 0.1;  // f*B = 50
  core::BmParams bm;     // 64 disparities, block 11
  for (float d : {8.0f, 20.0f, 33.5f}) {
    const test::StereoPair pair = test::shifted_pair({cam.width, cam.height}, d, 7);
    cv::Mat disp;
    match_sgbm_baseline(pair.left, pair.right, bm, disp);
    ASSERT_EQ(disp.type(), CV_32F);
    ASSERT_EQ(disp.size(), pair.left.size());
    const CentralMedian m = central_median(disp, cam);
    ASSERT_TRUE(m.distance_m) << "d " << d;
    EXPECT_GT(m.valid_px, m.box.area() / 2) << "d " << d;
    EXPECT_NEAR(*m.disparity_px, d, 0.25) << "d " << d;
    EXPECT_NEAR(*m.distance_m, 50.0 / d, 0.02 * 50.0 / d) << "d " << d;
  }
}

}  // namespace
}  // namespace sg::vision
