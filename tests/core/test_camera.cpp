#include <gtest/gtest.h>

#include "sg/core/camera.hpp"

namespace sg::core {
namespace {

TEST(Camera, DepthDisparityRoundTrip) {
  Camera cam;
  for (double z : {0.5, 1.0, 3.7, 15.0, 80.0}) {
    const double d = cam.disparity(z);
    EXPECT_NEAR(cam.depth(d), z, 1e-12 * z);
  }
  EXPECT_DOUBLE_EQ(cam.disparity(1.0), 60.0);  // f * B = 500 * 0.12
}

TEST(Camera, PointProjectRoundTrip) {
  Camera cam;
  const cv::Point3d p = cam.point(100.25, 400.5, 12.0);
  EXPECT_DOUBLE_EQ(p.z, 5.0);
  const cv::Point2d q = cam.project(p);
  EXPECT_NEAR(q.x, 100.25, 1e-9);
  EXPECT_NEAR(q.y, 400.5, 1e-9);
}

TEST(Camera, ValidateNamesEachBadField) {
  Camera cam;
  EXPECT_TRUE(validate(cam).empty());
  cam.fps = -30;
  cam.focal_px = 0;
  const auto problems = validate(cam);
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_NE(problems[0].find("camera.focal_px=0"), std::string::npos);
  EXPECT_NE(problems[1].find("camera.fps=-30"), std::string::npos);
}

}  // namespace
}  // namespace sg::core
