// `stereoguard eval`: detection accuracy against ground truth, or optical-flow accuracy (--flow).
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <vector>

#include "commands.hpp"
#include "eval_stereo.hpp"
#include "eval_suite.hpp"
#include "eval_truth.hpp"
#include "options.hpp"
#include "outputs.hpp"
#include "sg/core/error.hpp"
#include "sg/eval/flow_metrics.hpp"
#include "sg/io/gt_formats.hpp"
#include "sg/io/stereo_folder.hpp"
#include "sg/pipeline/dropping_source.hpp"
#include "sg/pipeline/evaluation.hpp"
#include "sg/pipeline/flow_evaluation.hpp"

namespace sg::apps {
namespace {

namespace fs = std::filesystem;

struct EvalArgs {
  InputOptions input;
  DetectorOptions detector;
  OutputOptions outputs;
  bool quiet = false;
  std::string json;
  // --flow: optical-flow accuracy on image pairs with a forward GT flow (Middlebury .flo).
  bool flow = false;
  std::string left, right, gt, dir;
  std::string flow_methods = "all";
  // --stereo: stereo accuracy against GT disparity.
  bool stereo = false;
  double gt_scale = 0;
  std::string matchers = "bm,sgbm,fast,fast-periodic,fast-filled,fast-census";
  int drop_every = 0;  ///< drop every n-th frame (5 = 20 %), 0 = none
  // --truth: a recording against a truth log; --baseline-method: a baseline instead.
  std::string truth, distance_column, baseline;
  std::optional<double> due_within_m;
  std::optional<std::string> quiet_phases;
  // --suite random: the randomised scene suite (suite.detector, quiet and json are copied over).
  SuiteEvalArgs suite;
};

std::vector<core::FlowMethod> flow_methods(const std::string& text) {
  if (text == "all")
    return {core::FlowMethod::kDisUltrafast, core::FlowMethod::kDisFast,
            core::FlowMethod::kDisMedium, core::FlowMethod::kFarneback};
  return {core::parse_flow_method(text)};
}

void eval_flow_main(const EvalArgs& args) {
  std::vector<io::FlowGtPair> pairs;
  if (!args.dir.empty()) {
    if (!args.left.empty() || !args.right.empty() || !args.gt.empty())
      throw core::InputError("eval --flow: give either --dir or --left/--right/--gt");
    pairs = io::find_flow_gt_pairs(args.dir);
  } else {
    if (args.left.empty() || args.right.empty() || args.gt.empty())
      throw core::InputError("eval --flow: give --left A --right B --gt FILE.flo, or --dir D");
    pairs.push_back({fs::path(args.left).stem().string(), args.left, args.right, args.gt});
  }
  const std::vector<core::FlowMethod> methods = flow_methods(args.flow_methods);
  nlohmann::json rows = nlohmann::json::array();
  std::map<std::string, std::pair<double, double>> sums;
  bool header = false;
  pipeline::evaluate_flow(pairs, methods, [&](const pipeline::FlowEvalRow& row) {
    if (!header) std::printf("%-16s %-14s %9s %8s\n", "pair", "method", "EPE px", "bad3 %");
    header = true;
    const eval::FlowAccuracy& a = row.accuracy;
    const char* method = core::to_string(row.method);
    std::printf("%-16s %-14s %9.3f %8.2f\n", row.pair.c_str(), method, a.epe, a.bad3_percent);
    sums[method].first += a.epe;
    sums[method].second += a.bad3_percent;
    rows.push_back({{"pair", row.pair},
                    {"method", method},
                    {"epe_px", a.epe},
                    {"bad3_percent", a.bad3_percent},
                    {"valid_pixels", a.valid_pixels}});
  });
  if (pairs.size() > 1)
    for (core::FlowMethod m : methods) {
      const auto& s = sums[core::to_string(m)];
      const double n = static_cast<double>(pairs.size());
      std::printf("%-16s %-14s %9.3f %8.2f\n", "mean", core::to_string(m), s.first / n,
                  s.second / n);
    }
  std::fflush(stdout);
  if (!args.json.empty()) write_json_output(args.json, nlohmann::json{{"flow", rows}});
}

void eval_main(const EvalArgs& args) {
  if (!args.suite.suite.empty()) {
    SuiteEvalArgs suite = args.suite;
    suite.detector = args.detector;
    suite.quiet = args.quiet;
    suite.json = args.json;
    eval_suite_main(suite);
    return;
  }
  if (args.suite.count || args.suite.seed || !args.suite.max_size.empty() ||
      args.suite.max_frames != 0 || args.suite.jobs != 0 || !args.suite.plot.empty())
    throw core::InputError("--count, --seed, --max-size, --max-frames, --jobs and --plot need "
                           "--suite random");
  if (args.flow) {
    eval_flow_main(args);
    return;
  }
  if (args.stereo) {
    StereoEvalArgs s;
    s.left = args.left;
    s.right = args.right;
    s.gt = args.gt;
    s.dir = args.dir;
    s.gt_scale = args.gt_scale;
    s.matchers = args.matchers;
    s.json = args.json;
    s.base = make_run_options(args.detector).params.bm;
    s.auto_range = !args.detector.num_disparities.has_value();
    eval_stereo_main(s);
    return;
  }
  InputOptions input = args.input;
  input.spec.left = args.left;  // --left/--right are shared with --flow
  input.spec.right = args.right;
  if (!args.truth.empty() || !args.baseline.empty()) {
    TruthEvalArgs t;
    t.input = input;
    t.detector = args.detector;
    t.outputs = args.outputs;
    t.quiet = args.quiet;
    t.json = args.json;
    t.drop_every = args.drop_every;
    t.truth = args.truth;
    t.distance_column = args.distance_column;
    t.due_within_m = args.due_within_m;
    t.quiet_phases = args.quiet_phases;
    t.baseline = args.baseline;
    eval_truth_main(t);
    return;
  }
  if (args.due_within_m || args.quiet_phases || !args.distance_column.empty())
    throw core::InputError("--due-within, --quiet-phases and --distance-column need --truth FILE");
  OpenedInput in = open_input(input, args.detector.config);
  io::RunSettings settings;
  pipeline::RunOptions options = make_run_options(args.detector, input_platform(in), &settings,
                                                  &in.source->camera());
  const ResolvedOutputs outputs = resolve_outputs(args.outputs, settings);
  if (outputs.scale != 1.0) {
    throw core::InputError("scale: eval does not rescale the ground truth; use scale only with run");
  }
  options.keep_maps = !outputs.dump.empty();
  pipeline::TruthLookup truth_of;
  if (in.scenario) {
    truth_of = [s = in.scenario](int) {
      return pipeline::FrameTruthView{s->last_truth(), s->last_maps().danger};
    };
  } else {
    io::FolderSource* folder = in.folder;
    if (folder == nullptr) {
      throw core::InputError(in.name +
                             " has no ground truth: eval scores a scenario, a stereo folder with "
                             "gt/, or a recording with --truth FILE (a truth log)");
    }
    if (!folder->has_truth()) {
      throw core::InputError(in.name + " has no ground truth (gt/frames.jsonl)");
    }
    truth_of = [folder](int i) {
      return pipeline::FrameTruthView{folder->truth(i), folder->truth_maps(i).danger};
    };
  }
  if (args.drop_every < 0 || args.drop_every == 1)
    throw core::InputError("drop-every=" + std::to_string(args.drop_every) +
                           ": must be 0 (none) or >= 2");
  pipeline::DroppingSource dropping(*in.source, args.drop_every);
  FrameOutputs frame_outputs(outputs, true, !args.quiet && io::stderr_is_terminal(),
                             in.source->size(),
                             options.params.bm.min_disparity + options.params.bm.num_disparities);
  const pipeline::Evaluation result = pipeline::evaluate(
      dropping, truth_of, options,
      [&](const core::StereoFrame&, const core::Detection& d) { frame_outputs.write(d); });
  frame_outputs.clear_progress();
  std::cout << "eval " << in.name << " (mode " << core::to_string(options.params.mode);
  if (dropping.dropped() > 0) std::cout << ", " << dropping.dropped() << " frames dropped";
  std::cout << ")\n"
            << result.report.table();
  if (!args.json.empty()) {
    nlohmann::json j = result.report.to_json();
    j["input"] = in.name;
    j["mode"] = core::to_string(options.params.mode);
    const bool flow_mode = options.params.mode == core::Mode::kStereoFlow;
    j["gaps"] = flow_mode ? options.params.scene_flow.gaps : options.params.stereo.gaps;
    if (flow_mode) j["flow_method"] = core::to_string(options.params.flow.method);
    write_json_output(args.json, j);
  }
  frame_outputs.finish(std::cout);
}

}  // namespace

void add_eval_command(CLI::App& app) {
  auto args = std::make_shared<EvalArgs>();
  CLI::App* cmd = app.add_subcommand(
      "eval",
      "score detections against ground truth (a scenario, a stereo folder with gt/, or a "
      "recording with --truth)");
  add_input_options(*cmd, args->input, false);
  add_detector_options(*cmd, args->detector);
  cmd->add_option("--json", args->json, "write the metrics as JSON");
  add_output_options(*cmd, args->outputs, /*with_scale=*/false);
  cmd->add_flag("--quiet", args->quiet, "no progress bar (shown only when stderr is a terminal)");
  cmd->add_option("--drop-every", args->drop_every,
                  "lose every n-th frame before the pipeline, as a loaded camera link does "
                  "(5 = 20 %; default 0 = none)");
  auto* truth_option = cmd->add_option(
      "--truth", args->truth,
      "score a recording (any input) against a truth log: CSV with frame and/or t_s, a distance "
      "(distance_m or board_distance_m) and/or phase; see docs/real-recordings.md");
  cmd->add_option("--distance-column", args->distance_column,
                  "with --truth: the log's distance column (default distance_m, else "
                  "board_distance_m)");
  cmd->add_option("--due-within", args->due_within_m,
                  "with --truth: due frames = not quiet and truth distance <= M metres (default: "
                  "truth TTC within the horizon)");
  cmd->add_option("--quiet-phases", args->quiet_phases,
                  "with --truth: phases whose frames are quiet, comma-separated (default "
                  "still,creep,retreat,quiet,static,stop)");
  auto* baseline_option = cmd->add_option(
      "--baseline-method", args->baseline,
      "run a baseline instead of the detector: central-median (StereoSGBM, median distance of "
      "the central quarter); without --truth only its alarms are counted");
  auto* flow_flag = cmd->add_flag("--flow", args->flow,
                "optical-flow accuracy instead: EPE and bad-3px % against a forward GT .flo");
  flow_flag->excludes(truth_option)->excludes(baseline_option);
  cmd->add_option("--left", args->left,
                  "left video, image folder or glob; with --flow: first image (frame 1)");
  cmd->add_option("--right", args->right,
                  "right video, image folder or glob; with --flow: second image (frame 2)");
  cmd->add_option("--gt", args->gt, "with --flow: GT flow from frame 1 to frame 2 (.flo)");
  cmd->add_option("--dir", args->dir,
                  "with --flow: a folder of pairs (NAME1/NAME2.png + NAME.flo, or "
                  "ID-img0/ID-img1 + ID-gt.flo), and its subfolders; with --stereo: a stereo GT "
                  "dataset (Middlebury, KITTI layouts; see docs/detectors.md)");
  cmd->add_flag("--stereo", args->stereo,
                "stereo accuracy instead: bad-1/2/4 %, MAE, density per matcher against GT "
                "disparity (--dir DATASET, or --left/--right/--gt)")
      ->excludes(flow_flag)
      ->excludes(truth_option)
      ->excludes(baseline_option);
  cmd->add_option("--gt-scale", args->gt_scale,
                  "with --stereo: 8-bit GT PNG scale, disparity = value / scale (default 0 = "
                  "from the folder's datasets.xml)");
  cmd->add_option("--matchers", args->matchers,
                  "with --stereo: bm, sgbm, fast, fast-sad, fast-census, fast-filled (fast with "
                  "its holes filled at half size), fast-periodic (fast without its matches on "
                  "repeating texture), longseq, comma-separated (default "
                  "bm,sgbm,fast,fast-periodic,fast-filled,fast-census)");
  cmd->add_option("--flow-methods", args->flow_methods,
                  "with --flow: dis-ultrafast, dis-fast, dis-medium, farneback or all (default)");
  auto* suite_option = cmd->add_option(
      "--suite", args->suite.suite,
      "score a suite of generated scenes instead: 'random' (seeds --seed .. --seed + --count - "
      "1; docs/random-suite.md)");
  suite_option->excludes(flow_flag)->excludes(truth_option)->excludes(baseline_option);
  cmd->add_option("--count", args->suite.count, "with --suite: number of scenes (>= 1)");
  cmd->add_option("--seed", args->suite.seed, "with --suite: the first scene's seed");
  cmd->add_option("--max-size", args->suite.max_size,
                  "with --suite: scale larger scenes down to fit WxH (e.g. 320x240 for CI)");
  cmd->add_option("--max-frames", args->suite.max_frames,
                  "with --suite: render at most N frames per scene (0 = all)");
  cmd->add_option("--jobs", args->suite.jobs,
                  "with --suite: scenes scored at once (default 0 = all cores)");
  cmd->add_option("--plot", args->suite.plot,
                  "with --suite: draw the lead and false-alarm histograms to this PNG");
  cmd->callback([args] { eval_main(*args); });
}

}  // namespace sg::apps
