#include <gtest/gtest.h>

#include <limits>

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

TEST(Camera, ValidateRejectsPhysicallyImpossibleValues) {
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  struct Case {
    double Camera::*field;
    double value;
    const char* needle;
  };
  const Case cases[] = {
      {&Camera::fps, 0.0, "camera.fps=0"},         {&Camera::fps, -5.0, "camera.fps=-5"},
      {&Camera::fps, inf, "camera.fps=inf"},       {&Camera::fps, nan, "camera.fps=nan"},
      {&Camera::fps, 1e7, "camera.fps=1e+07"},     {&Camera::focal_px, nan, "camera.focal_px=nan"},
      {&Camera::focal_px, -1, "camera.focal_px=-1"}, {&Camera::focal_px, inf, "camera.focal_px=inf"},
      {&Camera::baseline_m, 0, "camera.baseline_m=0"},
      {&Camera::baseline_m, nan, "camera.baseline_m=nan"},
      {&Camera::baseline_m, 1e6, "camera.baseline_m=1e+06"},
  };
  for (const Case& c : cases) {
    Camera cam;
    cam.*c.field = c.value;
    const auto problems = validate(cam);
    ASSERT_FALSE(problems.empty()) << c.needle;
    EXPECT_NE(problems[0].find(c.needle), std::string::npos) << problems[0];
  }
  Camera fast;
  fast.fps = 1000.0;  // a high-speed camera is still a camera
  EXPECT_TRUE(validate(fast).empty());
}

}  // namespace
}  // namespace sg::core
