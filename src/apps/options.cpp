#include "options.hpp"

#include <cstdio>

#include "sg/core/error.hpp"

namespace sg::apps {

void add_input_options(CLI::App& app, InputOptions& options, bool left_right) {
  auto* scenario = app.add_option("--scenario", options.scenario,
                                  "built-in scenario name or scenario YAML file");
  auto* input = app.add_option("--input", options.input, "stereo folder (see README)");
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

cv::Size parse_size(const std::string& text, const std::string& name, const std::string& example) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || x != 'x') {
    throw core::InputError(name + "=" + text + ": must look like " + example);
  }
  return {w, h};
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
                 "detector preset of a platform: robot (default), walker, car or drone (envelope, "
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

std::string format_metres(double m) {
  char text[32];
  std::snprintf(text, sizeof text, m < 10.0 ? "%.2f" : "%.0f", m);
  return text;
}


}  // namespace sg::apps
