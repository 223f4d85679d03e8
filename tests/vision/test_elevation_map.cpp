#include <gtest/gtest.h>

#include <cmath>

#include "sg/core/error.hpp"
#include "sg/vision/elevation_map.hpp"
#include "sg/vision/surveyed.hpp"

namespace sg::vision {
namespace {

core::Camera camera() {
  core::Camera cam;  // 640x480, f 500 px, B 0.12 m
  return cam;
}

/// The exact disparity of a road Y = road.y(X, Z) seen from the camera (the camera 1.2 m above
/// the road: c = 1.2), with an optional box: a face towards the camera at Z = box_z, X in
/// [-0.6, 0.6], from the road up to 0.8 m. Sky (no hit within 60 m) is invalid.
cv::Mat render(const core::Camera& cam, const RoadModel& road, double box_z) {
  cv::Mat disp(cam.height, cam.width, CV_32FC1, cv::Scalar(-1.0f));
  for (int y = 0; y < cam.height; ++y) {
    for (int x = 0; x < cam.width; ++x) {
      const double u = (x - cam.cx) / cam.focal_px, v = (y - cam.cy) / cam.focal_px;
      // Z v = a2 u^2 Z^2 + a1 u Z + b2 Z^2 + b1 Z + c: the nearest positive root.
      const double A = road.a2 * u * u + road.b2, B = road.a1 * u + road.b1 - v, C = road.c;
      double Z = -1.0;
      if (std::abs(A) < 1e-12) {
        if (B < 0.0) Z = -C / B;
      } else {
        const double disc = B * B - 4.0 * A * C;
        if (disc >= 0.0) {
          const double r1 = (-B - std::sqrt(disc)) / (2.0 * A);
          const double r2 = (-B + std::sqrt(disc)) / (2.0 * A);
          const double lo = std::min(r1, r2), hi = std::max(r1, r2);
          Z = lo > 0.0 ? lo : hi;
        }
      }
      if (box_z > 0.0 && (Z <= 0.0 || Z > box_z)) {
        const double X = u * box_z, Y = v * box_z;
        const double ground = road.y(X, box_z);
        if (std::abs(X) <= 0.6 && Y <= ground && Y >= ground - 0.8) Z = box_z;
      }
      if (Z > 0.0 && Z < 60.0) disp.at<float>(y, x) = static_cast<float>(cam.disparity(Z));
    }
  }
  return disp;
}

RoadModel road(double a2, double a1, double b2, double b1, double c) {
  RoadModel r;
  r.a2 = a2, r.a1 = a1, r.b2 = b2, r.b1 = b1, r.c = c;
  r.found = true;
  return r;
}

TEST(ElevationMap, RecoversAPlaneAndACurvedRoadWithin2cmAt10m) {
  const core::Camera cam = camera();
  // A flat road, a slope (rising 3 % ahead), a road curving up ahead and falling to the sides.
  for (const RoadModel truth : {road(0, 0, 0, 0, 1.2), road(0, 0.02, 0, -0.03, 1.2),
                                road(0.004, 0.01, -0.002, -0.01, 1.2)}) {
    const cv::Mat disp = render(cam, truth, 0.0);
    const RoadModel fit = fit_road(disp, cam, ElevationParams{});
    ASSERT_TRUE(fit.found);
    for (const double X : {-2.0, 0.0, 2.0})
      EXPECT_NEAR(fit.y(X, 10.0), truth.y(X, 10.0), 0.02) << "X " << X << " b2 " << truth.b2;
  }
}

TEST(ElevationMap, MarksABoxOnTheRoadAsAnObstacleAndTheRoadAsRoad) {
  const core::Camera cam = camera();
  for (const RoadModel truth : {road(0, 0, 0, 0, 1.2), road(0.004, 0.01, -0.002, -0.01, 1.2)}) {
    const cv::Mat disp = render(cam, truth, 6.0);
    const ElevationParams p;
    const RoadModel fit = fit_road(disp, cam, p);
    ASSERT_TRUE(fit.found);
    const ElevationMap map = build_elevation_map(disp, cam, fit, p);
    int r, c;
    ASSERT_TRUE(map.locate(0.0, 6.0, r, c));
    EXPECT_EQ(map.cell.at<std::uint8_t>(r, c), static_cast<std::uint8_t>(Cell::kObstacle));
    // Road cells beside and before the box.
    ASSERT_TRUE(map.locate(2.0, 4.0, r, c));
    EXPECT_EQ(map.cell.at<std::uint8_t>(r, c), static_cast<std::uint8_t>(Cell::kRoad));
    ASSERT_TRUE(map.locate(-0.2, 3.0, r, c));
    EXPECT_EQ(map.cell.at<std::uint8_t>(r, c), static_cast<std::uint8_t>(Cell::kRoad));
    // No obstacle cell anywhere but the box's row of cells.
    for (int rr = 0; rr < map.cell.rows; ++rr)
      for (int cc = 0; cc < map.cell.cols; ++cc)
        if (map.cell.at<std::uint8_t>(rr, cc) == static_cast<std::uint8_t>(Cell::kObstacle)) {
          EXPECT_NEAR((rr + 0.5) * map.cell_m, 6.0, map.cell_m) << rr << " " << cc;
        }
    cv::Mat mask;
    mark_elevation_obstacles(disp, cam, fit, map, p, mask);
    const cv::Point box = cam.project({0.0, truth.y(0.0, 6.0) - 0.4, 6.0});
    EXPECT_EQ(mask.at<std::uint8_t>(box), 255);
    const cv::Point ground = cam.project({0.0, truth.y(0.0, 4.0), 4.0});
    EXPECT_EQ(mask.at<std::uint8_t>(ground), 0);
  }
}

TEST(ElevationMapDetector, MarksANearBoxOnTheRoadNotTheRoadNorAFarBox) {
  const core::Camera cam = camera();
  const core::Envelope envelope;     // |X| <= 0.5 m, -1 <= Y <= 1 m
  const core::ProximityParams near;  // 4 m
  const RoadModel truth = road(0.004, 0.01, -0.002, -0.01, 1.2);
  cv::Mat danger, ttc;
  label_elevation_map(render(cam, truth, 3.0), cam, envelope, ElevationParams{}, near, danger,
                      ttc);
  // The box's face within the envelope's band (its top 0.6 m of 0.8 m are above Y = 1).
  const cv::Point box = cam.project({0.0, truth.y(0.0, 3.0) - 0.5, 3.0});
  EXPECT_EQ(danger.at<std::uint8_t>(box), 255);
  const cv::Point ground = cam.project({1.5, truth.y(1.5, 3.0), 3.0});  // beside the box
  EXPECT_EQ(danger.at<std::uint8_t>(ground), 0);
  EXPECT_GT(cv::countNonZero(danger), 1000);
  // Only the box: each dangerous pixel lies within the box's image, 3 m away.
  const cv::Point top_left = cam.project({-0.6, truth.y(-0.6, 3.0) - 0.8, 3.0});
  const cv::Point bottom_right = cam.project({0.6, truth.y(0.6, 3.0), 3.0});
  const cv::Rect image_of_box(top_left - cv::Point(2, 2), bottom_right + cv::Point(3, 3));
  EXPECT_EQ(cv::countNonZero(danger(image_of_box)), cv::countNonZero(danger));
  // 6 m away it is an obstacle of the map but beyond the alarm distance; no box, no danger.
  label_elevation_map(render(cam, truth, 6.0), cam, envelope, ElevationParams{}, near, danger,
                      ttc);
  EXPECT_EQ(cv::countNonZero(danger), 0);
  label_elevation_map(render(cam, truth, -1.0), cam, envelope, ElevationParams{}, near, danger,
                      ttc);
  EXPECT_EQ(cv::countNonZero(danger), 0);
}

TEST(ElevationMap, NoRoadWithoutGroundAndBadParametersByName) {
  const core::Camera cam = camera();
  const cv::Mat sky(cam.height, cam.width, CV_32FC1, cv::Scalar(-1.0f));
  EXPECT_FALSE(fit_road(sky, cam, ElevationParams{}).found);
  EXPECT_THROW(build_elevation_map(sky, cam, RoadModel{}, ElevationParams{}), core::InputError);
  EXPECT_THROW(fit_road(cv::Mat(4, 4, CV_8UC1), cam, ElevationParams{}), core::InputError);
  ElevationParams p;
  p.cell_m = 0.0;
  p.density_ratio = 0.5;
  const std::vector<std::string> problems = validate(p);
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_EQ(problems[0], "elevation.cell_m=0: must be > 0 (m)");
  EXPECT_EQ(problems[1], "elevation.density_ratio=0.5: must be > 1");
  EXPECT_THROW(fit_road(sky, cam, p), core::InputError);
  EXPECT_TRUE(validate(ElevationParams{}).empty());
}

}  // namespace
}  // namespace sg::vision
