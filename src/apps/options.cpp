#include "options.hpp"

#include <cstdio>

#include "sg/core/error.hpp"
#include "sg/core/platform.hpp"
#include "sg/io/config.hpp"
#include "sg/io/stereo_folder.hpp"

namespace sg::apps {

void add_input_options(CLI::App& app, InputOptions& options, bool left_right) {
  auto* scenario = app.add_option("--scenario", options.scenario,
                                  "built-in scenario name or scenario YAML file");
  auto* input = app.add_option("--input", options.input, "stereo folder (see docs/inputs.md)");
  scenario->excludes(input);
  add_source_options(app, options, left_right);
}

void add_source_options(CLI::App& app, InputOptions& options, bool left_right) {
  io::SourceSpec& s = options.spec;
  if (left_right) {
    app.add_option("--left", s.left, "left video, image folder or glob pattern ('dir/l*.png')");
    app.add_option("--right", s.right, "right video, image folder or glob pattern");
  }
  app.add_option("--sbs", options.sbs,
                 "side-by-side video (left half = left image); alone with one --camera: a "
                 "side-by-side camera")
      ->expected(0, 1);
  app.add_option("--kitti", s.kitti, "KITTI raw drive folder (image_00, image_01, timestamps)");
  app.add_flag("--kitti-color", s.kitti_color, "with --kitti: colour cameras image_02/image_03");
  app.add_option("--euroc", s.euroc, "EuRoC mav0 folder (cam0, cam1, sensor.yaml, data.csv)");
  app.add_option("--camera", s.camera, "V4L2 camera indices I,J (or I with --sbs)")->delimiter(',');
  app.add_option("--calib", s.calib,
                 "calibration: OpenCV YAML/XML (M1 D1 M2 D2 R T [R1 R2 P1 P2 Q]), KITTI "
                 "calib_cam_to_cam.txt, or a camera.yaml of a rectified pair");
  app.add_option("--focal", s.focal_px, "rectified input: focal length, px");
  app.add_option("--baseline", s.baseline_m, "rectified input: baseline, m");
  app.add_option("--cx", s.cx, "rectified input: principal point x, px (default: image centre)");
  app.add_option("--cy", s.cy, "rectified input: principal point y, px (default: image centre)");
  app.add_option("--input-fps", s.input_fps,
                 "frame rate of an input without timestamps or a stated rate, Hz (default 30)");
}

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

cv::Size parse_size(const std::string& text, const std::string& name, const std::string& example) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || x != 'x') {
    throw core::InputError(name + "=" + text + ": must look like " + example);
  }
  return {w, h};
}

std::string input_platform(const OpenedInput& input) {
  return input.scenario ? input.scenario->scenario().platform : std::string();
}

void add_detector_options(CLI::App& app, DetectorOptions& o) {
  app.add_option("--config", o.config, "YAML config file (flags given too override it)");
  app.add_option("--detector,--mode", o.mode,
                 "detector: stereo-flow (default), stereo, or one the thesis surveys: "
                 "motion-parallax, relative-size, elevation-map, sceneflow-seg, longseq");
  app.add_option("--num-disparities", o.num_disparities,
                 "stereo search range, px (positive multiple of 16; default 64)");
  app.add_option("--block-size", o.block_size, "stereo block size, px (odd, 5..255)");
  app.add_option("--matcher", o.matcher,
                 "stereo matcher: fast (our SIMD block matcher, StereoBM's results; default), bm "
                 "(OpenCV StereoBM), sgbm (OpenCV StereoSGBM) or longseq (thesis 3.2.3: longest "
                 "run of good matches over one row)");
  app.add_option("--cost", o.cost, "fast matcher cost: sad (default) or census");
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
  app.add_option("--workers", o.workers,
                 "W: farm workers computing SM/OF tasks at once, or auto (default: auto, one per "
                 "core)");
  app.add_option("--tiles", o.tiles,
                 "T: row tiles per task, or auto (default: auto, 2 on more than one core)");
  app.add_option("--tokens", o.tokens, "frames in flight (default 0: W + 1)");
  app.add_option("--threads", o.threads, "threads of the task arena (default 0 = all cores)");
  app.add_flag("--tile-flow", o.tile_flow,
               "split optical flow into the T tiles too (faster, not bit-identical)");
}

core::CameraFit camera_fit(const pipeline::RunOptions& options, const core::Camera& camera) {
  core::DetectorParams derived = options.params;
  const core::CameraFit wanted = core::adapt_to_camera(derived, camera);
  core::CameraFit fit = core::depth_range(options.params, camera);
  if (options.params.bm.num_disparities == derived.bm.num_disparities) fit.warning = wanted.warning;
  return fit;
}

std::string format_metres(double m) {
  char text[32];
  std::snprintf(text, sizeof text, m < 10.0 ? "%.2f" : "%.0f", m);
  return text;
}

pipeline::RunOptions make_run_options(const DetectorOptions& o,
                                      const std::string& default_platform,
                                      io::RunSettings* settings_out, const core::Camera* camera) {
  pipeline::RunOptions run;
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
  const pipeline::AutoConfiguration automatic = pipeline::auto_configuration(run.threads);
  if (run.workers == io::kAuto) run.workers = automatic.workers;
  if (run.tiles == io::kAuto) run.tiles = automatic.tiles;
  if (o.tile_flow) run.tile_flow = true;
  run.prefault_heap = true;  // main() keeps freed blocks on one heap
  return run;
}

}  // namespace sg::apps
