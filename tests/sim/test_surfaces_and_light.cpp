// Texture kinds, moving cast shadows and motion blur of the simulator: each changes the images
// the way it claims to and leaves the ground truth alone.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <set>

#include "sg/sim/renderer.hpp"

namespace sg::sim {
namespace {

/// A 160 x 120 camera looking at the ground and a wall 6 m ahead, with a box in front of it.
Scenario plain_scene() {
  Scenario s;
  s.name = "surfaces";
  s.frames = 4;
  s.camera.width = 160;
  s.camera.height = 120;
  s.camera.focal_px = 125.0;
  s.camera.cx = 79.5;
  s.camera.cy = 59.5;
  s.noise_sigma = 0.0;
  s.background_z_m = 6.0;
  Box b;
  b.size_m = {1.0, 1.0, 0.5};
  b.position_m = {0.0, 0.7, 4.0};
  s.obstacles = {b};
  return s;
}

double image_std(const cv::Mat& image, const cv::Rect& roi) {
  cv::Scalar mean, std;
  cv::meanStdDev(image(roi), mean, std);
  return std[0];
}

TEST(Textures, EachKindGivesItsOwnImageAndLowTextureHasLittleContrast) {
  const cv::Rect wall(0, 0, 160, 40);  // above the box: the wall only
  std::set<std::vector<std::uint8_t>> images;
  double noise_std = 0.0, low_std = 0.0;
  for (std::size_t k = 0; k < texture_kind_names().size(); ++k) {
    Scenario s = plain_scene();
    s.background_texture = s.ground_texture = s.obstacles[0].texture = static_cast<TextureKind>(k);
    const RenderedFrame f = Renderer(s).render(0);
    images.insert(std::vector<std::uint8_t>(f.frame.left.datastart, f.frame.left.dataend));
    if (k == 0) noise_std = image_std(f.frame.left, wall);
    if (k == 1) low_std = image_std(f.frame.left, wall);
    EXPECT_GT(image_std(f.frame.left, wall), 2.0) << texture_kind_names()[k];
  }
  EXPECT_EQ(images.size(), texture_kind_names().size());
  EXPECT_LT(low_std, 0.25 * noise_std);
}

TEST(Textures, StripesRepeatAlongTheWall) {
  // Autocorrelation of a wall row: stripes have a second peak (their period) almost as high as
  // the zero shift, value noise has none.
  const auto best_repeat = [](TextureKind kind) {
    Scenario s = plain_scene();
    s.obstacles.clear();
    s.background_texture = kind;
    s.background_seed = 3;
    cv::Mat row;
    Renderer(s).render(0).frame.left.row(20).convertTo(row, CV_64F);
    row -= cv::mean(row)[0];
    const double zero = row.dot(row);
    double best = -1.0;
    for (int shift = 4; shift < 60; ++shift)
      best = std::max(best, row.colRange(0, 160 - shift).dot(row.colRange(shift, 160)) /
                                (zero * (160 - shift) / 160.0));
    return best;
  };
  EXPECT_GT(best_repeat(TextureKind::kStripes), 0.6);
  EXPECT_LT(best_repeat(TextureKind::kNoise), 0.6);
}

TEST(Shadows, ACasterDarkensTheGroundWhereItsShadowFallsAndTheShadowMoves) {
  Scenario lit = plain_scene();
  lit.obstacles.clear();
  lit.background_z_m = 40.0;
  Scenario shaded = lit;
  shaded.shadows.to_light = {0.0, -1.0, 0.0};  // light from straight above
  // A caster 3 m above the ground 5 m ahead, drifting right at 2 m/s.
  shaded.shadows.casters = {{{0.0, lit.height_m - 3.0, 5.0}, {2.0, 0.0, 0.0}, 0.8, 0.5}};
  const Renderer a(lit), b(shaded);
  const auto darkened = [](const cv::Mat& bright, const cv::Mat& dark) {
    cv::Mat ratio;
    cv::Mat fb, fd;
    bright.convertTo(fb, CV_32F);
    dark.convertTo(fd, CV_32F);
    cv::divide(fd, cv::max(fb, 1.0), ratio);
    return ratio;
  };
  const RenderedFrame a0 = a.render(0), b0 = b.render(0), b3 = b.render(3);
  // The ground point under the caster (X 0, Z 5) is at column cx, row cy + f h / Z.
  const int row = static_cast<int>(std::lround(lit.camera.cy + lit.camera.focal_px * lit.height_m / 5.0));
  const cv::Mat r0 = darkened(a0.frame.left, b0.frame.left);
  EXPECT_NEAR(r0.at<float>(row, 80), 0.5, 0.03);           // in the umbra: half the light
  EXPECT_NEAR(r0.at<float>(row, 5), 1.0, 0.01);            // far beside it: untouched
  EXPECT_NEAR(r0.at<float>(10, 80), 1.0, 0.01);            // the wall above: untouched
  // Three frames later (0.1 s, 0.2 m to the right) the shadow's centre moved right.
  const cv::Mat r3 = darkened(a.render(3).frame.left, b3.frame.left);
  const auto centre = [&](const cv::Mat& ratio) {
    double sum = 0, weight = 0;
    for (int x = 0; x < ratio.cols; ++x) {
      const double dark = 1.0 - ratio.at<float>(row, x);
      sum += dark * x;
      weight += dark;
    }
    return sum / weight;
  };
  EXPECT_NEAR(centre(r3) - centre(r0), lit.camera.focal_px * 0.2 / 5.0, 1.0);
  // A shadow is not an obstacle: the truth is that of the lit scene.
  EXPECT_EQ(cv::norm(a0.maps.disparity, b0.maps.disparity, cv::NORM_INF), 0.0);
  EXPECT_EQ(a0.truth.alarm, b0.truth.alarm);
}

/// Mean |horizontal gradient| over the image.
double sharpness(const cv::Mat& image) {
  cv::Mat dx;
  cv::Sobel(image, dx, CV_32F, 1, 0);
  return cv::mean(cv::abs(dx))[0];
}

TEST(MotionBlur, AYawingCameraBlursAlongItsMotionAndAStillOneDoesNot) {
  Scenario still = plain_scene();
  still.obstacles.clear();
  Scenario yawing = still;
  yawing.camera_motion.yaw_rate_dps = 60.0;  // 2 deg a frame: about 4.4 px at f 125
  Scenario blurred = yawing;
  blurred.effects.exposure_time_s = 0.03;  // 0.9 of the frame interval
  const RenderedFrame sharp = Renderer(yawing).render(2), soft = Renderer(blurred).render(2);
  EXPECT_LT(sharpness(soft.frame.left), 0.75 * sharpness(sharp.frame.left));
  EXPECT_LT(sharpness(soft.frame.right), 0.75 * sharpness(sharp.frame.right));
  EXPECT_EQ(cv::norm(sharp.maps.disparity, soft.maps.disparity, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(sharp.maps.flow, soft.maps.flow, cv::NORM_INF), 0.0);
  // Frame 0 is blurred too (its motion comes from the instant before it).
  EXPECT_LT(sharpness(Renderer(blurred).render(0).frame.left),
            0.75 * sharpness(Renderer(yawing).render(0).frame.left));
  // Nothing moves: the exposure changes nothing.
  Scenario still_blurred = still;
  still_blurred.effects.exposure_time_s = 0.03;
  EXPECT_EQ(cv::norm(Renderer(still).render(1).frame.left,
                     Renderer(still_blurred).render(1).frame.left, cv::NORM_INF),
            0.0);
}

}  // namespace
}  // namespace sg::sim
