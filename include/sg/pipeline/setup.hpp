#pragma once
/// A run's setup from the user's choices, shared by the CLI (`stereoguard run`, eval, bench) and
/// the Python module: which input to open (a scenario, a stereo folder or a real input), and the
/// RunOptions from defaults, platform preset, camera-derived defaults, config file and overrides.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "sg/core/platform.hpp"
#include "sg/core/source.hpp"
#include "sg/io/config.hpp"
#include "sg/io/source_factory.hpp"
#include "sg/io/stereo_folder.hpp"
#include "sg/pipeline/runner.hpp"
#include "sg/sim/renderer.hpp"

namespace sg::pipeline {

/// A scenario name or file, a stereo folder, or a real input (left/right, sbs, kitti, euroc,
/// camera with calib or focal/baseline/cx/cy); the CLI's --scenario, --input and input flags.
struct InputOptions {
  std::string scenario;
  std::string input;
  io::SourceSpec spec;
  std::optional<std::string> sbs;  ///< --sbs FILE, or --sbs alone with one --camera
  /// The default scenario when neither is given; empty = one of them is required.
  std::string fallback_scenario;
};

/// An opened input: the source, plus the simulator or folder behind it (for ground truth).
struct OpenedInput {
  std::string name;  ///< scenario name or folder path
  std::unique_ptr<core::FrameSource> source;
  sim::ScenarioSource* scenario = nullptr;  ///< when the input is a scenario
  io::FolderSource* folder = nullptr;       ///< when the input is a stereo folder
};

/// Opens the input; `config` (a config file, may be empty) supplies its `input:` section when
/// no input is given. Throws core::InputError for two inputs at once or a broken input.
OpenedInput open_input(const InputOptions& options, const std::string& config = {});

/// The platform a scenario input is made for: the scenario's, or for a stereo folder the one its
/// scenario.yaml names (`simulate` writes it beside the images); "" without one. Throws
/// core::InputError for a scenario.yaml that does not load.
std::string input_platform(const OpenedInput& input);

/// Detector choices (the CLI's --config, --mode, --num-disparities, --block-size, --gaps, --fps,
/// ...); unset = the config file's value, else the default.
struct DetectorOptions {
  std::string config;  ///< YAML config file path, empty = none
  std::optional<std::string> mode;
  std::optional<std::string> matcher, cost;
  std::optional<int> num_disparities, block_size, min_area;
  std::optional<std::vector<int>> gaps;
  std::optional<std::string> flow_method;
  std::optional<std::string> platform;
  std::optional<double> fps;
  std::optional<std::string> workers, tiles;  ///< a positive integer or "auto"
  std::optional<int> tokens, threads;
  bool tile_flow = false;
};

/// Defaults, then the platform preset (options.platform, else the config's `platform` key, else
/// `default_platform`, e.g. the scenario's), then the config file, then the options. Not
/// validated here (pipeline::run does). `settings`, when given, receives the config file's run
/// settings (outputs, scale). With `camera`, the defaults that depend on it
/// (core::adapt_to_camera: disparity range, pixel sizes, frame gaps) come after the platform
/// preset, before the config file and the options.
RunOptions make_run_options(const DetectorOptions& options,
                            const std::string& default_platform = "",
                            io::RunSettings* settings = nullptr,
                            const core::Camera* camera = nullptr);

/// The depth range `options` measure with `camera`, and the warning of a disparity range capped
/// short of the contact plane (only when the range is the derived one, not the user's).
core::CameraFit camera_fit(const RunOptions& options, const core::Camera& camera);

/// What `stereoguard run` runs: the input opened and resized by the scale, options made for its
/// camera and validated.
struct PreparedRun {
  OpenedInput input;
  RunOptions options;
  io::RunSettings settings;  ///< the config file's run settings
  double scale = 1.0;        ///< input resize factor applied
};

/// open_input, make_run_options for the input's platform, io::scale_source with `scale` (else the
/// config's `scale:`), make_run_options again with the scaled camera, validate. Throws
/// core::InputError naming the first problem.
PreparedRun prepare_run(const InputOptions& input, const DetectorOptions& detector,
                        std::optional<double> scale = std::nullopt);

}  // namespace sg::pipeline
