#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "sg/core/error.hpp"
#include "sg/sim/renderer.hpp"

namespace sg::sim {
namespace {

/// An odd-sized camera so tests stay fast; f scaled from the default 640 x 480.
core::Camera small_camera() {
  core::Camera c;
  c.width = 161;
  c.height = 121;
  c.focal_px = 125.0;
  c.cx = 80.0;
  c.cy = 60.0;
  return c;
}

Scenario small(const std::string& builtin) {
  Scenario s = builtin_scenario(builtin);
  s.camera = small_camera();
  s.noise_sigma = 0.0;
  return s;
}

bool equal(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != b.type()) return false;
  if (a.empty()) return true;
  cv::Mat diff;
  cv::compare(a.reshape(1), b.reshape(1), diff, cv::CMP_NE);
  return cv::countNonZero(diff) == 0;
}

/// Mean absolute difference between `target` and `source` sampled at `map` (CV_32FC2 absolute
/// coordinates), over the pixels of `mask` whose sample lies inside the image.
double warp_error(const cv::Mat& source, const cv::Mat& target, const cv::Mat& map,
                  const cv::Mat& mask) {
  cv::Mat warped;
  cv::remap(source, warped, map, cv::noArray(), cv::INTER_LINEAR, cv::BORDER_CONSTANT, -1);
  double sum = 0;
  int n = 0;
  for (int y = 0; y < target.rows; ++y)
    for (int x = 0; x < target.cols; ++x) {
      const cv::Vec2f m = map.at<cv::Vec2f>(y, x);
      if (!mask.at<std::uint8_t>(y, x) || m[0] < 0 || m[1] < 0 || m[0] > source.cols - 1 ||
          m[1] > source.rows - 1)
        continue;
      sum += std::abs(warped.at<std::uint8_t>(y, x) - target.at<std::uint8_t>(y, x));
      ++n;
    }
  EXPECT_GT(n, 500);
  return n > 0 ? sum / n : 1e9;
}

/// Absolute sampling positions p + offset(p).
cv::Mat absolute_map(const cv::Mat& offset) {
  cv::Mat map(offset.size(), CV_32FC2);
  for (int y = 0; y < map.rows; ++y)
    for (int x = 0; x < map.cols; ++x) {
      const cv::Vec2f o = offset.at<cv::Vec2f>(y, x);
      map.at<cv::Vec2f>(y, x) = {x + o[0], y + o[1]};
    }
  return map;
}

TEST(Renderer, OutputsHaveTheDeclaredTypes) {
  const Renderer r(small("head-on"));
  const RenderedFrame f0 = r.render(0);
  const RenderedFrame f1 = r.render(1);
  EXPECT_EQ(f0.frame.left.type(), CV_8UC1);
  EXPECT_EQ(f0.frame.right.type(), CV_8UC1);
  EXPECT_EQ(f0.frame.left.size(), cv::Size(161, 121));
  EXPECT_EQ(f0.maps.disparity.type(), CV_32FC1);
  EXPECT_EQ(f0.maps.ids.type(), CV_16UC1);
  EXPECT_EQ(f0.maps.danger.type(), CV_8UC1);
  EXPECT_TRUE(f0.maps.flow.empty());
  EXPECT_EQ(f1.maps.flow.type(), CV_32FC2);
  EXPECT_DOUBLE_EQ(f1.frame.time_s, 1.0 / 30.0);
  EXPECT_EQ(f1.frame.index, 1);
  EXPECT_THROW(r.render(r.scenario().frames), std::out_of_range);
}

TEST(Renderer, DangerOnlyRendersTheSameImagesAndTruthWithoutDisparityAndFlow) {
  // With and without motion blur (which needs each camera's flow inside the renderer).
  for (double exposure_s : {0.0, 0.02}) {
    Scenario s = small("head-on");
    s.effects.exposure_time_s = exposure_s;
    const Renderer r(s);
    // Frame 0, and the last, where the box is inside the horizon.
    for (int i : {0, s.frames - 1}) {
      const RenderedFrame all = r.render(i), lean = r.render(i, TruthMapSet::kDangerOnly);
      EXPECT_EQ(cv::norm(all.frame.left, lean.frame.left, cv::NORM_INF), 0.0) << i;
      EXPECT_EQ(cv::norm(all.frame.right, lean.frame.right, cv::NORM_INF), 0.0) << i;
      EXPECT_EQ(cv::norm(all.maps.danger, lean.maps.danger, cv::NORM_INF), 0.0) << i;
      EXPECT_EQ(cv::norm(all.maps.ids, lean.maps.ids, cv::NORM_INF), 0.0) << i;
      EXPECT_GT(cv::countNonZero(lean.maps.ids), 0) << i;
      if (i > 0) {
        EXPECT_GT(cv::countNonZero(lean.maps.danger), 0);
      }
      EXPECT_EQ(all.truth.alarm, lean.truth.alarm) << i;
      EXPECT_TRUE(lean.maps.disparity.empty());
      EXPECT_TRUE(lean.maps.flow.empty());
      EXPECT_FALSE(all.maps.disparity.empty());
    }
  }
}

TEST(Renderer, GroundDisparityMatchesThePlane) {
  Scenario s = small("static");
  s.obstacles.clear();
  const Renderer r(s);
  const RenderedFrame f = r.render(0);
  const double h = s.height_m, b = s.camera.baseline_m, f_px = s.camera.focal_px;
  // Rows below the foot of the background wall see the ground: d = B * (y - cy) / h.
  const int first = static_cast<int>(s.camera.cy + f_px * h / s.background_z_m) + 2;
  for (int y = first; y < f.maps.disparity.rows; ++y)
    for (int x = 0; x < f.maps.disparity.cols; x += 7) {
      const double expected = b * (y - s.camera.cy) / h;
      ASSERT_NEAR(f.maps.disparity.at<float>(y, x), expected, 1e-4 * expected) << x << "," << y;
    }
  // The wall: d = f * B / background_z; above it the sky: d = 0 and a flat gray.
  const int wall_row = static_cast<int>(s.camera.cy) - 5;
  EXPECT_NEAR(f.maps.disparity.at<float>(wall_row, 50), f_px * b / s.background_z_m, 1e-5);
  EXPECT_EQ(f.maps.disparity.at<float>(0, 50), 0.0f);
  EXPECT_EQ(f.frame.left.at<std::uint8_t>(0, 50), f.frame.left.at<std::uint8_t>(0, 120));
  EXPECT_EQ(cv::countNonZero(f.maps.ids), 0);
}

TEST(Renderer, BoxDisparityIsItsFrontFaceDepth) {
  const Scenario s = small("head-on");
  const RenderedFrame f = Renderer(s).render(60);
  const double z_near = 15.0 - 0.25 - 3.0 * 2.0;
  const int cx = static_cast<int>(s.camera.cx);
  EXPECT_EQ(f.maps.ids.at<std::uint16_t>(60, cx), 1);
  EXPECT_NEAR(f.maps.disparity.at<float>(60, cx), s.camera.focal_px * 0.12 / z_near, 1e-4);
  EXPECT_EQ(f.maps.ids.at<std::uint16_t>(5, 5), 0);
}

TEST(Renderer, CollisionTruthFollowsTheAnalyticTtc) {
  const Scenario s = builtin_scenario("head-on");
  const Box& box = s.obstacles[0];
  // Z_near(t) = 14.75 - 3 t; TTC = (Z_near - 0.5) / 3.
  for (double t : {1.8, 2.5, 3.0, 4.5}) {
    const core::ObstacleTruth o = box_collision(s, box, t);
    EXPECT_TRUE(o.colliding) << t;
    ASSERT_TRUE(o.ttc_s.has_value()) << t;
    EXPECT_NEAR(*o.ttc_s, (14.25 - 3.0 * t) / 3.0, 1e-9);
  }
  // TTC 3.75 s > horizon: not colliding and no TTC.
  const core::ObstacleTruth early = box_collision(s, box, 1.0);
  EXPECT_FALSE(early.colliding);
  EXPECT_FALSE(early.ttc_s.has_value());
  // The renderer reports the same per frame.
  const Renderer r(small("head-on"));
  const core::FrameTruth t90 = r.truth(90);
  ASSERT_EQ(t90.obstacles.size(), 1u);
  EXPECT_TRUE(t90.obstacles[0].colliding);
  EXPECT_NEAR(*t90.obstacles[0].ttc_s, (14.25 - 3.0 * 3.0) / 3.0, 1e-9);
  EXPECT_GT(t90.obstacles[0].pixels, 0);
}

TEST(Renderer, CrossingRecedingAndBesideDoNotCollide) {
  for (const char* name : {"crossing", "receding", "ego-pass", "static"}) {
    const Scenario s = builtin_scenario(name);
    for (const Box& b : s.obstacles)
      for (int i = 0; i < s.frames; i += 5) {
        const core::ObstacleTruth o = box_collision(s, b, i / s.camera.fps);
        EXPECT_FALSE(o.colliding) << name << " frame " << i;
        EXPECT_FALSE(o.ttc_s.has_value()) << name;
      }
  }
  Scenario s;
  Box beside;  // approaches, but its X extent [1.0, 1.6] misses |X| <= 0.5
  beside.size_m = {0.6, 1.5, 0.5};
  beside.position_m = {1.3, 0.45, 6.0};
  beside.velocity_mps = {0, 0, -3.0};
  EXPECT_FALSE(box_collision(s, beside, 0.0).colliding);
  Box late = beside;  // on course but contact after the horizon: t_c = (29.75 - 0.5) / 3
  late.position_m = {0, 0.45, 30.0};
  EXPECT_FALSE(box_collision(s, late, 0.0).colliding);
  EXPECT_FALSE(box_collision(s, late, 0.0).ttc_s.has_value());
  EXPECT_TRUE(box_collision(s, late, 7.0).colliding);
  Box overhead = late;  // above the envelope: Y extent [-3.75, -2.25] misses [-1, 1]
  overhead.position_m = {0, -3.0, 5.0};
  EXPECT_FALSE(box_collision(s, overhead, 0.0).colliding);
  Box inside = beside;  // already at the contact depth and in front of the camera
  inside.position_m = {0.0, 0.45, 0.5};
  inside.velocity_mps = {0, 0, 0};
  ASSERT_TRUE(box_collision(s, inside, 0.0).ttc_s.has_value());
  EXPECT_EQ(*box_collision(s, inside, 0.0).ttc_s, 0.0);
  // Ego motion counts: a static box, the camera driving at 2 m/s.
  s.ego_velocity_mps = {0, 0, 2.0};
  Box still = late;
  still.velocity_mps = {0, 0, 0};
  still.position_m = {0, 0.45, 5.25};
  ASSERT_TRUE(box_collision(s, still, 0.5).colliding);
  EXPECT_NEAR(*box_collision(s, still, 0.5).ttc_s, (5.0 - 1.0 - 0.5) / 2.0, 1e-12);
}

TEST(Renderer, FramesToFirstContactEndAtTheFrameTheBoxTouches) {
  Scenario s = builtin_scenario("head-on");
  s.frames = 200;
  // Z_near(t) = 14.75 - 3 t reaches the contact depth 0.5 m at t = 4.75 s: frame 142.5, so
  // frame 143 (t = 4.767 s) is the first in contact and the scene keeps 144 frames.
  EXPECT_EQ(frames_to_first_contact(s), 144);
  // A swaying camera takes the rotating path; the box still touches at frame 143.
  s.camera_motion.pitch_amplitude_deg = 0.5;
  s.camera_motion.oscillation_hz = 1.0;
  ASSERT_TRUE(s.camera_motion.rotates());
  EXPECT_EQ(frames_to_first_contact(s), 144);
  // A shorter scene, and one whose box passes beside, keep their frames.
  s.frames = 100;
  EXPECT_EQ(frames_to_first_contact(s), 100);
  Scenario beside = builtin_scenario("ego-pass");
  EXPECT_EQ(frames_to_first_contact(beside), beside.frames);
}

TEST(Renderer, DangerMaskAndAlarmFollowTheCollidingBox) {
  Scenario s = small("two-obstacles");
  const Renderer r(s);
  const int i = s.frames - 1;
  const RenderedFrame f = r.render(i);
  ASSERT_EQ(f.truth.obstacles.size(), 2u);
  EXPECT_TRUE(f.truth.obstacles[0].colliding);
  EXPECT_FALSE(f.truth.obstacles[1].colliding);
  cv::Mat box1 = f.maps.ids == 1;
  EXPECT_EQ(cv::countNonZero(box1), f.truth.obstacles[0].pixels);
  EXPECT_TRUE(equal(box1, f.maps.danger));
  EXPECT_EQ(f.truth.alarm, f.truth.obstacles[0].pixels >= s.min_area_px);
  // truth() agrees with render().
  const core::FrameTruth t = r.truth(i);
  EXPECT_EQ(t.alarm, f.truth.alarm);
  EXPECT_EQ(t.obstacles[0].pixels, f.truth.obstacles[0].pixels);
  EXPECT_EQ(t.obstacles[1].pixels, f.truth.obstacles[1].pixels);
  // A higher min_area silences the alarm but not the danger mask.
  s.min_area_px = f.truth.obstacles[0].pixels + 1;
  const RenderedFrame g = Renderer(s).render(i);
  EXPECT_FALSE(g.truth.alarm);
  EXPECT_TRUE(equal(g.maps.danger, f.maps.danger));
}

TEST(Renderer, FlowWarpsThePreviousFrameOntoTheCurrentOne) {
  // A box moving sideways and towards a still camera, then a still box seen from a camera moving
  // forward and sideways (ground, background and box all move in the image).
  Scenario moving = small("head-on");
  moving.obstacles[0].size_m = {2.0, 2.0, 1.0};
  moving.obstacles[0].position_m = {-1.0, 0.2, 6.0};
  moving.obstacles[0].velocity_mps = {1.5, 0.0, -3.0};
  Scenario ego = moving;
  ego.obstacles[0].velocity_mps = {0, 0, 0};
  ego.ego_velocity_mps = {0.6, 0.0, 4.0};
  for (const Scenario* s : {&moving, &ego}) {
    const Renderer r(*s);
    const int i = 20;
    const RenderedFrame prev = r.render(i - 1);
    const RenderedFrame cur = r.render(i);
    const bool ego_motion = s == &ego;
    cv::Mat mask = ego_motion ? cv::Mat(cur.maps.disparity > 0) : cv::Mat(cur.maps.ids > 0);
    cv::erode(mask, mask, cv::Mat(), cv::Point(-1, -1), 2);  // skip occlusion edges
    const double with_flow =
        warp_error(prev.frame.left, cur.frame.left, absolute_map(cur.maps.flow), mask);
    const double without = warp_error(prev.frame.left, cur.frame.left,
                                      absolute_map(cv::Mat::zeros(mask.size(), CV_32FC2)), mask);
    EXPECT_LT(with_flow, 3.0) << ego_motion;  // bilinear sampling, texture scale change
    EXPECT_LT(with_flow, 0.3 * without) << ego_motion << " without flow " << without;
  }
}

TEST(Renderer, DisparityMapsLeftOntoRight) {
  for (const char* name : {"head-on", "static"}) {
    const Renderer r(small(name));
    const RenderedFrame f = r.render(60);
    cv::Mat offset(f.maps.disparity.size(), CV_32FC2), shifted(offset.size(), CV_32FC2);
    for (int y = 0; y < offset.rows; ++y)
      for (int x = 0; x < offset.cols; ++x) {
        const float d = f.maps.disparity.at<float>(y, x);
        offset.at<cv::Vec2f>(y, x) = {-d, 0.0f};
        shifted.at<cv::Vec2f>(y, x) = {-d - 2.0f, 0.0f};
      }
    cv::Mat mask = f.maps.disparity > 0;
    const double matched = warp_error(f.frame.right, f.frame.left, absolute_map(offset), mask);
    const double off = warp_error(f.frame.right, f.frame.left, absolute_map(shifted), mask);
    EXPECT_LT(matched, 3.0) << name;
    EXPECT_LT(matched, 0.3 * off) << name << " 2 px off: " << off;
  }
}

TEST(Renderer, FramesArePureFunctionsOfTheIndex) {
  Scenario s = small("two-obstacles");
  s.noise_sigma = 2.0;
  const Renderer a(s), b(s);
  a.render(3);
  const RenderedFrame x = a.render(7);
  const RenderedFrame y = b.render(7);
  const RenderedFrame z = a.render(7);
  for (const RenderedFrame* o : {&y, &z}) {
    EXPECT_TRUE(equal(x.frame.left, o->frame.left));
    EXPECT_TRUE(equal(x.frame.right, o->frame.right));
    EXPECT_TRUE(equal(x.maps.disparity, o->maps.disparity));
    EXPECT_TRUE(equal(x.maps.flow, o->maps.flow));
    EXPECT_TRUE(equal(x.maps.ids, o->maps.ids));
  }
  // Thread count does not change the output.
  const int threads = cv::getNumThreads();
  cv::setNumThreads(1);
  const RenderedFrame serial = a.render(7);
  cv::setNumThreads(threads);
  EXPECT_TRUE(equal(x.frame.left, serial.frame.left));
  EXPECT_TRUE(equal(x.frame.right, serial.frame.right));
  EXPECT_TRUE(equal(x.maps.flow, serial.maps.flow));
}

TEST(Renderer, NoiseAndGainAreApplied) {
  Scenario s = small("static");
  const RenderedFrame clean = Renderer(s).render(4);
  s.noise_sigma = 3.0;
  s.right_gain = 0.8;
  const Renderer r(s);
  const RenderedFrame noisy = r.render(4);
  cv::Mat diff;
  cv::subtract(noisy.frame.left, clean.frame.left, diff, cv::noArray(), CV_32F);
  cv::Scalar mean, stddev;
  cv::meanStdDev(diff, mean, stddev);
  EXPECT_NEAR(stddev[0], 3.0, 0.4);
  EXPECT_NEAR(mean[0], 0.0, 0.3);
  // Different frames and sides draw different noise: the sky (flat) shows it.
  const RenderedFrame other = r.render(5);
  EXPECT_FALSE(equal(noisy.frame.left.row(0), other.frame.left.row(0)));
  // The right image is scaled by right_gain: its sky (gray 200 in the left) is near 160.
  EXPECT_NEAR(cv::mean(noisy.frame.right.row(0))[0], 160.0, 1.0);
  EXPECT_NEAR(cv::mean(noisy.frame.left.row(0))[0], 200.0, 1.0);
}

TEST(Renderer, InvalidScenarioIsRejected) {
  Scenario s = small("head-on");
  s.frames = 0;
  EXPECT_THROW(Renderer{s}, core::InputError);
}

TEST(ScenarioSource, StreamsEveryFrameWithItsTruth) {
  Scenario s = small("head-on");
  s.frames = 4;
  ScenarioSource source(s);
  EXPECT_EQ(source.size(), 4);
  EXPECT_EQ(source.camera().width, 161);
  for (int i = 0; i < 4; ++i) {
    const auto frame = source.next();
    ASSERT_TRUE(frame.has_value());
    EXPECT_EQ(frame->index, i);
    EXPECT_DOUBLE_EQ(frame->time_s, i / 30.0);
    EXPECT_EQ(source.last_truth().frame, i);
    // What scoring needs (TruthMapSet::kDangerOnly), not the disparity and flow.
    EXPECT_EQ(source.last_maps().danger.size(), cv::Size(161, 121));
    EXPECT_EQ(source.last_maps().ids.size(), cv::Size(161, 121));
    EXPECT_TRUE(source.last_maps().flow.empty());
    EXPECT_TRUE(source.last_maps().disparity.empty());
  }
  EXPECT_FALSE(source.next().has_value());
}

TEST(ScenarioSource, PendingFramesRenderWhenLoadedAsNextRendersThem) {
  Scenario s = small("head-on");
  s.frames = 4;
  ScenarioSource eager(s), lazy(s);
  std::vector<core::PendingFrame> pending;
  while (auto p = lazy.next_pending()) pending.push_back(std::move(*p));
  ASSERT_EQ(pending.size(), 4u);
  // Loaded out of order (a dropped frame is never loaded): each frame depends on its index only.
  std::vector<core::StereoFrame> loaded(pending.size());
  for (size_t i : {2u, 0u, 3u}) loaded[i] = pending[i].load();
  for (size_t i = 0; i < pending.size(); ++i) {
    const auto frame = eager.next();
    ASSERT_TRUE(frame.has_value());
    EXPECT_TRUE(pending[i].load_where_read);
    EXPECT_EQ(pending[i].index, frame->index);
    EXPECT_EQ(pending[i].time_s, frame->time_s);
    if (i == 1) continue;
    EXPECT_EQ(loaded[i].index, frame->index);
    EXPECT_EQ(loaded[i].time_s, frame->time_s);
    EXPECT_EQ(cv::norm(loaded[i].left, frame->left, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(loaded[i].right, frame->right, cv::NORM_INF), 0.0);
  }
}

/// GT alarm of every `step`-th frame of a built-in at full resolution, plus its last frame
/// (truth() only casts rays, no shading).
std::vector<std::pair<int, bool>> alarms(const std::string& name, int step) {
  const Renderer r(builtin_scenario(name));
  const int frames = r.scenario().frames;
  std::vector<std::pair<int, bool>> out;
  for (int i = 0; i < frames; i += step) out.emplace_back(i, r.truth(i).alarm);
  if (out.back().first != frames - 1) out.emplace_back(frames - 1, r.truth(frames - 1).alarm);
  return out;
}

TEST(Builtins, HeadOnAlarmsOnlyInItsLastThreeSeconds) {
  // Contact at t = (15 - 0.25 - 0.5) / 3 = 4.75 s; alarm when TTC <= 3 s, i.e. t >= 1.75 s.
  const auto expected = [](int i) { return i / 30.0 >= 1.75 - 1e-9; };
  for (const auto& [i, alarm] : alarms("head-on", 4)) EXPECT_EQ(alarm, expected(i)) << i;
  const Renderer r(builtin_scenario("head-on"));
  EXPECT_FALSE(r.truth(52).alarm);  // t = 1.733 s
  EXPECT_TRUE(r.truth(53).alarm);   // t = 1.767 s
  EXPECT_LE((r.scenario().frames - 1) / 30.0, 4.75);  // the last frame comes before contact
  EXPECT_GE((r.scenario().frames - 1) / 30.0, 4.6);
}

TEST(Builtins, HarmlessScenariosNeverAlarm) {
  for (const char* name : {"static", "receding", "crossing", "ego-pass"})
    for (const auto& [i, alarm] : alarms(name, 5)) EXPECT_FALSE(alarm) << name << " frame " << i;
}

TEST(Builtins, CollidingScenariosAlarmNearTheEnd) {
  for (const char* name : {"ego-wall", "two-obstacles", "pedestrian", "head-on-fast"}) {
    const auto a = alarms(name, 6);
    EXPECT_FALSE(a.front().second) << name;
    EXPECT_TRUE(a.back().second) << name;
    // Once on, the alarm stays on (constant velocities, the box keeps growing).
    const auto first = std::find_if(a.begin(), a.end(), [](const auto& p) { return p.second; });
    EXPECT_TRUE(std::all_of(first, a.end(), [](const auto& p) { return p.second; })) << name;
  }
  // ego-wall: TTC = (14 - 2 t - 0.5) / 2 <= 3 from t = 3.75 s.
  const Renderer wall(builtin_scenario("ego-wall"));
  EXPECT_FALSE(wall.truth(112).alarm);
  EXPECT_TRUE(wall.truth(113).alarm);
  // two-obstacles: box 1 (left) collides, box 2 (right) never does.
  const Renderer two(builtin_scenario("two-obstacles"));
  const core::FrameTruth last = two.truth(two.scenario().frames - 1);
  EXPECT_TRUE(last.obstacles[0].colliding);
  EXPECT_FALSE(last.obstacles[1].colliding);
}

}  // namespace
}  // namespace sg::sim
