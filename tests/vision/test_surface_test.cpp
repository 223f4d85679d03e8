#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <opencv2/core.hpp>
#include <vector>

#include "sg/vision/surface_test.hpp"

namespace sg::vision {
namespace {

constexpr float kSentinel = -7.0f;

/// Bit patterns, so that NaN equals NaN and -0 differs from 0.
std::vector<std::uint32_t> bits(const std::vector<float>& v) {
  std::vector<std::uint32_t> out(v.size());
  std::memcpy(out.data(), v.data(), v.size() * sizeof(float));
  return out;
}

struct Case {
  cv::Vec3d velocity;
  int y = 0, x0 = 0, x1 = 0;
  std::vector<float> disparity;
};

/// Random runs of one row: disparities on the matcher's 1/16 px grid and continuous ones, from
/// 0.6 to 90 px (about 100 m to 0.7 m with f B = 60), velocities approaching and receding.
std::vector<Case> random_cases(int count, std::uint64_t seed) {
  cv::RNG rng(seed);
  std::vector<Case> cases;
  for (int i = 0; i < count; ++i) {
    Case c;
    c.velocity = cv::Vec3d(rng.uniform(-2.0, 2.0), rng.uniform(-1.0, 1.0), rng.uniform(-12.0, 2.0));
    c.y = rng.uniform(0, 480);
    c.x0 = rng.uniform(0, 600);
    c.x1 = std::min(640, c.x0 + rng.uniform(0, 90));
    c.disparity.assign(640, 0.0f);
    const double base = rng.uniform(0.6, 90.0);
    const bool grid = rng.uniform(0, 2) == 0;
    for (float& d : c.disparity) {
      const double v = std::max(0.6, base + rng.gaussian(0.2 * base));
      d = grid ? static_cast<float>(std::round(v * 16.0) / 16.0) : static_cast<float>(v);
    }
    cases.push_back(std::move(c));
  }
  return cases;
}

SurfaceTest frame_test() {
  core::Camera cam;  // f = 500 px, B = 0.12 m
  core::SceneFlowParams p;
  return make_surface_test(cam, core::Envelope{}, p, 20.0 / 30.0);
}

/// Outputs of test_surface_run and of the reference for every case, with sentinels around the
/// run; counts of dangerous pixels.
void run_both(const SurfaceTest& k, double keep, const std::vector<Case>& cases, int& dangerous,
              int& safe) {
  dangerous = safe = 0;
  for (const Case& c : cases) {
    std::vector<float> fast(640, kSentinel), slow(640, kSentinel);
    test_surface_run(k, c.velocity, keep, c.y, c.x0, c.x1, c.disparity.data(), fast.data());
    test_surface_run_reference(k, c.velocity, keep, c.y, c.x0, c.x1, c.disparity.data(),
                               slow.data());
    const std::vector<std::uint32_t> a = bits(fast), b = bits(slow);
    const auto first = std::mismatch(a.begin(), a.end(), b.begin()).first - a.begin();
    ASSERT_EQ(a, b) << "run y " << c.y << " x " << c.x0 << ".." << c.x1 << " V " << c.velocity
                    << " on " << surface_test_target() << ": first at x " << first << ", "
                    << fast[static_cast<size_t>(first)] << " against "
                    << slow[static_cast<size_t>(first)] << " (d "
                    << c.disparity[static_cast<size_t>(first)] << ")";
    for (int x = 0; x < 640; ++x) {
      if (x < c.x0 || x >= c.x1) {
        ASSERT_EQ(fast[static_cast<size_t>(x)], kSentinel) << "wrote outside the run at " << x;
        continue;
      }
      (std::isnan(fast[static_cast<size_t>(x)]) ? safe : dangerous) += 1;
    }
  }
}

TEST(SurfaceTest, EveryTargetEqualsTheScalarReferenceBitForBit) {
  const std::vector<Case> cases = random_cases(3000, 11);
  for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    ASSERT_EQ(surface_test_target(), hwy::TargetName(target));
    // keep 1: no doubt; the others: a surface's doubt leaves part of its approach.
    for (double keep : {1.0, 0.71, 0.3}) {
      int dangerous = 0, safe = 0;
      run_both(frame_test(), keep, cases, dangerous, safe);
      // Both verdicts occur often, so that a kernel wrong either way fails.
      EXPECT_GT(dangerous, 5000) << hwy::TargetName(target) << " keep " << keep;
      EXPECT_GT(safe, 5000) << hwy::TargetName(target) << " keep " << keep;
    }
  }
  hwy::SetSupportedTargetsForTest(0);
}

TEST(SurfaceTest, ReportsTheContactTimeOfAPointStraightAhead) {
  // d = 12 px: Z = 60 / 12 = 5 m on the optical axis, approaching at 2 m/s: t_c = (5 - 0.5) / 2.
  const SurfaceTest k = frame_test();
  std::vector<float> d(640, 12.0f), ttc(640, kSentinel);
  test_surface_run(k, {0.0, 0.0, -2.0}, 1.0, 240, 300, 340, d.data(), ttc.data());
  for (int x = 300; x < 340; ++x) EXPECT_FLOAT_EQ(ttc[static_cast<size_t>(x)], 2.25f) << x;
  // Receding, too slow to show over the span, or passing wide: never dangerous.
  for (const cv::Vec3d& v : {cv::Vec3d(0, 0, 2), cv::Vec3d(0, 0, -0.2), cv::Vec3d(4, 0, -2)}) {
    test_surface_run(k, v, 1.0, 240, 300, 340, d.data(), ttc.data());
    for (int x = 300; x < 340; ++x) EXPECT_TRUE(std::isnan(ttc[static_cast<size_t>(x)])) << v;
  }
}

TEST(SurfaceTest, ADoubtedSurfaceIsTestedWithTheShareOfItsApproachLeft) {
  // Z = 5 m ahead, approaching at 1.8 m/s: t_c = (5 - 0.5) / 1.8 = 2.5 s. A doubt of sigma_V m/s
  // leaves keep = 1 - sigma_V / 1.8 of the approach to test; the TTC reported stays that of V.
  std::vector<float> d(640, 12.0f), ttc(640, kSentinel);
  const cv::Vec3d v(0.0, 0.0, -1.8);
  test_surface_run(frame_test(), v, 1.0, 240, 312, 328, d.data(), ttc.data());
  EXPECT_FLOAT_EQ(ttc[312], 2.5f);
  // sigma_V 0.25 m/s: 1.55 m/s reaches contact after 2.9 s, inside the 3 s horizon.
  test_surface_run(frame_test(), v, 1.0 - 0.25 / 1.8, 240, 312, 328, d.data(), ttc.data());
  EXPECT_FLOAT_EQ(ttc[312], 2.5f);
  // sigma_V 0.5 m/s: 1.3 m/s needs 3.46 s, beyond the horizon.
  test_surface_run(frame_test(), v, 1.0 - 0.5 / 1.8, 240, 312, 328, d.data(), ttc.data());
  EXPECT_TRUE(std::isnan(ttc[312]));
}

}  // namespace
}  // namespace sg::vision
