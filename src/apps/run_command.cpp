// `stereoguard run`: the main job. Detects obstacles on any input (scenario, stereo folder,
// videos, KITTI, EuRoC, camera), writes events, an overlay video and a summary, shows the overlay
// live (--show), and stops cleanly on SIGINT, SIGTERM or the live view's q (docs/live-and-stop.md).
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>
#include <utility>

#include "commands.hpp"
#include "options.hpp"
#include "live_view.hpp"
#include "outputs.hpp"
#include "stop_signals.hpp"
#include "sg/core/error.hpp"
#include "sg/io/events.hpp"
#include "sg/io/overlay.hpp"
#include "sg/par/beside.hpp"

namespace sg::apps {
namespace {

struct RunArgs {
  InputOptions input{.scenario = {}, .input = {}, .spec = {}, .sbs = {},
                     .fallback_scenario = "head-on"};
  DetectorOptions detector;
  OutputOptions outputs;
  std::string events, overlay, summary;
  bool no_timing = false;
  bool quiet = false;
  bool show = false;
};

/// One line when the warning state changes, so a user sees the warnings as they happen.
class WarningPrinter {
 public:
  void operator()(const core::Detection& d, std::ostream& out) {
    // Severity flickers with the TTC estimate: say only when it rises above what this warning
    // already said.
    const bool changed = d.signal != last_signal_ || d.steering != last_steering_ ||
                         (d.signal && d.severity > last_severity_);
    last_signal_ = d.signal;
    last_steering_ = d.steering;
    last_severity_ = d.signal ? std::max(last_severity_, d.severity) : core::Severity::kNone;
    if (!changed) return;
    out << "frame " << std::setw(4) << d.frame << "  t=" << std::fixed
              << std::setprecision(2) << d.time_s << " s  ";
    if (!d.signal) {
      out << "clear\n";
      return;
    }
    out << (d.severity == core::Severity::kDanger ? "DANGER " : "WARNING") << "  regions";
    for (const auto& r : d.regions)
      if (r.fired) out << " " << r.name;
    const core::Obstacle* nearest = nullptr;
    for (const auto& o : d.obstacles)
      if (!nearest || o.distance_m < nearest->distance_m) nearest = &o;
    if (nearest) {
      out << std::setprecision(1) << "  nearest " << nearest->distance_m << " m";
      if (nearest->ttc_s) out << ", TTC " << *nearest->ttc_s << " s";
    }
    out << "  steer " << core::to_string(d.steering) << "\n";
  }

