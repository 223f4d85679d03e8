#include <gtest/gtest.h>

#include <fstream>

#include "io_test_util.hpp"
#include "sg/io/config.hpp"

namespace sg::io {
namespace {

using testing_util::input_error_of;
using testing_util::ScratchDir;

std::filesystem::path write_file(const ScratchDir& dir, const std::string& text) {
  const auto path = dir.path() / "config.yaml";
  std::ofstream(path) << text;
  return path;
}

TEST(Config, SetsOnlyTheGivenFields) {
  ScratchDir dir;
  const auto path = write_file(dir,
                               "mode: stereo-flow\nfps: 15\n"
                               "stereo: {num_disparities: 128, block_size: 9, coarse_fill: true, "
                               "periodic_ratio: 0.3}\n"
                               "label: {gaps: [1, 3], max_growth: 3.0}\n"
                               "envelope: {half_width_m: 0.8}\n"
                               "signal: {min_area_px: 300, on_k: 1}\n");
  core::DetectorParams p;
  RunSettings s;
  apply_config_file(path, p, s);
  EXPECT_EQ(p.mode, core::Mode::kStereoFlow);
  EXPECT_DOUBLE_EQ(s.pace_fps, 15.0);
  EXPECT_EQ(p.bm.num_disparities, 128);
  EXPECT_EQ(p.bm.block_size, 9);
  EXPECT_TRUE(p.bm.coarse_fill);
  EXPECT_DOUBLE_EQ(p.bm.periodic_ratio, 0.3);
  EXPECT_EQ(p.stereo.gaps, (std::vector<int>{1, 3}));
  EXPECT_DOUBLE_EQ(p.stereo.max_growth, 3.0);
  EXPECT_DOUBLE_EQ(p.envelope.half_width_m, 0.8);
  EXPECT_EQ(p.signal.min_area_px, 300);
  EXPECT_EQ(p.signal.on_k, 1);
  const core::DetectorParams defaults;
  EXPECT_EQ(p.bm.uniqueness_ratio, defaults.bm.uniqueness_ratio);
  EXPECT_DOUBLE_EQ(p.envelope.horizon_s, defaults.envelope.horizon_s);
}

// workers and tiles: auto (the default) or a positive integer, in the file as on the command line.
TEST(Config, WorkersAndTilesAreAutoOrAPositiveCount) {
  EXPECT_EQ(parse_count_or_auto("auto", "--workers"), kAuto);
  EXPECT_EQ(parse_count_or_auto("3", "--workers"), 3);
  for (const char* bad : {"0", "-1", "2x", "", "AUTO", "1.5"})
    EXPECT_NE(input_error_of([&] { parse_count_or_auto(bad, "--tiles"); }).find("--tiles"),
              std::string::npos)
        << bad;
  ScratchDir dir;
  core::DetectorParams p;
  RunSettings s;
  EXPECT_EQ(s.workers, kAuto);
  EXPECT_EQ(s.tiles, kAuto);
  apply_config_file(write_file(dir, "workers: 2\ntiles: auto\n"), p, s);
  EXPECT_EQ(s.workers, 2);
  EXPECT_EQ(s.tiles, kAuto);
  EXPECT_NE(input_error_of([&] { apply_config_file(write_file(dir, "workers: 0\n"), p, s); })
                .find("config.workers"),
            std::string::npos);
}

TEST(Config, FlowAndSceneFlowSections) {
  ScratchDir dir;
  const auto path = write_file(dir,
                               "flow: {method: farneback, fb_levels: 4}\n"
                               "scene_flow:\n"
                               "  gaps: [2, 6]\n"
                               "  v_min_mps: 0.5\n"
                               "  z_max_m: 15\n"
                               "  edge_margin_px: 3\n"
                               "  longest_gap_decides: false\n"
                               "  startup_doubt_se: 1.5\n"
                               "  surface_bridge_m: 0.5\n"
                               "  chain_outlier_px: 3\n"
                               "  chain_outlier_fraction: 0.4\n"
                               "  exclude_ground: true\n"
                               "  ground: {tolerance_m: 0.1, min_inliers: 50, side_margin_px: 0.5,\n"
                               "           split_surfaces: false}\n");
  core::DetectorParams p;
  RunSettings s;
  apply_config_file(path, p, s);
  EXPECT_EQ(p.flow.method, core::FlowMethod::kFarneback);
  EXPECT_EQ(p.flow.fb_levels, 4);
  EXPECT_EQ(p.scene_flow.gaps, (std::vector<int>{2, 6}));
  EXPECT_DOUBLE_EQ(p.scene_flow.v_min_mps, 0.5);
  EXPECT_DOUBLE_EQ(p.scene_flow.z_max_m, 15.0);
  EXPECT_EQ(p.scene_flow.edge_margin_px, 3);
  EXPECT_FALSE(p.scene_flow.longest_gap_decides);
  EXPECT_DOUBLE_EQ(p.scene_flow.startup_doubt_se, 1.5);
  EXPECT_DOUBLE_EQ(p.scene_flow.surface_bridge_m, 0.5);
  EXPECT_DOUBLE_EQ(p.scene_flow.chain_outlier_px, 3.0);
  EXPECT_DOUBLE_EQ(p.scene_flow.chain_outlier_fraction, 0.4);
  EXPECT_TRUE(p.scene_flow.exclude_ground);
  EXPECT_DOUBLE_EQ(p.scene_flow.ground.tolerance_m, 0.1);
  EXPECT_EQ(p.scene_flow.ground.min_inliers, 50);
  EXPECT_DOUBLE_EQ(p.scene_flow.ground.side_margin_px, 0.5);
  EXPECT_FALSE(p.scene_flow.ground.split_surfaces);
  const core::DetectorParams defaults;
  EXPECT_EQ(p.scene_flow.use_envelope_band, defaults.scene_flow.use_envelope_band);
  EXPECT_EQ(p.stereo.gaps, defaults.stereo.gaps);  // Stereo mode's gaps are another section
}

TEST(Config, BadFlowMethodAndUnknownSceneFlowKeysAreNamed) {
  ScratchDir dir;
  core::DetectorParams p;
  RunSettings s;
  auto path = write_file(dir, "flow: {method: lucas-kanade}\n");
  std::string message = input_error_of([&] { apply_config_file(path, p, s); });
  EXPECT_NE(message.find("flow.method=lucas-kanade"), std::string::npos) << message;
  path = write_file(dir, "scene_flow: {ground: {tolerance: 0.1}}\n");
  message = input_error_of([&] { apply_config_file(path, p, s); });
  EXPECT_NE(message.find("scene_flow.ground.tolerance"), std::string::npos) << message;
  path = write_file(dir, "scene_flow: {gaps: one}\n");
  message = input_error_of([&] { apply_config_file(path, p, s); });
  EXPECT_NE(message.find("scene_flow.gaps"), std::string::npos) << message;
}

TEST(Config, PlatformKeyIsReadButLeftToTheCaller) {
  ScratchDir dir;
  const auto path = write_file(dir, "platform: car\nenvelope: {half_width_m: 0.8}\n");
  EXPECT_EQ(config_platform(path), std::optional<std::string>("car"));
  core::DetectorParams p;
  RunSettings s;
  apply_config_file(path, p, s);
  EXPECT_EQ(s.platform, "car");
  EXPECT_EQ(p.bm.num_disparities, core::DetectorParams{}.bm.num_disparities);  // not applied
  EXPECT_DOUBLE_EQ(p.envelope.half_width_m, 0.8);
  EXPECT_FALSE(config_platform(write_file(dir, "mode: stereo\n")).has_value());
}

TEST(Config, EmptyFileChangesNothing) {
  ScratchDir dir;
  core::DetectorParams p;
  RunSettings s;
  apply_config_file(write_file(dir, ""), p, s);
  EXPECT_EQ(p.bm.num_disparities, core::DetectorParams{}.bm.num_disparities);
}

TEST(Config, UnknownKeyIsNamed) {
  ScratchDir dir;
  core::DetectorParams p;
  RunSettings s;
  const auto path = write_file(dir, "signal: {min_aera_px: 3}\n");
  const std::string message = input_error_of([&] { apply_config_file(path, p, s); });
  EXPECT_NE(message.find("signal.min_aera_px"), std::string::npos) << message;
  EXPECT_NE(message.find(path.string()), std::string::npos) << message;
}

TEST(Config, WrongTypeIsNamed) {
  ScratchDir dir;
  core::DetectorParams p;
  RunSettings s;
  const auto path = write_file(dir, "stereo: {block_size: large}\n");
  EXPECT_NE(input_error_of([&] { apply_config_file(path, p, s); }).find("stereo.block_size"),
            std::string::npos);
}

TEST(Config, BadModeMissingFileAndBadYaml) {
  ScratchDir dir;
  core::DetectorParams p;
  RunSettings s;
  EXPECT_NE(input_error_of([&] { apply_config_file(write_file(dir, "mode: mono\n"), p, s); })
                .find("detector=mono"),
            std::string::npos);
  EXPECT_NE(input_error_of([&] { apply_config_file(dir.path() / "nope.yaml", p, s); })
                .find("does not exist"),
            std::string::npos);
  EXPECT_FALSE(
      input_error_of([&] { apply_config_file(write_file(dir, "stereo: [1, 2\n"), p, s); })
          .empty());
}

TEST(Config, StereoMatcherAndCost) {
  ScratchDir dir;
  core::DetectorParams p;
  RunSettings s;
  auto path = write_file(dir, "stereo: {matcher: fast, cost: census}\n");
  apply_config_file(path, p, s);
  EXPECT_EQ(p.bm.matcher, core::Matcher::kFast);
  EXPECT_EQ(p.bm.cost, core::MatchCost::kCensus);
  path = write_file(dir, "stereo: {matcher: elas}\n");
  const std::string message = input_error_of([&] { apply_config_file(path, p, s); });
  EXPECT_NE(message.find("stereo.matcher=elas"), std::string::npos) << message;
  path = write_file(dir,
                    "stereo: {matcher: longseq, longseq_cost_max: 9.5, longseq_best_max: 4,"
                    " longseq_both_ways: false}\n");
  apply_config_file(path, p, s);
  EXPECT_EQ(p.bm.matcher, core::Matcher::kLongSeq);
  EXPECT_DOUBLE_EQ(p.bm.longseq_cost_max, 9.5);
  EXPECT_DOUBLE_EQ(p.bm.longseq_best_max, 4.0);
  EXPECT_FALSE(p.bm.longseq_both_ways);
}

TEST(Config, DetectorAndTheSurveyedDetectorsSections) {
  ScratchDir dir;
  core::DetectorParams p;
  RunSettings s;
  auto path = write_file(dir,
                         "detector: relative-size\n"
                         "motion_parallax: {smooth_px: 5, flow_min_px_s: 9}\n"
                         "relative_size: {gap_frames: 6, cluster_min: 3}\n"
                         "elevation: {cell_m: 0.25, seed: 7}\n"
                         "sceneflow_seg: {grid_step_px: 2, v_min_mps: 0.5}\n"
                         "proximity: {alarm_distance_m: 6}\n");
  apply_config_file(path, p, s);
  EXPECT_EQ(p.mode, core::Mode::kRelativeSize);
  EXPECT_EQ(p.motion_parallax.smooth_px, 5);
  EXPECT_DOUBLE_EQ(p.motion_parallax.flow_min_px_s, 9.0);
  EXPECT_EQ(p.relative_size.gap_frames, 6);
  EXPECT_EQ(p.relative_size.cluster_min, 3);
  EXPECT_DOUBLE_EQ(p.elevation.cell_m, 0.25);
  EXPECT_EQ(p.elevation.seed, 7u);
  EXPECT_EQ(p.sceneflow_seg.grid_step_px, 2);
  EXPECT_DOUBLE_EQ(p.sceneflow_seg.v_min_mps, 0.5);
  EXPECT_DOUBLE_EQ(p.proximity.alarm_distance_m, 6.0);
  // The longseq detector selects its matcher; a key of no section is an error naming it.
  path = write_file(dir, "mode: longseq\n");
  apply_config_file(path, p, s);
  EXPECT_EQ(p.bm.matcher, core::Matcher::kLongSeq);
  path = write_file(dir, "elevation: {cell_size: 1}\n");
  const std::string message = input_error_of([&] { apply_config_file(path, p, s); });
  EXPECT_NE(message.find("elevation.cell_size"), std::string::npos) << message;
}

}  // namespace
}  // namespace sg::io
