#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "sg/core/error.hpp"
#include "sg/vision/scene_flow.hpp"
#include "sg/vision/segment_motion.hpp"
#include "synthetic.hpp"

namespace sg::vision {
namespace {

using test::camera;

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

/// An envelope wide and tall enough to hold every patch below: only the TTC decides.
core::Envelope wide() {
  core::Envelope e;
  e.half_width_m = 5.0;
  e.y_top_m = -5.0;
  e.y_bottom_m = 5.0;
  return e;
}

/// Maps of a scene: background at 25 m with unknown velocity, and patches at their depths whose
/// pixels carry `v` plus Gaussian noise of sigma `noise` m/s per component (fixed seed).
struct Maps {
  cv::Mat disp, edges, danger, ttc, velocity;
  Maps() {
    const core::Camera c = camera();
    disp = cv::Mat(c.height, c.width, CV_32F, cv::Scalar(c.disparity(25.0)));
    danger = cv::Mat::zeros(disp.size(), CV_8U);
    edges = cv::Mat::zeros(disp.size(), CV_8U);
    ttc = cv::Mat(disp.size(), CV_32F, cv::Scalar(kNaN));
    velocity = cv::Mat(disp.size(), CV_32FC3, cv::Scalar(kNaN, kNaN, kNaN));
  }
  void patch(const cv::Rect& r, double z, cv::Vec3d v, double noise, cv::RNG& rng) {
    disp(r).setTo(camera().disparity(z));
    for (int y = r.y; y < r.br().y; ++y)
      for (int x = r.x; x < r.br().x; ++x)
        velocity.at<cv::Vec3f>(y, x) =
            cv::Vec3f(v + cv::Vec3d(rng.gaussian(noise), rng.gaussian(noise), rng.gaussian(noise)));
  }
  /// Pixels of r whose own velocity passes the envelope test (the per-pixel labelling).
  int per_pixel_dangerous(const cv::Rect& r, const core::SceneFlowParams& p) const {
    int n = 0;
    for (int y = r.y; y < r.br().y; ++y)
      for (int x = r.x; x < r.br().x; ++x) {
        double t = 0;
        const cv::Vec3d V(velocity.at<cv::Vec3f>(y, x));
        n += heads_into_envelope(camera().point(x, y, disp.at<float>(y, x)), V, wide(), p.v_min_mps,
                                 t);
      }
    return n;
  }
};

const cv::Rect kLeft(30, 40, 40, 40), kRight(100, 40, 40, 40);

// The velocity of a point 6 m ahead whose TTC is 3.3 s, 10 % over the 3 s horizon, measured with
// a 15 % noise per pixel: pixel by pixel a large part of the patch looks dangerous; pooled, none.
TEST(PoolSurfaceMotion, TtcJustOverTheHorizonRaisesNoPixelOnceItIsPooled) {
  const core::SceneFlowParams p;
  Maps m;
  cv::RNG rng(11);
  const double vz = -(6.0 - 0.5) / 3.3;
  m.patch(kLeft, 6.0, {0, 0, vz}, 0.15 * -vz, rng);
  EXPECT_GT(m.per_pixel_dangerous(kLeft, p), 150);  // the early alarm pooling removes
  pool_surface_motion(m.disp, camera(), wide(), p, 2.0, m.edges, m.danger, m.ttc, m.velocity);
  EXPECT_EQ(cv::countNonZero(m.danger), 0);
  const cv::Vec3f v = m.velocity.at<cv::Vec3f>(60, 50);
  EXPECT_NEAR(v[2], vz, 0.05 * -vz);
}

// Just under the horizon (2.7 s) the whole patch is dangerous with about the true TTC, where the
// per-pixel test keeps only part of it; the background beyond z_max is no surface.
TEST(PoolSurfaceMotion, TtcJustUnderTheHorizonMarksTheWholeSurface) {
  const core::SceneFlowParams p;
  Maps m;
  cv::RNG rng(12);
  const double vz = -(6.0 - 0.5) / 2.7;
  m.patch(kLeft, 6.0, {0, 0, vz}, 0.15 * -vz, rng);
  EXPECT_LT(m.per_pixel_dangerous(kLeft, p), kLeft.area() * 9 / 10);
  // Candidates without a velocity of their own (their source lay near a past edge) take the
  // surface's.
  m.velocity(cv::Rect(40, 50, 10, 10)).setTo(cv::Scalar(kNaN, kNaN, kNaN));
  pool_surface_motion(m.disp, camera(), wide(), p, 2.0, m.edges, m.danger, m.ttc, m.velocity);
  EXPECT_EQ(cv::countNonZero(m.danger(kLeft)), kLeft.area());
  EXPECT_EQ(cv::countNonZero(m.danger), kLeft.area());
  EXPECT_NEAR(m.ttc.at<float>(60, 50), 2.7, 0.1);
  EXPECT_TRUE(std::isnan(m.ttc.at<float>(10, 10)));
  EXPECT_TRUE(std::isnan(m.velocity.at<cv::Vec3f>(10, 10)[0]));
}

// The noise gate of the labelling holds for the pooled motion: a motion that would grow the
// disparity by less than min_delta_d_px over the gaps measured (here 0.14 px over 0.05 s) is noise.
TEST(PoolSurfaceMotion, MotionTooSmallToShowOverTheSpanIsNoise) {
  const core::SceneFlowParams p;
  Maps m;
  cv::RNG rng(14);
  m.patch(kLeft, 6.0, {0, 0, -(6.0 - 0.5) / 2.7}, 0.0, rng);
  pool_surface_motion(m.disp, camera(), wide(), p, 0.05, m.edges, m.danger, m.ttc, m.velocity);
  EXPECT_EQ(cv::countNonZero(m.danger), 0);
  pool_surface_motion(m.disp, camera(), wide(), p, 0.5, m.edges, m.danger, m.ttc, m.velocity);
  EXPECT_EQ(cv::countNonZero(m.danger), kLeft.area());
}

// Surfaces apart (pixels beyond z_max between them) keep their own velocities: an approaching patch
// does not make a static one beside it dangerous; a minority of mismatched pixels (20 % at 30 m/s
// towards the camera) does not move the median.
TEST(PoolSurfaceMotion, SurfacesKeepTheirOwnVelocityAndOutliersDoNotCount) {
  const core::SceneFlowParams p;
  Maps m;
  cv::RNG rng(13);
  m.patch(kLeft, 5.0, {0.1, 0, -2.0}, 0.2, rng);
  m.patch(kRight, 5.0, {0, 0, 0}, 0.2, rng);
  for (int y = kRight.y; y < kRight.br().y; ++y)
    for (int x = kRight.x; x < kRight.x + 8; ++x) m.velocity.at<cv::Vec3f>(y, x) = {0, 0, -30};
  pool_surface_motion(m.disp, camera(), wide(), p, 2.0, m.edges, m.danger, m.ttc, m.velocity);
  EXPECT_EQ(cv::countNonZero(m.danger(kRight)), 0);
  EXPECT_NEAR(m.velocity.at<cv::Vec3f>(60, 120)[2], 0.0, 0.1);
  EXPECT_NEAR(m.velocity.at<cv::Vec3f>(60, 50)[2], -2.0, 0.1);
  EXPECT_EQ(cv::countNonZero(m.danger(kLeft)), kLeft.area());
}

// A chain short of its window (the first frames of a stream): each surface's velocity is
// doubted by the scatter of its own positions about its fitted line. Two patches 6 m away
// approach at 2.2 m/s (TTC 2.5 s) over 6 samples 1/30 s apart. The left one's mean residuals
// scatter by about 1 cm (a large, well-measured face; pixel noise of 5 cm averages out over its
// 1600 pixels): doubted by about 0.2 m/s, its slowest plausible approach still meets the horizon.
// The right one's follow a staircase of up to 20 cm, as the thin pole's did: its doubt exceeds
// its approach. A fifth of the left patch are mismatches (-30 m/s, residuals of 1 m): outside
// the middle half of its V_z, they are no part of its scatter.
TEST(PoolSurfaceMotion, AShortChainTrustsEachSurfaceAsFarAsItsOwnScatterAllows) {
  const core::SceneFlowParams p;
  const cv::Vec3d v(0, 0, -(6.0 - 0.5) / 2.5);
  const std::vector<double> times = {0.0, -1 / 30.0, -2 / 30.0, -3 / 30.0, -4 / 30.0, -5 / 30.0};
  const std::vector<double> clean = {0.01, -0.01, 0.0, 0.01, -0.01, 0.0};
  const std::vector<double> stairs = {0.1, 0.05, -0.2, -0.15, 0.1, 0.1};
  auto run = [&](bool doubted) {
    Maps m;
    cv::RNG rng(21);
    m.patch(kLeft, 6.0, v, 0.05, rng);
    m.patch(kRight, 6.0, v, 0.05, rng);
    const int slots = static_cast<int>(times.size());
    ChainResiduals startup{cv::Mat(m.disp.size(), CV_32FC(slots)), times};
    std::fill_n(startup.residuals_m.ptr<float>(), startup.residuals_m.total() * slots, kNaN);
    auto fill = [&](const cv::Rect& r, const std::vector<double>& common) {
      for (int y = r.y; y < r.br().y; ++y)
        for (int x = r.x; x < r.br().x; ++x) {
          float* res = startup.residuals_m.ptr<float>(y) + x * slots;
          for (int j = 0; j < slots; ++j)
            res[j] = static_cast<float>(common[static_cast<size_t>(j)] + rng.gaussian(0.05));
        }
    };
    fill(kLeft, clean);
    fill(kRight, stairs);
    for (int y = kLeft.y; y < kLeft.br().y; ++y)
      for (int x = kLeft.x; x < kLeft.x + 8; ++x) {
        m.velocity.at<cv::Vec3f>(y, x) = {0, 0, -30};
        float* res = startup.residuals_m.ptr<float>(y) + x * slots;
        for (int j = 0; j < slots; ++j) res[j] = j % 2 ? 1.0f : -1.0f;
      }
    pool_surface_motion(m.disp, camera(), wide(), p, 2.0, m.edges, m.danger, m.ttc, m.velocity,
                        doubted ? startup : ChainResiduals{});
    return std::make_pair(cv::countNonZero(m.danger(kLeft)), cv::countNonZero(m.danger(kRight)));
  };
  const auto trusted = run(false);
  EXPECT_EQ(trusted.first, kLeft.area());
  EXPECT_EQ(trusted.second, kRight.area());
  const auto doubted = run(true);
  EXPECT_EQ(doubted.first, kLeft.area());
  EXPECT_EQ(doubted.second, 0);
}

// The doubt is doubt_se standard errors of the slope of a line through the residuals, widened as
// Student's t for few samples; it needs three samples to measure a scatter at all.
TEST(SlopeDoubt, StandardErrorsOfTheResidualsScatterWidenedForFewSamples) {
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  // Three samples 0.1 s apart, the middle one 1 cm off the line through the others: the line
  // fitted through all three leaves a sum of squares 6.67e-5 m^2 over sum (t - mean)^2 = 0.02 s^2
  // and one degree of freedom: standard error 0.0577 m/s; t_0.975(1) = 12.706 = 6.48 x 1.96.
  EXPECT_NEAR(slope_doubt({0.0, -0.1, -0.2}, {0.0, 0.01, 0.0}, 2.0), 2.0 * 12.706 / 1.96 * 0.057735,
              1e-4);
  EXPECT_NEAR(slope_doubt({0.0, -0.1, -0.2}, {0.0, 0.01, 0.0}, 1.0), 12.706 / 1.96 * 0.057735,
              1e-4);
  // Residuals on any straight line: no scatter.
  EXPECT_NEAR(slope_doubt({0.0, -0.1, -0.3, -0.4}, {0.1, 0.08, 0.04, 0.02}, 2.0), 0.0, 1e-6);
  // Two samples, or three of which one is missing: nothing to measure yet.
  EXPECT_EQ(slope_doubt({0.0, -0.1}, {0.0, 0.01}, 2.0), inf);
  EXPECT_EQ(slope_doubt({0.0, -0.1, -0.2}, {0.0, nan, 0.01}, 2.0), inf);
  // The same scatter over more samples: a smaller doubt, the more so as t shrinks towards 1.96.
  std::vector<double> t, r;
  double last = inf;
  for (int n = 1; n <= 21; ++n) {
    t.push_back(-0.1 * (n - 1));
    r.push_back(n % 2 ? 0.01 : -0.01);
    if (n < 3) continue;
    const double d = slope_doubt(t, r, 2.0);
    EXPECT_LT(d, last) << n;
    last = d;
  }
}

// An object standing on the ground meets it at one disparity, so the two are one continuous
// surface. Pooled together, the larger ground's motion is the object's: a post 3 m ahead walking
// at 1.2 m/s towards a still camera read as still as the floor it stands on (simulated seed 1095:
// warned of 2.3 s after it entered the horizon). Surfaces never join the ground's side with
// what is off it: the post keeps its own motion, the floor its own.
TEST(PoolSurfaceMotion, AnObjectStandingOnTheGroundKeepsItsOwnMotion) {
  const core::SceneFlowParams p;
  const cv::Rect post(70, 20, 8, 60), floor(10, 80, 140, 30);
  auto run = [&](bool with_side) {
    Maps m;
    cv::RNG rng(31);
    m.patch(post, 3.0, {0, 0, -1.2}, 0.05, rng);
    m.patch(floor, 3.0, {0, 0, 0}, 0.05, rng);  // its near row, the post's foot, at the same depth
    cv::Mat side;
    if (with_side) {
      side = cv::Mat::zeros(m.disp.size(), CV_8U);
      side(floor).setTo(255);
    }
    pool_surface_motion(m.disp, camera(), wide(), p, 2.0, m.edges, m.danger, m.ttc, m.velocity,
                        {}, 0.0, side);
    return m;
  };
  const Maps joined = run(false);
  EXPECT_EQ(cv::countNonZero(joined.danger), 0);
  EXPECT_NEAR(joined.velocity.at<cv::Vec3f>(50, 73)[2], 0.0, 0.05);
  const Maps apart = run(true);
  EXPECT_EQ(cv::countNonZero(apart.danger(post)), post.area());
  EXPECT_EQ(cv::countNonZero(apart.danger), post.area());
  EXPECT_NEAR(apart.velocity.at<cv::Vec3f>(50, 73)[2], -1.2, 0.05);
  EXPECT_NEAR(apart.velocity.at<cv::Vec3f>(95, 73)[2], 0.0, 0.05);
  // A mask of another size is an error, not a silent misreading.
  Maps m;
  EXPECT_THROW(pool_surface_motion(m.disp, camera(), wide(), p, 2.0, m.edges, m.danger, m.ttc,
                                   m.velocity, {}, 0.0, cv::Mat::zeros(10, 10, CV_8U)),
               core::InputError);
}

// Velocities from quantized disparities cluster on a few values; the pooled velocity must average
// over them (here 40 % read -2.1 and 60 % -2.0 m/s, mean -2.04), not snap to one as a median does.
TEST(PoolSurfaceMotion, PooledVelocityIsNotStuckToTheQuantizationGrid) {
  const core::SceneFlowParams p;
  Maps m;
  cv::RNG rng(15);
  m.patch(kLeft, 6.0, {0, 0, -2.0}, 0.0, rng);
  for (int y = kLeft.y; y < kLeft.br().y; ++y)
    for (int x = kLeft.x; x < kLeft.x + kLeft.width * 2 / 5; ++x)
      m.velocity.at<cv::Vec3f>(y, x)[2] = -2.1f;
  pool_surface_motion(m.disp, camera(), wide(), p, 2.0, m.edges, m.danger, m.ttc, m.velocity);
  EXPECT_NEAR(m.velocity.at<cv::Vec3f>(60, 50)[2], -2.04, 0.015);
}

// A surface is one object where its disparity is continuous, even across pixels that the
// depth-edge margin keeps out of the test: on overhang (area-integrated edges) such a margin cut a
// 17 x 13 px piece off a bar 4.8 m away, and that piece alone pooled -1.51 m/s for a true -1.40:
// an early alarm. The piece pools with the rest of the bar; a patch at another depth stays apart.
TEST(PoolSurfaceMotion, MarginPixelsJoinTheirObjectButNotAnotherDepth) {
  const core::SceneFlowParams p;
  Maps m;
  cv::RNG rng(17);
  const cv::Rect piece(30, 40, 12, 12), rest(42, 40, 60, 12), band(42, 40, 4, 12);
  m.patch(piece, 4.8, {0, 0, -1.7}, 0.0, rng);  // a few biased pixels of the object
  m.patch(rest, 4.8, {0, 0, -1.4}, 0.0, rng);
  m.edges(band).setTo(255);  // the margin cuts the piece off the rest
  m.velocity(band).setTo(cv::Scalar(kNaN, kNaN, kNaN));
  const cv::Rect other(30, 52, 72, 12);  // touches both, 2 m nearer: another object
  m.patch(other, 2.8, {0, 0, 0}, 0.0, rng);
  pool_surface_motion(m.disp, camera(), wide(), p, 2.0, m.edges, m.danger, m.ttc, m.velocity);
  // The piece takes the interquartile mean of the whole object (144 at -1.7, 672 at -1.4: -1.4).
  EXPECT_NEAR(m.velocity.at<cv::Vec3f>(45, 35)[2], -1.4, 1e-5);
  EXPECT_NEAR(m.velocity.at<cv::Vec3f>(45, 80)[2], -1.4, 1e-5);
  EXPECT_NEAR(m.velocity.at<cv::Vec3f>(58, 35)[2], 0.0, 1e-5);
  // Margin pixels join a surface but are never dangerous themselves.
  EXPECT_EQ(cv::countNonZero(m.danger(band)), 0);
  EXPECT_TRUE(std::isnan(m.velocity.at<cv::Vec3f>(45, 43)[2]));
}

// A thin pole that the matcher breaks into pieces (simulated thin-pole: a stretch 0.25 m long
// matched to the wall behind cut the top 0.3 m off, and that piece alone pooled -1.60 m/s for a
// true -1.40, an early alarm) is one surface again where the pieces resume at a similar
// disparity within surface_bridge_m down the same columns. Here a 6 px post 5 m ahead (f 100 px:
// 0.3 m spans 6 rows); the short top piece reads -1.7 m/s (TTC 2.6 s, under the 3 s horizon),
// the long lower one the true -1.4 (3.2 s).
TEST(PoolSurfaceMotion, PiecesOfAPoleCutByAMismatchedStretchPoolAsOneSurface) {
  auto top_dangerous = [](int stretch_rows, double bridge_m) {
    core::SceneFlowParams p;
    p.surface_bridge_m = bridge_m;
    Maps m;
    cv::RNG rng(19);
    const cv::Rect top(60, 20, 6, 15);
    const cv::Rect mismatched(60, top.br().y, 6, stretch_rows);
    const cv::Rect lower(60, mismatched.br().y, 6, 60);
    m.patch(top, 5.0, {0, 0, -1.7}, 0.0, rng);
    m.patch(mismatched, 7.0, {0, 0, 0}, 0.0, rng);  // the wall's disparity, another surface
    m.velocity(mismatched).setTo(cv::Scalar(kNaN, kNaN, kNaN));
    m.patch(lower, 5.0, {0, 0, -1.4}, 0.0, rng);
    pool_surface_motion(m.disp, camera(), wide(), p, 2.0, m.edges, m.danger, m.ttc, m.velocity);
    EXPECT_EQ(cv::countNonZero(m.danger(lower)), 0);
    return cv::countNonZero(m.danger(top));
  };
  EXPECT_EQ(top_dangerous(5, 0.3), 0);        // bridged: the top pools -1.4 with the rest
  EXPECT_EQ(top_dangerous(8, 0.3), 6 * 15);   // 0.4 m apart: two objects
  EXPECT_EQ(top_dangerous(5, 0.0), 6 * 15);   // no bridge: the biased piece alarms alone
}

TEST(PoolSurfaceMotion, MismatchedMapsAreAnInputError) {
  Maps m;
  cv::Mat small_ttc(10, 10, CV_32F);
  EXPECT_THROW(pool_surface_motion(m.disp, camera(), core::Envelope{}, core::SceneFlowParams{}, 2.0,
                                   m.edges, m.danger, small_ttc, m.velocity),
               core::InputError);
}

// The selection-based interquartile mean against a sorting reference, on sizes 1 to 40 and a
// large surface of quantized values with outliers, in shuffled orders.
TEST(InterquartileMean, AgreesWithTheSortingReference) {
  const auto by_sort = [](std::vector<float> v) {
    std::sort(v.begin(), v.end());
    const size_t q = v.size() / 4;
    double sum = 0.0;
    for (size_t i = q; i < v.size() - q; ++i) sum += v[i];
    return static_cast<float>(sum / static_cast<double>(v.size() - 2 * q));
  };
  cv::RNG rng(7);
  for (int n = 1; n <= 40; ++n) {
    std::vector<float> v(static_cast<size_t>(n));
    for (float& x : v) x = static_cast<float>(std::round(rng.uniform(-3.0, 3.0) * 16) / 16);
    std::vector<float> copy = v;
    EXPECT_FLOAT_EQ(interquartile_mean(copy), by_sort(v)) << n;
  }
  std::vector<float> big(300000);
  for (float& x : big)
    x = rng.uniform(0.0, 1.0) < 0.1 ? static_cast<float>(rng.uniform(-50.0, 50.0))
                                     : static_cast<float>(-1.4 + rng.gaussian(0.05));
  std::vector<float> copy = big;
  EXPECT_FLOAT_EQ(interquartile_mean(copy), by_sort(big));
  // Not the plain mean: the outliers are cut.
  EXPECT_NEAR(by_sort(big), -1.4, 0.01);
}

// A value of weight w counts as w copies: the weighted mean equals the plain interquartile mean
// of the repeated values, and low / high bound that mean's middle ranks, on sizes 1 to 40 with
// weights of stride cells (1 to 256) and quantized values with ties; unit weights give the plain
// mean.
TEST(WeightedInterquartileMean, EqualsTheMeanOfTheRepeatedValues) {
  cv::RNG rng(5);
  std::vector<std::pair<float, int>> scratch;
  for (int n = 1; n <= 40; ++n) {
    std::vector<float> v(static_cast<size_t>(n));
    std::vector<int> w(v.size()), ones(v.size(), 1);
    std::vector<float> repeated;
    for (size_t i = 0; i < v.size(); ++i) {
      v[i] = static_cast<float>(std::round(rng.uniform(-3.0, 3.0) * 8) / 8);
      w[i] = 1 << rng.uniform(0, 9);
      repeated.insert(repeated.end(), static_cast<size_t>(w[i]), v[i]);
    }
    float low = kNaN, high = kNaN;
    const float mean = weighted_interquartile_mean(v.data(), w.data(), v.size(), scratch, &low,
                                                   &high);
    std::sort(repeated.begin(), repeated.end());
    const size_t q = repeated.size() / 4;
    EXPECT_FLOAT_EQ(low, repeated[q]) << n;
    EXPECT_FLOAT_EQ(high, repeated[repeated.size() - q - 1]) << n;
    EXPECT_NEAR(mean, interquartile_mean(repeated), 1e-5) << n;
    std::vector<float> copy = v;
    EXPECT_NEAR(weighted_interquartile_mean(v.data(), ones.data(), v.size(), scratch),
                interquartile_mean(copy), 1e-5)
        << n;
  }
}

// A surface that reaches from 17 m down to 1.25 m (a floor, a wall seen at a slant) whose
// measured V_z drifts with depth: followed on ChainStrides' grid (every pixel far, one in up to
// 128 near), it pools the velocity it pools with every pixel followed, where the grid's samples
// counted once each would give the far part's.
TEST(PoolSurfaceMotion, AStrideGridPoolsAsIfEveryPixelWereFollowed) {
  core::SceneFlowParams p;
  p.use_envelope_band = false;
  ASSERT_GT(p.chain_stride, 1);
  const core::Camera c = camera();
  Maps full, grid;
  const ChainStrides strides(c, p);
  std::vector<float> samples;  // the grid's V_z, each counted once
  for (int y = 0; y < c.height; ++y)
    for (int x = 0; x < c.width; ++x) {
      const float d = 3.0f + 37.0f * static_cast<float>(y) / static_cast<float>(c.height - 1);
      const cv::Vec3f v(0.0f, 0.0f, static_cast<float>(-2.0 + 0.1 * c.depth(d)));
      for (Maps* m : {&full, &grid}) m->disp.at<float>(y, x) = d;
      full.velocity.at<cv::Vec3f>(y, x) = v;
      if (strides.followed(x, y, d)) {
        grid.velocity.at<cv::Vec3f>(y, x) = v;
        samples.push_back(v[2]);
      }
    }
  ASSERT_GT(strides.weight(40.0f), 64);  // the near rows are followed sparsely
  core::SceneFlowParams every = p;
  every.chain_stride = 1;  // every pixel followed: each its own weight
  pool_surface_motion(full.disp, c, wide(), every, 2.0, full.edges, full.danger, full.ttc,
                      full.velocity);
  pool_surface_motion(grid.disp, c, wide(), p, 2.0, grid.edges, grid.danger, grid.ttc,
                      grid.velocity);
  const float every_pixel = full.velocity.at<cv::Vec3f>(60, 80)[2];
  const float on_the_grid = grid.velocity.at<cv::Vec3f>(60, 80)[2];
  EXPECT_NEAR(on_the_grid, every_pixel, 0.02 * std::abs(every_pixel));
  EXPECT_GT(std::abs(interquartile_mean(samples) - every_pixel), 0.2);  // what weighting fixes
}

// The run-based union-find against the pixel-based reference: the same labels and count on
// random maps of surfaces at several depths, with holes, noise below and above the step, thin
// columns cut by stretches of other disparities, and with and without bridging.
TEST(LabelSurfaces, AgreesWithThePixelByPixelReference) {
  cv::RNG rng(21);
  for (int trial = 0; trial < 24; ++trial) {
    const cv::Size size(97 + trial, 61 + 2 * trial);
    cv::Mat disp(size, CV_32F), member(size, CV_8U);
    // Blocks of one disparity each, a few levels apart or within the step of one another.
    const int block = 4 + trial % 5;
    for (int y = 0; y < size.height; ++y)
      for (int x = 0; x < size.width; ++x) {
        const int b = (y / block) * 31 + (x / (block + 3)) * 17;
        const float level = static_cast<float>(10 + (b * 7919 % 5)) * (0.25f + 0.05f * trial);
        disp.at<float>(y, x) = level + static_cast<float>(rng.gaussian(0.15));
        member.at<uint8_t>(y, x) = rng.uniform(0.0, 1.0) < 0.85 ? 255 : 0;
      }
    // Thin posts cut into pieces by stretches of another disparity: what the bridge joins.
    for (int x = 5; x < size.width; x += 23)
      for (int y = 0; y < size.height; ++y) {
        disp.at<float>(y, x) = (y / 6) % 3 == 0 ? 2.0f : 30.0f;
        member.at<uint8_t>(y, x) = 255;
      }
    const float step = trial % 2 == 0 ? 0.5f : 1.0f;
    for (const double bridge : {0.0, 0.2, 1.5}) {
      cv::Mat fast, reference;
      const int n_fast = label_surfaces(disp, member, step, bridge, fast);
      const int n_reference = label_surfaces_reference(disp, member, step, bridge, reference);
      EXPECT_EQ(n_fast, n_reference) << "trial " << trial << " bridge " << bridge;
      EXPECT_EQ(cv::countNonZero(fast != reference), 0) << "trial " << trial << " bridge " << bridge;
      EXPECT_GT(n_fast, 2) << trial;  // surfaces to tell apart, not one or none
    }
  }
  cv::Mat labels;
  EXPECT_THROW(label_surfaces(cv::Mat(4, 4, CV_32F), cv::Mat(4, 5, CV_8U), 1.0f, 0.0, labels),
               core::InputError);
}

// label_surfaces joins a segment to the one above once for the pair, from the first continuous
// pixel pair it finds: a ramp that meets the row above only at its far end (or its near end, or
// only diagonally past either end) still joins it, and one that never meets it does not.
TEST(LabelSurfaces, JoinsTheRowAboveWhereverAlongTheSegmentTheyMeet) {
  struct Ramp {
    const char* what;
    float start, slope;  ///< row 1's disparity at x = 2 + i: start + slope * i, i = 0..9
    bool joined;
  };
  // Row 0: columns 2..11 at 10 px; step 0.5, so a ramp of slope 0.45 stays one segment.
  const Ramp ramps[] = {{"meets at its far end", 14.05f, -0.45f, true},
                        {"meets at its near end", 10.0f, 0.45f, true},
                        {"never meets", 14.05f, 0.45f, false}};
  for (const Ramp& r : ramps) {
    for (const int shift : {0, 1, -1}) {  // row 1 shifted: the meeting pixel pair is diagonal
      cv::Mat disp(3, 16, CV_32F, cv::Scalar(0)), member(3, 16, CV_8U, cv::Scalar(0));
      for (int x = 2; x < 12; ++x) {
        disp.at<float>(0, x) = 10.0f;
        member.at<uint8_t>(0, x) = 255;
        const int i = x - 2, xr = x + shift;
        disp.at<float>(1, xr) = r.start + r.slope * static_cast<float>(i);
        member.at<uint8_t>(1, xr) = 255;
      }
      cv::Mat fast, reference;
      const int n = label_surfaces(disp, member, 0.5f, 0.0, fast);
      EXPECT_EQ(n, label_surfaces_reference(disp, member, 0.5f, 0.0, reference)) << r.what;
      EXPECT_EQ(cv::countNonZero(fast != reference), 0) << r.what << " shift " << shift;
      EXPECT_EQ(n, r.joined ? 2 : 3) << r.what << " shift " << shift;
      EXPECT_EQ(fast.at<int>(0, 2) == fast.at<int>(1, 2 + shift), r.joined) << r.what;
    }
  }
}

}  // namespace
}  // namespace sg::vision
