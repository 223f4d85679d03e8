#include "sg/pipeline/setup.hpp"

#include <filesystem>

#include "sg/core/error.hpp"
#include "sg/core/platform.hpp"
#include "sg/io/scaled_source.hpp"

namespace sg::pipeline {

OpenedInput open_input(const InputOptions& options_in, const std::string& config) {
  InputOptions options = options_in;
  if (options.sbs) {  // --sbs alone: a side-by-side camera
    if (options.sbs->empty()) {
      options.spec.sbs_camera = true;
    } else {
      options.spec.sbs = *options.sbs;
    }
  }
  const bool flags =
      options.spec.any() || options.sbs || !options.input.empty() || !options.scenario.empty();
  if (!config.empty()) {
    core::DetectorParams unused;
    io::RunSettings settings;
    io::apply_config_file(config, unused, settings);
    // The input the flags name, else the config's; its camera from the config, flags on top.
    const io::SourceSpec& c = settings.input;
    io::SourceSpec merged = flags ? options.spec : c;
    merged.calib = c.calib;
    merged.focal_px = c.focal_px;
    merged.baseline_m = c.baseline_m;
    merged.cx = c.cx;
    merged.cy = c.cy;
    merged.input_fps = c.input_fps;
    const io::SourceSpec& f = options.spec;
    if (!f.calib.empty()) merged.calib = f.calib;
    for (auto [to, from] : {std::pair{&merged.focal_px, &f.focal_px},
                            {&merged.baseline_m, &f.baseline_m},
                            {&merged.cx, &f.cx},
                            {&merged.cy, &f.cy},
                            {&merged.input_fps, &f.input_fps}}) {
      if (*from) *to = *from;
    }
    options.spec = merged;
  }
  OpenedInput opened;
  if (options.spec.any()) {
    if (!options.input.empty() || !options.scenario.empty()) {
      throw core::InputError("give one input: --scenario, --input or " + options.spec.name());
    }
    opened.name = options.spec.name();
    opened.source = io::open_source(options.spec);
    return opened;
  }
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
  if (input.scenario) return input.scenario->scenario().platform;
  if (input.folder) {
    // A folder that `simulate` wrote carries its scenario, whose platform made its ground truth.
    const std::filesystem::path file = std::filesystem::path(input.name) / "scenario.yaml";
    if (std::filesystem::is_regular_file(file))
      return sim::load_scenario_file(file.string()).platform;
  }
  return {};
}

core::CameraFit camera_fit(const RunOptions& options, const core::Camera& camera) {
  core::DetectorParams derived = options.params;
  const core::CameraFit wanted = core::adapt_to_camera(derived, camera);
  core::CameraFit fit = core::depth_range(options.params, camera);
  if (options.params.bm.num_disparities == derived.bm.num_disparities) fit.warning = wanted.warning;
  return fit;
}

RunOptions make_run_options(const DetectorOptions& o, const std::string& default_platform,
                            io::RunSettings* settings_out, const core::Camera* camera) {
  RunOptions run;
  io::RunSettings settings;
  std::string platform = default_platform;
  if (!o.config.empty()) {
    if (auto from_file = io::config_platform(o.config)) platform = *from_file;
  }
  if (o.platform) platform = *o.platform;
  core::apply_platform(platform, run.params);
  // run and eval recommend Stereo-Flow: Stereo mode alarms on whatever passes by (crossing,
  // ego-pass, turning). A config file's detector.mode or --mode picks the other.
  run.params.mode = core::Mode::kStereoFlow;
  if (camera) {
    // The camera-derived defaults, for the contact plane (and range, gaps) the config file gives;
    // the file is applied again below, so that the values it sets itself win over derived ones.
    if (!o.config.empty()) io::apply_config_file(o.config, run.params, settings);
    core::adapt_to_camera(run.params, *camera);
  }
  if (!o.config.empty()) io::apply_config_file(o.config, run.params, settings);
  if (settings_out) *settings_out = settings;
  run.pace_fps = settings.pace_fps;
  run.workers = settings.workers;
  run.tiles = settings.tiles;
  run.tokens = settings.tokens;
  run.threads = settings.threads;
  if (o.mode) core::select_detector(run.params, core::parse_mode(*o.mode));
  if (o.num_disparities) run.params.bm.num_disparities = *o.num_disparities;
  if (o.block_size) run.params.bm.block_size = *o.block_size;
  if (o.matcher) run.params.bm.matcher = core::parse_matcher(*o.matcher);
  if (o.cost) run.params.bm.cost = core::parse_match_cost(*o.cost);
  if (o.gaps) {
    if (core::is_surveyed(run.params.mode))
      throw core::InputError(std::string("gaps: the ") + core::to_string(run.params.mode) +
                             " detector compares no frame gaps (stereo and stereo-flow do; "
                             "relative-size has relative_size.gap_frames)");
    if (run.params.mode == core::Mode::kStereoFlow)
      run.params.scene_flow.gaps = *o.gaps;
    else
      run.params.stereo.gaps = *o.gaps;
  }
  if (o.flow_method) run.params.flow.method = core::parse_flow_method(*o.flow_method);
  if (o.min_area) run.params.signal.min_area_px = *o.min_area;
  if (o.fps) run.pace_fps = *o.fps;
  if (o.workers) run.workers = io::parse_count_or_auto(*o.workers, "--workers");
  if (o.tiles) run.tiles = io::parse_count_or_auto(*o.tiles, "--tiles");
  if (o.tokens) run.tokens = *o.tokens;
  if (o.threads) run.threads = *o.threads;
  // auto: from the cores of the task arena (--threads); what ran is in the summary.
  const AutoConfiguration automatic = auto_configuration(run.threads);
  if (run.workers == io::kAuto) run.workers = automatic.workers;
  if (run.tiles == io::kAuto) run.tiles = automatic.tiles;
  if (o.tile_flow) run.tile_flow = true;
  run.prefault_heap = true;  // main() keeps freed blocks on one heap
  return run;
}

PreparedRun prepare_run(const InputOptions& input, const DetectorOptions& detector,
                        std::optional<double> scale) {
  PreparedRun prepared;
  prepared.input = open_input(input, detector.config);
  const std::string platform = input_platform(prepared.input);
  make_run_options(detector, platform, &prepared.settings);
  prepared.scale = scale.value_or(prepared.settings.scale);
  prepared.input.source = io::scale_source(std::move(prepared.input.source), prepared.scale);
  const core::Camera& camera = prepared.input.source->camera();
  prepared.options = make_run_options(detector, platform, &prepared.settings, &camera);
  core::throw_if_invalid(validate(prepared.options, camera), "invalid parameters");
  return prepared;
}

}  // namespace sg::pipeline
