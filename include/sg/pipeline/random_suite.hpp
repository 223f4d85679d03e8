#pragma once
/// The randomised scene suite (`stereoguard eval --suite random`, docs/random-suite.md): renders
/// and scores the scenes of seeds S, S+1, ..., S+N-1 (sim::random_scenario), several scenes at
/// once, each scene's pipeline on one worker and one tile, and sums up the distributions.
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "sg/eval/detection_metrics.hpp"
#include "sg/pipeline/setup.hpp"

namespace sg::pipeline {

struct RandomSuiteOptions {
  std::uint32_t first_seed = 1000;  ///< seed of the first scene
  int count = 10;                   ///< scenes, >= 1
  cv::Size max_size{0, 0};          ///< larger images are scaled down to fit; 0x0 = no cap
  int max_frames = 0;               ///< frames per scene at most; 0 = no cap (else >= 2)
  int jobs = 0;                     ///< scenes rendered and scored at once; 0 = all cores
  /// Detector choices; each scene applies them over its own platform preset and camera.
  DetectorOptions detector;
};

/// Every violation as text ("count=0: must be >= 1"); empty when valid.
std::vector<std::string> validate(const RandomSuiteOptions& options);

/// What a scene drew that its description leaves out, for breaking the suite's figures down by
/// cause (scripts/suite_breakdown.py reads them from the JSON).
struct RandomSceneTraits {
  std::string ego_motion;           ///< one of sim::kRandomEgoMotions
  double focal_baseline_px_m = 0;   ///< f B: the disparity of a point 1 m away, px
  double noise_sigma = 0;           ///< gray levels
  int jpeg_quality = 0;             ///< 0 = no compression
  double exposure_ms = 0;           ///< motion blur's exposure time
  int shadow_casters = 0;
  std::string ground_texture, background_texture;  ///< sim::texture_kind_names()
  /// Per obstacle left in the scene: shape, path and surface texture.
  std::vector<std::string> shapes, paths, textures;
};

/// One scene's score.
struct RandomSceneResult {
  std::uint32_t seed = 0;
  std::string description;  ///< sim::random_scenario's
  std::string platform;     ///< the detector preset it ran with
  int width = 0, height = 0, frames = 0;
  double fps = 0.0;
  RandomSceneTraits traits;
  eval::DetectionReport report;
  /// Ground truth has alarm frames (a colliding scene); else a clear scene.
  bool colliding() const { return report.gt_alarm_frames > 0; }
  /// Smallest lead over its colliding obstacles, s; nullopt when one was never warned of (or
  /// the scene is clear).
  std::optional<double> lead_s;
  /// The same over the colliding obstacles that entered the horizon in view (their GT TTC at
  /// their first colliding frame at least kEnteringShare of the horizon): the only ones that
  /// can be warned of a whole horizon ahead. An obstacle that starts 1.5 s from contact bounds
  /// lead_s by 1.5 s whatever the detector does. nullopt when one was never warned of, or the
  /// scene has none (`entering` tells which).
  std::optional<double> lead_entering_s;
  int entering = 0;  ///< colliding obstacles that entered the horizon in view
  /// Time from the first ground-truth alarm frame (the obstacle is within the horizon and large
  /// enough) to the first alarm at or after it, s; nullopt when none followed (or clear).
  std::optional<double> first_alarm_delay_s;
  double wall_s = 0.0;  ///< render and score time of the scene, s
  /// Ranks the worst scenes, 0 (perfect) .. 2: colliding: 1 - recall_settled, +1 when an
  /// obstacle was never warned of; clear: the false alarm rate.
  double badness() const;
};

/// An obstacle entered the horizon in view when its first colliding frame's GT TTC is at least
/// this share of the horizon.
inline constexpr double kEnteringShare = 0.9;

/// Mean and percentiles (nearest rank) of a sample; all 0 with count 0.
struct Distribution {
  int count = 0;
  double mean = 0.0, p10 = 0.0, p50 = 0.0, p90 = 0.0;
};
Distribution distribution(std::vector<double> values);

struct RandomSuiteSummary {
  int scenes = 0, colliding = 0, clear = 0;
  Distribution recall_settled;       ///< colliding scenes
  Distribution lead_s;               ///< colliding scenes warned of in time (missed ones apart)
  int missed = 0;                    ///< colliding scenes with an obstacle never warned of
  /// Over the scenes with obstacles that entered the horizon in view, those warned of in time.
  Distribution lead_entering_s;
  int missed_entering = 0;  ///< scenes with an obstacle entering in view never warned of
  Distribution first_alarm_delay_s;  ///< colliding scenes with an alarm after the first GT alarm
  Distribution false_alarm_rate;     ///< clear scenes
  std::vector<std::uint32_t> worst_seeds;  ///< up to 10, worst first (RandomSceneResult::badness)
  double wall_s = 0.0;                     ///< the whole suite, s
};

struct RandomSuiteResult {
  std::vector<RandomSceneResult> scenes;  ///< in seed order
  RandomSuiteSummary summary;
  nlohmann::json to_json() const;
  /// The summary for a person: distributions and the worst scenes, one per line.
  std::string table() const;
};

/// Two histograms side by side, drawn with OpenCV (8-bit BGR, 900x360): the lead of the
/// colliding scenes (s; missed ones in a bar of their own) and the false alarm rate of the clear
/// scenes.
cv::Mat plot_random_suite(const RandomSuiteResult& result);

/// Renders and scores one scene (the pipeline on one worker, one tile, one thread).
RandomSceneResult score_random_scene(std::uint32_t seed, const RandomSuiteOptions& options);

/// Scores every scene; `scene_done` (may be empty) is called once per finished scene, from the
/// thread that scored it, one call at a time. Throws core::InputError for invalid options.
RandomSuiteResult run_random_suite(const RandomSuiteOptions& options,
                                   const std::function<void()>& scene_done = {});

}  // namespace sg::pipeline
