#pragma once
/// Options shared by the commands: input selection and detector parameters.
#include <CLI/CLI.hpp>
#include <memory>
#include <optional>
#include <string>

#include "sg/core/params.hpp"
#include "sg/core/source.hpp"
#include "sg/io/stereo_folder.hpp"
#include "sg/pipeline/runner.hpp"
#include "sg/sim/renderer.hpp"

namespace sg::apps {

/// --scenario NAME|FILE or --input DIR.
struct InputOptions {
  std::string scenario;
  std::string input;
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

void add_input_options(CLI::App& app, InputOptions& options);
OpenedInput open_input(const InputOptions& options);

/// Detector flags (--config, --mode, --num-disparities, --block-size, --gaps, --fps, ...).
struct DetectorOptions {
  std::string config;
  std::optional<std::string> mode;
  std::optional<int> num_disparities, block_size, min_area;
  std::optional<std::vector<int>> gaps;
  std::optional<std::string> flow_method;
  std::optional<std::string> platform;
  std::optional<double> fps;
  std::optional<int> workers, tiles, tokens, threads;
  bool tile_flow = false;
};

void add_detector_options(CLI::App& app, DetectorOptions& options);
/// Defaults, then the platform preset (--platform, else the config's `platform` key, else
/// `default_platform`, e.g. the scenario's), then the config file, then the flags. Not validated
/// here (pipeline::run does).
pipeline::RunOptions make_run_options(const DetectorOptions& options,
                                      const std::string& default_platform = "");
/// The platform a scenario input is made for ("" for a folder or a scenario without one).
std::string input_platform(const OpenedInput& input);

}  // namespace sg::apps
