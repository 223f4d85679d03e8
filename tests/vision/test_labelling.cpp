#include <gtest/gtest.h>

#include <cmath>

#include "sg/vision/labelling.hpp"

namespace sg::vision {
namespace {

/// f*B = 50 px*m, dt = 0.1 s, principal point at the centre of a 101 x 75 image.
core::Camera small_camera() {
  core::Camera c;
  c.width = 101;
  c.height = 75;
  c.focal_px = 100.0;
  c.baseline_m = 0.5;
  c.cx = 50.0;
  c.cy = 37.0;
  c.fps = 10.0;
  return c;
}

struct Maps {
  cv::Mat now, prev;
};

/// A background of invalid pixels with one 7x5 patch at (x, y) going from d_prev to d_now.
Maps patch(float d_prev, float d_now, int x = 47, int y = 35) {
  Maps m{cv::Mat(75, 101, CV_32F, cv::Scalar(-1.0f)), cv::Mat(75, 101, CV_32F, cv::Scalar(-1.0f))};
  m.prev(cv::Rect(x, y, 7, 5)).setTo(d_prev);
  m.now(cv::Rect(x, y, 7, 5)).setTo(d_now);
  return m;
}

struct Labels {
  cv::Mat danger, ttc;
};

/// TTC to the camera scaled to the time to reach the default contact depth (0.5 m).
float to_contact(double ttc_camera, double d) {
  const double z = small_camera().depth(d);
  return static_cast<float>(ttc_camera * (z - 0.5) / z);
}

Labels label(const cv::Mat& now, const std::vector<PastDisparity>& past,
             const core::StereoLabelParams& p = {}, const core::Envelope& e = {}) {
  Labels l;
  label_stereo(now, past, small_camera(), p, e, l.danger, l.ttc);
  return l;
}

TEST(LabelStereo, ApproachingPatchIsDangerousWithAnalyticTtc) {
  const Maps m = patch(10.0f, 12.0f);  // Z 5 m -> 4.17 m in 0.1 s
  const Labels l = label(m.now, {{1, &m.prev}});
  ASSERT_EQ(l.danger.type(), CV_8UC1);
  ASSERT_EQ(l.ttc.type(), CV_32FC1);
  EXPECT_EQ(cv::countNonZero(l.danger), 35);
  EXPECT_EQ(l.danger.at<uchar>(37, 50), 255);
  // TTC to the camera = dt * D_prev / (D_now - D_prev) = 0.1 * 10 / 2, then to contact.
  EXPECT_NEAR(l.ttc.at<float>(37, 50), to_contact(0.5, 12.0), 1e-6);
  EXPECT_NEAR(l.ttc.at<float>(37, 50), 0.44f, 1e-6);
  EXPECT_TRUE(std::isnan(l.ttc.at<float>(10, 10)));
  EXPECT_EQ(l.danger.at<uchar>(10, 10), 0);
}

TEST(LabelStereo, RecedingOrStillPatchIsSafe) {
  for (auto [prev, now] : {std::pair{12.0f, 10.0f}, std::pair{10.0f, 10.0f}}) {
    const Maps m = patch(prev, now);
    const Labels l = label(m.now, {{1, &m.prev}});
    EXPECT_EQ(cv::countNonZero(l.danger), 0) << prev << " -> " << now;
  }
}

TEST(LabelStereo, ChangeBelowMarginOrBeyondHorizonIsSafe) {
  core::StereoLabelParams p;
  p.min_delta_d_px = 0.5;
  const Maps small = patch(10.0f, 10.4375f);  // delta 0.4375 < 0.5
  EXPECT_EQ(cv::countNonZero(label(small.now, {{1, &small.prev}}, p).danger), 0);
  const Maps at_margin = patch(10.0f, 10.5f);  // TTC 2 s
  EXPECT_EQ(cv::countNonZero(label(at_margin.now, {{1, &at_margin.prev}}, p).danger), 35);
  core::Envelope e;
  e.horizon_s = 1.5;
  EXPECT_EQ(cv::countNonZero(label(at_margin.now, {{1, &at_margin.prev}}, p, e).danger), 0);
}

TEST(LabelStereo, FarPatchIsIgnored) {
  const Maps m = patch(2.5f, 3.0f);  // Z = 16.7 m, TTC 0.5 s
  core::StereoLabelParams p;
  p.min_delta_d_px = 0.5;
  p.z_max_m = 12.0;
  EXPECT_EQ(cv::countNonZero(label(m.now, {{1, &m.prev}}, p).danger), 0);
  p.z_max_m = 20.0;
  EXPECT_EQ(cv::countNonZero(label(m.now, {{1, &m.prev}}, p).danger), 35);
}

TEST(LabelStereo, InvalidPixelsAreNeverDangerous) {
  Maps m = patch(10.0f, 12.0f);
  m.prev.at<float>(36, 48) = -1.0f;  // previous invalid
  m.now.at<float>(37, 49) = -1.0f;   // current invalid
  m.prev.at<float>(38, 50) = 0.0f;   // previous at infinity
  const Labels l = label(m.now, {{1, &m.prev}});
  EXPECT_EQ(l.danger.at<uchar>(36, 48), 0);
  EXPECT_EQ(l.danger.at<uchar>(37, 49), 0);
  EXPECT_EQ(l.danger.at<uchar>(38, 50), 0);
  EXPECT_EQ(cv::countNonZero(l.danger), 32);
  // Invalid neighbours all around a valid rising pixel do not make the neighbours dangerous.
  cv::Mat now(75, 101, CV_32F, cv::Scalar(-1.0f)), prev(75, 101, CV_32F, cv::Scalar(-16.0f));
  now.at<float>(20, 20) = 12.0f;
  prev.at<float>(20, 20) = 10.0f;
  EXPECT_EQ(cv::countNonZero(label(now, {{1, &prev}}).danger), 1);
}

TEST(LabelStereo, EnvelopeBandExcludesGroundLikePoint) {
  // Row 70: Y = (70 - 37) / 100 * Z = 0.33 * 4.17 = 1.375 m, below y_bottom = 1.0 (ground).
  const Maps m = patch(10.0f, 12.0f, 47, 68);
  core::StereoLabelParams p;
  p.use_envelope_band = true;
  core::Envelope e;
  e.y_bottom_m = 1.0;
  Labels l = label(m.now, {{1, &m.prev}}, p, e);
  // Rows 68..72: Y = 1.29..1.46 m, all outside.
  EXPECT_EQ(cv::countNonZero(l.danger), 0);
  e.y_bottom_m = 1.4;  // rows 68..70 (Y <= 1.375) now inside
  l = label(m.now, {{1, &m.prev}}, p, e);
  EXPECT_EQ(cv::countNonZero(l.danger), 21);
  p.use_envelope_band = false;
  l = label(m.now, {{1, &m.prev}}, p, e);
  EXPECT_EQ(cv::countNonZero(l.danger), 35);
  // Overhead: row 2, Y = -35/100 * 4.17 = -1.46 m above y_top = -1.0.
  const Maps top = patch(10.0f, 12.0f, 47, 2);
  p.use_envelope_band = true;
  EXPECT_EQ(cv::countNonZero(label(top.now, {{1, &top.prev}}, p).danger), 0);
}

TEST(LabelStereo, MultiGapTakesTtcOfLongestFlaggingGap) {
  cv::Mat now(75, 101, CV_32F, cv::Scalar(-1.0f));
  cv::Mat d1 = now.clone(), d3 = now.clone();
  // Pixel A: gap 1: 11.5 -> 12, TTC 0.1*11.5/0.5 = 2.3; gap 3: 10 -> 12, TTC 0.3*10/2 = 1.5.
  now.at<float>(30, 30) = 12.0f;
  d1.at<float>(30, 30) = 11.5f;
  d3.at<float>(30, 30) = 10.0f;
  // Pixel B: gap 1 below the margin (11.75 -> 12); gap 3: 11.25 -> 12, TTC to the camera
  // 0.3*11.25/0.75 = 4.5, to contact 3.96 > 3; nothing flags it.
  now.at<float>(31, 31) = 12.0f;
  d1.at<float>(31, 31) = 11.75f;
  d3.at<float>(31, 31) = 11.25f;
  // Pixel C: only gap 3 flags it: 8 -> 12, TTC 0.3*8/4 = 0.6.
  now.at<float>(32, 32) = 12.0f;
  d1.at<float>(32, 32) = 11.875f;
  d3.at<float>(32, 32) = 8.0f;
  // Pixel D: gap 1 flags (10 -> 12, TTC 0.5), gap 3 invalid.
  now.at<float>(33, 33) = 12.0f;
  d1.at<float>(33, 33) = 10.0f;
  core::StereoLabelParams p;
  p.min_delta_d_px = 0.5;
  const Labels l = label(now, {{1, &d1}, {3, &d3}}, p);
  EXPECT_NEAR(l.ttc.at<float>(30, 30), to_contact(1.5, 12.0), 1e-6);
  EXPECT_EQ(l.danger.at<uchar>(31, 31), 0);
  EXPECT_NEAR(l.ttc.at<float>(32, 32), to_contact(0.6, 12.0), 1e-6);
  EXPECT_NEAR(l.ttc.at<float>(33, 33), to_contact(0.5, 12.0), 1e-6);
  EXPECT_EQ(cv::countNonZero(l.danger), 3);
  // Order of `past` does not matter.
  const Labels swapped = label(now, {{3, &d3}, {1, &d1}}, p);
  EXPECT_EQ(cv::countNonZero(swapped.danger != l.danger), 0);
}

TEST(LabelStereo, DepthMoreThanHalvedWithinTheGapIsAnEdgeNotMotion) {
  core::StereoLabelParams p;
  p.max_growth = 2.0;
  const Maps edge = patch(5.0f, 12.0f);  // 10 m -> 4.2 m in 0.1 s: background swept by an edge
  EXPECT_EQ(cv::countNonZero(label(edge.now, {{1, &edge.prev}}, p).danger), 0);
  const Maps halved = patch(6.0f, 12.0f);  // exactly halved: still motion
  EXPECT_EQ(cv::countNonZero(label(halved.now, {{1, &halved.prev}}, p).danger), 35);
  p.max_growth = 0.0;  // disabled
  EXPECT_EQ(cv::countNonZero(label(edge.now, {{1, &edge.prev}}, p).danger), 35);
}

TEST(LabelStereo, NoHistoryMeansNothingIsDangerous) {
  const Maps m = patch(10.0f, 12.0f);
  const Labels l = label(m.now, {});
  EXPECT_EQ(cv::countNonZero(l.danger), 0);
}

/// Naive reference, written the other way round: through depths and a closing speed.
void reference(const cv::Mat& now, const std::vector<std::pair<int, cv::Mat>>& past,
               const core::Camera& cam, const core::StereoLabelParams& p,
               const core::Envelope& e, cv::Mat& danger, cv::Mat& ttc, cv::Mat& ambiguous) {
  danger = cv::Mat::zeros(now.size(), CV_8U);
  ttc = cv::Mat(now.size(), CV_32F, cv::Scalar(std::nanf("")));
  ambiguous = cv::Mat::zeros(now.size(), CV_8U);
  const double dt = 1.0 / cam.fps;
  for (int y = 0; y < now.rows; ++y)
    for (int x = 0; x < now.cols; ++x) {
      const double d = now.at<float>(y, x);
      if (d <= 0) continue;
      const cv::Point3d pt = cam.point(x, y, d);
      if (pt.z > p.z_max_m) continue;
      if (p.use_envelope_band && (pt.y < e.y_top_m || pt.y > e.y_bottom_m)) continue;
      double best = INFINITY;
      int best_k = 0;
      for (const auto& [k, map] : past) {
        const double dp = map.at<float>(y, x);
        if (dp <= 0 || d - dp < p.min_delta_d_px) continue;
        const double z_before = cam.depth(dp);
        if (p.max_growth > 0) {
          if (std::abs(z_before / pt.z - p.max_growth) < 1e-9) ambiguous.at<uchar>(y, x) = 1;
          if (z_before > p.max_growth * pt.z) continue;
        }
        const double closing_speed = (cam.depth(dp) - pt.z) / (k * dt);  // m/s
        const double t = std::max(0.0, pt.z - e.z_contact_m) / closing_speed;
        if (std::abs(t - e.horizon_s) < 1e-9) ambiguous.at<uchar>(y, x) = 1;
        if (t <= e.horizon_s && k > best_k) {
          best_k = k;
          best = t;
        }
      }
      if (best < INFINITY) {
        danger.at<uchar>(y, x) = 255;
        ttc.at<float>(y, x) = static_cast<float>(best);
      }
    }
}

/// Random map of BM-like values: multiples of 1/16 in [0, 40), about 20 % invalid.
cv::Mat random_map(cv::RNG& rng, cv::Size size, const cv::Mat* around = nullptr) {
  cv::Mat m(size, CV_32F);
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x) {
      float v;
      if (rng.uniform(0.0, 1.0) < 0.2) {
        v = -1.0f;
      } else if (around && around->at<float>(y, x) > 0 && rng.uniform(0.0, 1.0) < 0.7) {
        v = around->at<float>(y, x) - rng.uniform(-16, 48) / 16.0f;  // mostly nearer now
        if (v < 0) v = 0;
      } else {
        v = rng.uniform(0, 640) / 16.0f;
      }
      m.at<float>(y, x) = v;
    }
  return m;
}

TEST(LabelStereo, MatchesNaiveReferenceOnRandomMaps) {
  core::Camera cam;
  cam.width = 211;
  cam.height = 157;
  cam.focal_px = 300.0;
  cam.baseline_m = 0.2;
  cam.cx = 104.3;
  cam.cy = 80.1;
  cam.fps = 25.0;
  cv::RNG rng(20240601);
  for (int trial = 0; trial < 4; ++trial) {
    const cv::Size size(cam.width, cam.height);
    const cv::Mat now = random_map(rng, size);
    const cv::Mat p1 = random_map(rng, size, &now), p4 = random_map(rng, size, &now),
                  p9 = random_map(rng, size, &now);
    core::StereoLabelParams p;
    p.gaps = {1, 4, 9};
    p.z_max_m = 6.0 + trial;
    p.min_delta_d_px = 0.25 + 0.25 * trial;
    p.use_envelope_band = trial % 2 == 0;
    p.max_growth = trial == 3 ? 0.0 : 1.5 + 0.5 * trial;
    core::Envelope e;
    e.horizon_s = 2.0 + trial;

    cv::Mat danger, ttc, ref_danger, ref_ttc, ambiguous;
    label_stereo(now, {{1, &p1}, {4, &p4}, {9, &p9}}, cam, p, e, danger, ttc);
    reference(now, {{1, p1}, {4, p4}, {9, p9}}, cam, p, e, ref_danger, ref_ttc, ambiguous);
    int flagged = 0, mismatches = 0;
    for (int y = 0; y < size.height; ++y)
      for (int x = 0; x < size.width; ++x) {
        if (ambiguous.at<uchar>(y, x)) continue;
        const bool a = danger.at<uchar>(y, x) != 0, b = ref_danger.at<uchar>(y, x) != 0;
        if (a != b) {
          ++mismatches;
          continue;
        }
        if (!a) {
          EXPECT_TRUE(std::isnan(ttc.at<float>(y, x)));
          continue;
        }
        ++flagged;
        EXPECT_NEAR(ttc.at<float>(y, x), ref_ttc.at<float>(y, x),
                    1e-5 * ref_ttc.at<float>(y, x));
      }
    EXPECT_EQ(mismatches, 0) << "trial " << trial;
    EXPECT_GT(flagged, 500) << "trial " << trial;  // the maps exercise the dangerous branch
  }
}

}  // namespace
}  // namespace sg::vision
