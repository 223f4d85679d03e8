#pragma once
/// Options shared by the commands: input selection and detector parameters.
#include <CLI/CLI.hpp>
#include <memory>
#include <optional>
#include <string>

#include "sg/core/params.hpp"
#include "sg/core/platform.hpp"
#include "sg/core/source.hpp"
#include "sg/io/config.hpp"
#include "sg/io/source_factory.hpp"
#include "sg/io/stereo_folder.hpp"
#include "sg/pipeline/runner.hpp"
#include "sg/sim/renderer.hpp"

namespace sg::apps {

/// --scenario NAME|FILE, --input DIR, or a real input (--left/--right, --sbs, --kitti, --euroc,
/// --camera with --calib or --focal/--baseline/--cx/--cy).
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
  std::string name;                          ///< scenario name or folder path
  std::unique_ptr<core::FrameSource> source;
  sim::ScenarioSource* scenario = nullptr;   ///< when the input is a scenario
  io::FolderSource* folder = nullptr;        ///< when the input is a stereo folder
};

/// `left_right`: add --left/--right too (eval has its own for --flow and copies them over).
void add_input_options(CLI::App& app, InputOptions& options, bool left_right = true);
/// Only the real-input flags (--left/--right, --sbs, --kitti, --euroc, --camera, --calib, ...).
void add_source_options(CLI::App& app, InputOptions& options, bool left_right = true);
/// Opens the input; `config` (a --config file, may be empty) supplies its `input:` section when
/// no input flag is given.
OpenedInput open_input(const InputOptions& options, const std::string& config = {});

/// "WxH" as a size; InputError "<name>=<text>: must look like <example>" otherwise.
cv::Size parse_size(const std::string& text, const std::string& name, const std::string& example);

/// Detector flags (--config, --mode, --num-disparities, --block-size, --gaps, --fps, ...).
struct DetectorOptions {
  std::string config;
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

void add_detector_options(CLI::App& app, DetectorOptions& options);
/// Defaults, then the platform preset (--platform, else the config's `platform` key, else
/// `default_platform`, e.g. the scenario's), then the config file, then the flags. Not validated
/// here (pipeline::run does). `settings`, when given, receives the config file's run settings
/// (outputs, scale).
/// With `camera`, the defaults that depend on it (core::adapt_to_camera: disparity range, pixel
/// sizes, frame gaps) come after the platform preset, before the config file and the flags.
pipeline::RunOptions make_run_options(const DetectorOptions& options,
                                      const std::string& default_platform = "",
                                      io::RunSettings* settings = nullptr,
                                      const core::Camera* camera = nullptr);
/// The depth range `options` measure with `camera`, and the warning of a disparity range capped
/// short of the contact plane (only when the range is the derived one, not the user's).
core::CameraFit camera_fit(const pipeline::RunOptions& options, const core::Camera& camera);
/// A distance for a person to read: "0.47" below 10 m, "20" from there.
std::string format_metres(double m);
/// The platform a scenario input is made for ("" for a folder or a scenario without one).
std::string input_platform(const OpenedInput& input);

}  // namespace sg::apps
