#include "options.hpp"

#include "sg/core/error.hpp"
#include "sg/core/platform.hpp"
#include "sg/io/config.hpp"
#include "sg/io/stereo_folder.hpp"

namespace sg::apps {

void add_input_options(CLI::App& app, InputOptions& options) {
  auto* scenario = app.add_option("--scenario", options.scenario,
                                  "built-in scenario name or scenario YAML file");
  auto* input = app.add_option("--input", options.input, "stereo folder (see README)");
  scenario->excludes(input);
}

OpenedInput open_input(const InputOptions& options) {
  OpenedInput opened;
  if (!options.input.empty()) {
    opened.name = options.input;
    auto source = std::make_unique<io::FolderSource>(options.input);
    opened.folder = source.get();
    opened.source = std::move(source);
    return opened;
  }
  std::string name = options.scenario.empty() ? options.fallback_scenario : options.scenario;
  if (name.empty()) throw core::InputError("give --scenario NAME|FILE or --input DIR");
  auto source = std::make_unique<sim::ScenarioSource>(sim::resolve_scenario(name));
  opened.name = name;
  opened.scenario = source.get();
  opened.source = std::move(source);
  return opened;
}

std::string input_platform(const OpenedInput& input) {
  return input.scenario ? input.scenario->scenario().platform : std::string();
}

void add_detector_options(CLI::App& app, DetectorOptions& o) {
  app.add_option("--config", o.config, "YAML config file (flags given too override it)");
  app.add_option("--mode", o.mode, "stereo (default) or stereo-flow");
  app.add_option("--num-disparities", o.num_disparities,
                 "stereo search range, px (positive multiple of 16; default 64)");
  app.add_option("--block-size", o.block_size, "stereo block size, px (odd, 5..255)");
  app.add_option("--gaps", o.gaps,
                 "frame gaps k compared by the mode's labelling, e.g. --gaps 1 (the thesis) or "
                 "1,4,10 (Stereo mode default 1,5,15; Stereo-Flow 1,4,10,20)")
      ->delimiter(',');
  app.add_option("--flow-method", o.flow_method,
                 "Stereo-Flow optical flow: dis-ultrafast (default), dis-fast, dis-medium or "
                 "farneback");
  app.add_option("--min-area", o.min_area, "smallest obstacle blob, px (default 150)");
  app.add_option("--platform", o.platform,
                 "detector preset of a platform: robot (default), walker or car (envelope, "
                 "disparity range, depth limits); default: the scenario's");
  app.add_option("--fps", o.fps, "pace the input like a camera at this rate, Hz (0 = no pacing)");
  app.add_option("--workers", o.workers, "W: farm workers computing SM/OF tasks at once (default 1)");
  app.add_option("--tiles", o.tiles, "T: row tiles per task (default 1)");
  app.add_option("--tokens", o.tokens, "frames in flight (default 0 = W + 1)");
  app.add_option("--threads", o.threads, "threads of the task arena (default 0 = all cores)");
  app.add_flag("--tile-flow", o.tile_flow,
               "split optical flow into the T tiles too (faster, not bit-identical)");
}

pipeline::RunOptions make_run_options(const DetectorOptions& o,
                                      const std::string& default_platform) {
  pipeline::RunOptions run;
  io::RunSettings settings;
  std::string platform = default_platform;
  if (!o.config.empty()) {
    if (auto from_file = io::config_platform(o.config)) platform = *from_file;
  }
  if (o.platform) platform = *o.platform;
  core::apply_platform(platform, run.params);
  if (!o.config.empty()) io::apply_config_file(o.config, run.params, settings);
  run.pace_fps = settings.pace_fps;
  run.workers = settings.workers;
  run.tiles = settings.tiles;
  run.tokens = settings.tokens;
  run.threads = settings.threads;
  if (o.mode) run.params.mode = core::parse_mode(*o.mode);
  if (o.num_disparities) run.params.bm.num_disparities = *o.num_disparities;
  if (o.block_size) run.params.bm.block_size = *o.block_size;
  if (o.gaps) {
    if (run.params.mode == core::Mode::kStereoFlow)
      run.params.scene_flow.gaps = *o.gaps;
    else
      run.params.stereo.gaps = *o.gaps;
  }
  if (o.flow_method) run.params.flow.method = core::parse_flow_method(*o.flow_method);
  if (o.min_area) run.params.signal.min_area_px = *o.min_area;
  if (o.fps) run.pace_fps = *o.fps;
  if (o.workers) run.workers = *o.workers;
  if (o.tiles) run.tiles = *o.tiles;
  if (o.tokens) run.tokens = *o.tokens;
  if (o.threads) run.threads = *o.threads;
  if (o.tile_flow) run.tile_flow = true;
  return run;
}

}  // namespace sg::apps
