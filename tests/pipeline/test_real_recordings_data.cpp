// The real-recording evaluation on the first 60 frames of ../shared/data/unibo_robot_approach
// (label data; skipped when the recording is absent): the detector and the baseline run on the
// video, and their detections are scored against the recording's truth log.
#include <gtest/gtest.h>

#include <filesystem>

#include "sg/eval/truth_log.hpp"
#include "sg/io/source_factory.hpp"
#include "sg/pipeline/central_baseline.hpp"
#include "sg/pipeline/runner.hpp"

namespace sg::pipeline {
namespace {

namespace fs = std::filesystem;

const fs::path kUnibo = fs::path(SG_SHARED_DIR) / "data" / "unibo_robot_approach";
constexpr int kFrames = 60;  // the `creep` phase: the robot barely moves, 2.2-2.7 m from the box

/// The first `limit` frames of a source.
class FirstFrames : public core::FrameSource {
 public:
  FirstFrames(std::unique_ptr<core::FrameSource> inner, int limit)
      : inner_(std::move(inner)), limit_(limit) {}
  std::optional<core::StereoFrame> next() override {
    if (taken_ >= limit_) return std::nullopt;
    ++taken_;
    return inner_->next();
  }
  const core::Camera& camera() const override { return inner_->camera(); }
  int size() const override { return limit_; }

 private:
  std::unique_ptr<core::FrameSource> inner_;
  int limit_, taken_ = 0;
};

class UniboData : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::is_regular_file(kUnibo / "truth.csv"))
      GTEST_SKIP() << "no unibo_robot_approach recording at " << kUnibo;
    io::SourceSpec spec;
    spec.left = (kUnibo / "robotL.mp4").string();
    spec.right = (kUnibo / "robotR.mp4").string();
    spec.calib = (kUnibo / "camera.yaml").string();
    source_ = std::make_unique<FirstFrames>(io::open_source(spec), kFrames);
    const eval::TruthLog log = eval::read_truth_log(kUnibo / "truth.csv");
    criteria_.due_within_m = 0.85;
    truth_ = eval::derive_truth(log, criteria_, source_->camera().frame_period());
  }

  /// What holds whatever the detector: the frames are all scored and quiet.
  void expect_creep_scores(const eval::TruthReport& r) {
    EXPECT_EQ(r.frames, kFrames);
    EXPECT_EQ(r.scored_frames, kFrames);
    EXPECT_EQ(r.unscored_frames, 0);
    EXPECT_EQ(r.rows_past_last_frame, 389 - kFrames);
    EXPECT_TRUE(r.matched_by_frame);
    EXPECT_EQ(r.quiet_frames, kFrames);
    EXPECT_EQ(r.due_frames, 0);
    EXPECT_EQ(r.still_frames, 0);  // creep is quiet, not still
    EXPECT_TRUE(r.contacts.empty());
  }

  std::unique_ptr<core::FrameSource> source_;
  eval::TruthCriteria criteria_;
  std::vector<eval::TruthFrame> truth_;
};

TEST_F(UniboData, DetectorIsScoredAgainstTheTruthLog) {
  RunOptions options;
  options.params.mode = core::Mode::kStereoFlow;
  eval::TruthScorer scorer(truth_, criteria_);
  const RunSummary s =
      run(*source_, options,
          [&](const core::StereoFrame&, const core::Detection& d) { scorer.add(d); });
  EXPECT_EQ(s.frames, kFrames);
  const eval::TruthReport r = scorer.report();
  expect_creep_scores(r);
  EXPECT_EQ(r.quiet_alarm_frames, s.alarm_frames);
  std::cout << r.table();
}

TEST_F(UniboData, BaselineSeesTheSceneAtARoomsDistance) {
  CentralBaselineOptions options;
  options.params.mode = core::Mode::kStereoFlow;
  eval::TruthScorer scorer(truth_, criteria_);
  int with_distance = 0;
  const RunSummary s = run_central_baseline(
      *source_, options, [&](const core::StereoFrame&, const core::Detection& d) {
        scorer.add(d);
        if (d.obstacles.empty()) return;
        ++with_distance;
        // The box and the newspaper-covered wall behind it: a few metres, nothing near.
        EXPECT_GT(d.obstacles[0].distance_m, 1.0) << d.frame;
        EXPECT_LT(d.obstacles[0].distance_m, 8.0) << d.frame;
      });
  EXPECT_EQ(s.frames, kFrames);
  EXPECT_EQ(with_distance, kFrames);  // a textured room: the centre always has disparities
  const eval::TruthReport r = scorer.report();
  expect_creep_scores(r);
  std::cout << r.table();
}

}  // namespace
}  // namespace sg::pipeline
