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
                               "stereo: {num_disparities: 128, block_size: 9}\n"
                               "label: {gaps: [1, 3]}\n"
                               "envelope: {half_width_m: 0.8}\n"
                               "signal: {min_area_px: 300, on_k: 1}\n");
  core::DetectorParams p;
  RunSettings s;
  apply_config_file(path, p, s);
  EXPECT_EQ(p.mode, core::Mode::kStereoFlow);
  EXPECT_DOUBLE_EQ(s.pace_fps, 15.0);
  EXPECT_EQ(p.bm.num_disparities, 128);
  EXPECT_EQ(p.bm.block_size, 9);
  EXPECT_EQ(p.stereo.gaps, (std::vector<int>{1, 3}));
  EXPECT_DOUBLE_EQ(p.envelope.half_width_m, 0.8);
  EXPECT_EQ(p.signal.min_area_px, 300);
  EXPECT_EQ(p.signal.on_k, 1);
  const core::DetectorParams defaults;
  EXPECT_EQ(p.bm.uniqueness_ratio, defaults.bm.uniqueness_ratio);
  EXPECT_DOUBLE_EQ(p.envelope.horizon_s, defaults.envelope.horizon_s);
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
                .find("mode=mono"),
            std::string::npos);
  EXPECT_NE(input_error_of([&] { apply_config_file(dir.path() / "nope.yaml", p, s); })
                .find("does not exist"),
            std::string::npos);
  EXPECT_FALSE(
      input_error_of([&] { apply_config_file(write_file(dir, "stereo: [1, 2\n"), p, s); })
          .empty());
}

}  // namespace
}  // namespace sg::io
