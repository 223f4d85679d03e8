#include "eval_truth.hpp"

#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "sg/core/error.hpp"
#include "sg/eval/truth_log.hpp"
#include "sg/pipeline/central_baseline.hpp"
#include "sg/pipeline/dropping_source.hpp"

namespace sg::apps {
namespace {

constexpr const char* kCentralMedian = "central-median";

eval::TruthCriteria make_criteria(const TruthEvalArgs& args, const core::Envelope& envelope) {
  eval::TruthCriteria c;
  c.z_contact_m = envelope.z_contact_m;
  c.horizon_s = envelope.horizon_s;
  if (args.quiet_phases) c.quiet_phases = eval::parse_phase_list(*args.quiet_phases);
  if (args.due_within_m) {
    if (!std::isfinite(*args.due_within_m) || *args.due_within_m <= 0.0) {
      std::ostringstream msg;
      msg << "due-within=" << *args.due_within_m << ": must be a distance > 0 m";
      throw core::InputError(msg.str());
    }
    c.due_within_m = args.due_within_m;
  }
  return c;
}

nlohmann::json criteria_json(const eval::TruthCriteria& c, const eval::TruthLog& log) {
  return {{"z_contact_m", c.z_contact_m},
          {"horizon_s", c.horizon_s},
          {"due_within_m", c.due_within_m ? nlohmann::json(*c.due_within_m) : nullptr},
          {"quiet_phases", log.has_phase ? nlohmann::json(c.quiet_phases) : nullptr},
          {"distance_column", log.distance_column},
          {"min_closing_mps", c.min_closing_mps},
          {"fit_half_window_s", c.fit_half_window_s}};
}

}  // namespace

void eval_truth_main(const TruthEvalArgs& args) {
  const bool baseline = !args.baseline.empty();
  if (baseline && args.baseline != kCentralMedian) {
    throw core::InputError("baseline-method=" + args.baseline + ": the only baseline is " +
                           kCentralMedian);
  }
  if (args.truth.empty() &&
      (args.due_within_m || args.quiet_phases || !args.distance_column.empty()))
    throw core::InputError("--due-within, --quiet-phases and --distance-column need --truth FILE");
  if (args.drop_every < 0 || args.drop_every == 1)
    throw core::InputError("drop-every=" + std::to_string(args.drop_every) +
                           ": must be 0 (none) or >= 2");
  // The truth first: a broken log fails before minutes of matching.
  std::optional<eval::TruthLog> log;
  if (!args.truth.empty()) {
    eval::TruthLogOptions log_options;
    log_options.distance_column = args.distance_column;
    log = eval::read_truth_log(args.truth, log_options);
  }
  OpenedInput in = open_input(args.input, args.detector.config);
  io::RunSettings settings;
  pipeline::RunOptions options =
      make_run_options(args.detector, input_platform(in), &settings, &in.source->camera());
  const ResolvedOutputs outputs = resolve_outputs(args.outputs, settings);
  if (outputs.scale != 1.0)
    throw core::InputError("scale: eval does not rescale its input; use scale only with run");
  options.keep_maps = !outputs.dump.empty();

  std::optional<eval::TruthCriteria> criteria;
  std::optional<eval::TruthScorer> scorer;
  if (log) {
    criteria = make_criteria(args, options.params.envelope);
    scorer.emplace(eval::derive_truth(*log, *criteria, in.source->camera().frame_period()),
                   *criteria);
  }
  pipeline::DroppingSource dropping(*in.source, args.drop_every);
  FrameOutputs frame_outputs(outputs, true, !args.quiet && io::stderr_is_terminal(),
                             in.source->size(),
                             options.params.bm.min_disparity + options.params.bm.num_disparities);
  const auto sink = [&](const core::StereoFrame&, const core::Detection& d) {
    if (scorer) scorer->add(d);
    frame_outputs.write(d);
  };
  pipeline::RunSummary summary;
  if (baseline) {
    pipeline::CentralBaselineOptions b;
    b.params = options.params;
    b.keep_maps = options.keep_maps;
    summary = pipeline::run_central_baseline(dropping, b, sink);
  } else {
    summary = pipeline::run(dropping, options, sink);
  }
  frame_outputs.clear_progress();

  const std::string who =
      baseline ? std::string("baseline ") + kCentralMedian
               : std::string("stereoguard, mode ") + core::to_string(options.params.mode);
  std::cout << "eval " << in.name;
  if (log) std::cout << " against " << args.truth;
  std::cout << " (" << who;
  if (dropping.dropped() > 0) std::cout << ", " << dropping.dropped() << " frames dropped";
  std::cout << ")\n";
  nlohmann::json j;
  if (scorer) {
    const eval::TruthReport report = scorer->report();
    if (report.rows_past_last_frame > 0) {
      std::cerr << "stereoguard: warning: " << args.truth << " has " << report.rows_past_last_frame
                << " rows past the last frame of " << in.name << " (" << report.frames
                << " frames); they are not scored\n";
    }
    std::cout << report.table();
    j = report.to_json();
    j["truth"] = args.truth;
    j["criteria"] = criteria_json(*criteria, *log);
  } else {
    std::cout << "  frames            " << summary.frames << " (no truth log: alarms only)\n"
              << "  alarm frames      " << summary.alarm_frames << "\n";
    j = {{"frames", summary.frames}, {"alarm_frames", summary.alarm_frames}};
  }
  j["input"] = in.name;
  j["detector"] = baseline ? kCentralMedian : "stereoguard";
  j["mode"] = baseline ? kCentralMedian : core::to_string(options.params.mode);
  j["throughput_fps"] = summary.throughput_fps;
  if (!args.json.empty()) write_json_output(args.json, j);
  frame_outputs.finish(std::cout);
}

}  // namespace sg::apps