 private:
  bool last_signal_ = false;
  core::Severity last_severity_ = core::Severity::kNone;
  core::Steering last_steering_ = core::Steering::kStraight;
};

void run_main(const RunArgs& args) {
  StopOnSignals stop;
  pipeline::PreparedRun prepared =
      pipeline::prepare_run(args.input, args.detector, args.outputs.scale);
  OpenedInput& in = prepared.input;
  const ResolvedOutputs outputs = resolve_outputs(args.outputs, prepared.settings);
  const core::Camera& cam = in.source->camera();
  pipeline::RunOptions& options = prepared.options;
  options.keep_maps = !outputs.dump.empty();
  options.stop = &stop.flag();
  // Before any output exists: without a display, --show is a user error like a bad path.
  std::optional<LiveView> view;
  if (args.show) view.emplace();

  std::string overlay = args.overlay;
  if (overlay.empty() && args.input.input.empty() && args.input.scenario.empty() &&
      !args.input.spec.any() && !args.input.sbs) {
    overlay = "stereoguard-" + in.name + ".mp4";
  }
  std::optional<io::EventWriter> events;
  if (!args.events.empty()) events.emplace(args.events, !args.no_timing);
  FrameOutputs frame_outputs(outputs, !args.no_timing, !args.quiet && io::stderr_is_terminal(),
                             in.source->size(),
                             options.params.bm.min_disparity + options.params.bm.num_disparities);
  // The video is written under a temporary name and renamed only when the run succeeds, so a
  // failed run never leaves a truncated video that looks complete.
  const std::string overlay_partial = overlay + ".partial.mp4";
  std::optional<io::OverlayWriter> video;
  if (!overlay.empty()) video.emplace(overlay_partial, cv::Size(cam.width, cam.height), cam.fps);

  const core::CameraFit range = camera_fit(options, cam);
  std::cout << "stereoguard run: " << in.name << ", " << cam.width << "x" << cam.height << ", "
            << (in.source->size() >= 0 ? std::to_string(in.source->size()) + " frames, " : "")
            << "mode " << core::to_string(options.params.mode) << ", depth "
            << format_metres(range.near_m) << "-" << format_metres(range.far_m) << " m\n";
  if (!range.warning.empty()) std::cout << "warning: " << range.warning << "\n";
  WarningPrinter printer;
  std::ostringstream warning;
  pipeline::RunSummary summary;
  // Frames for the window, which lives on this thread: the newest one waits here for it.
  par::Latest<std::pair<cv::Mat, double>> for_view;
  const pipeline::DetectionSink sink = [&](const core::StereoFrame& frame,
                                           const core::Detection& d) {
    if (events) events->write(d);
    if (video || view) {
      const cv::Mat drawn = io::draw_overlay(frame, d);
      if (video) video->write(drawn);
      if (view) for_view.put({drawn, d.latency_ms});
    }
    frame_outputs.write(d);
    if (args.quiet) return;
    warning.str("");
    printer(d, warning);
    if (warning.tellp() > 0) {
      frame_outputs.clear_progress();
      std::cout << warning.str() << std::flush;
    }
  };
  try {
    if (!view) {
      summary = pipeline::run(*in.source, options, sink);
    } else {
      // The pipeline beside, the window here: q, Esc or closing it stops the run.
      par::run_beside([&] { summary = pipeline::run(*in.source, options, sink); },
                      [&] {
                        try {
                          const auto next = for_view.take();
                          if (!(next ? view->show(next->first, next->second) : view->poll(5)))
                            stop.request();
                        } catch (...) {
                          stop.request();
                          throw;
                        }
                      });
    }
  } catch (...) {
    if (video) {
      video->close();
      std::filesystem::remove(overlay_partial);
    }
    throw;
  }
  frame_outputs.clear_progress();
  std::cout << "\n" << summary.text();
  if (video) {
    video->close();
    std::filesystem::rename(overlay_partial, overlay);
    std::cout << "overlay           " << overlay << " (" << video->frames_written()
              << " frames)\n";
  }
  if (events) std::cout << "events            " << args.events << "\n";
  frame_outputs.finish(std::cout);
  if (!args.summary.empty()) {
    std::ofstream out(args.summary);
    if (!out) throw core::InputError("cannot write summary file " + args.summary);
    out << summary.to_json().dump(2) << "\n";
    std::cout << "summary           " << args.summary << "\n";
  }
  if (stop.exit_status() != 0) throw ExitStatus{stop.exit_status()};
}

}  // namespace

void add_run_command(CLI::App& app) {
  auto args = std::make_shared<RunArgs>();
  CLI::App* cmd = app.add_subcommand(
      "run",
      "detect obstacles on any input: scenario, stereo folder, videos, KITTI, EuRoC or camera "
      "(default: the head-on scenario)");
  add_input_options(*cmd, args->input);
  add_detector_options(*cmd, args->detector);
  cmd->add_option("--events", args->events, "write one JSON line per frame to this file");
  cmd->add_option("--overlay", args->overlay,
                  "write an overlay video (.mp4); default with no input: stereoguard-head-on.mp4");
  cmd->add_option("--summary", args->summary, "write the run summary as JSON");
  cmd->add_flag("--no-timing", args->no_timing,
                "leave latency_ms out of the events (byte-identical repeated runs)");
  add_output_options(*cmd, args->outputs, /*with_scale=*/true);
  cmd->add_flag("--quiet", args->quiet,
                "do not print warnings as they happen, nor the progress bar (shown only when "
                "stderr is a terminal)");
  cmd->add_flag("--show", args->show,
                "show the overlay live in a window (needs a display); q or Esc stops the run "
                "like Ctrl-C, with exit status 0");
  cmd->callback([args] { run_main(*args); });
}

}  // namespace sg::apps
