// `stereoguard eval`: detection accuracy against ground truth, or optical-flow accuracy (--flow).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "commands.hpp"
#include "eval_stereo.hpp"
#include "eval_suite.hpp"
#include "eval_truth.hpp"
#include "options.hpp"
#include "outputs.hpp"
#include "sg/core/error.hpp"
#include "sg/eval/flow_metrics.hpp"
#include "sg/io/file_kinds.hpp"
#include "sg/io/gt_formats.hpp"
#include "sg/io/stereo_folder.hpp"
#include "sg/pipeline/dropping_source.hpp"
#include "sg/pipeline/evaluation.hpp"
#include "sg/vision/flow.hpp"

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
  std::string matchers = "bm,sgbm,fast,fast-census";
  int drop_every = 0;  ///< drop every n-th frame (5 = 20 %), 0 = none
  // --truth: a recording against a truth log; --baseline-method: a baseline instead.
  std::string truth, distance_column, baseline;
  std::optional<double> due_within_m;
  std::optional<std::string> quiet_phases;
  // --suite random: the randomised scene suite (suite.detector, quiet and json are copied over).
  SuiteEvalArgs suite;
};

/// Two images and the forward GT flow from the first to the second.
struct FlowPair {
  std::string name;
  fs::path first, second, gt;
};

/// Pairs of one folder: Middlebury (NAME.flo with NAME1.EXT, NAME2.EXT) and FlyingChairs
/// (ID-gt.flo with ID-img0.EXT, ID-img1.EXT). A .flo without its two images is skipped.
void find_pairs_in(const fs::path& dir, std::vector<FlowPair>& out) {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_regular_file()) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  auto image = [&files](const std::string& stem) -> fs::path {
    for (const auto& f : files)
      if (f.stem().string() == stem && io::is_image_file(f)) return f;
    return {};
  };
  for (const auto& f : files) {
    if (f.extension() != ".flo") continue;
    const std::string stem = f.stem().string();
    const std::string suffix = "-gt";
    fs::path a, b;
    std::string name = stem;
    if (stem.size() > suffix.size() && stem.compare(stem.size() - 3, 3, suffix) == 0) {
      name = stem.substr(0, stem.size() - 3);
      a = image(name + "-img0");
      b = image(name + "-img1");
    } else {
      a = image(stem + "1");
      b = image(stem + "2");
    }
    if (!a.empty() && !b.empty()) out.push_back({name, a, b, f});
  }
}

/// The folder's pairs and those of its direct subfolders, in name order.
std::vector<FlowPair> find_pairs(const fs::path& dir) {
  if (!fs::is_directory(dir)) throw core::InputError("flow folder " + dir.string() + " does not exist");
  std::vector<FlowPair> out;
  find_pairs_in(dir, out);
  std::vector<fs::path> subdirs;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_directory()) subdirs.push_back(e.path());
  std::sort(subdirs.begin(), subdirs.end());
  for (const auto& d : subdirs) find_pairs_in(d, out);
  if (out.empty())
    throw core::InputError("flow folder " + dir.string() +
                           ": no pair found (NAME1/NAME2 + NAME.flo, or ID-img0/ID-img1 + "
                           "ID-gt.flo)");
  return out;
}

cv::Mat read_gray(const fs::path& path) {
  if (!fs::is_regular_file(path)) throw core::InputError("image " + path.string() + " does not exist");
  cv::Mat img = cv::imread(path.string(), cv::IMREAD_GRAYSCALE);
  if (img.empty()) throw core::InputError("image " + path.string() + " cannot be decoded");
  return img;
}

std::vector<core::FlowMethod> flow_methods(const std::string& text) {
  if (text == "all")
    return {core::FlowMethod::kDisUltrafast, core::FlowMethod::kDisFast,
            core::FlowMethod::kDisMedium, core::FlowMethod::kFarneback};
  return {core::parse_flow_method(text)};
}

void eval_flow_main(const EvalArgs& args) {
  std::vector<FlowPair> pairs;
  if (!args.dir.empty()) {
    if (!args.left.empty() || !args.right.empty() || !args.gt.empty())
      throw core::InputError("eval --flow: give either --dir or --left/--right/--gt");
    pairs = find_pairs(args.dir);
  } else {
    if (args.left.empty() || args.right.empty() || args.gt.empty())
      throw core::InputError("eval --flow: give --left A --right B --gt FILE.flo, or --dir D");
    pairs.push_back({fs::path(args.left).stem().string(), args.left, args.right, args.gt});
  }
  const std::vector<core::FlowMethod> methods = flow_methods(args.flow_methods);
  for (const FlowPair& pair : pairs)
    for (const fs::path& f : {pair.first, pair.second, pair.gt})
      if (!fs::is_regular_file(f)) throw core::InputError("file " + f.string() + " does not exist");
  nlohmann::json rows = nlohmann::json::array();
  std::map<std::string, std::pair<double, double>> sums;
  std::printf("%-16s %-14s %9s %8s\n", "pair", "method", "EPE px", "bad3 %");
  for (const FlowPair& pair : pairs) {
    const cv::Mat first = read_gray(pair.first), second = read_gray(pair.second);
    const cv::Mat gt = io::read_flo(pair.gt);
    if (first.size() != second.size() || first.size() != gt.size())
      throw core::InputError("pair " + pair.name + ": sizes differ (" + pair.first.string() + ", " +
                             pair.second.string() + ", " + pair.gt.string() + ")");
    for (core::FlowMethod m : methods) {
      core::FlowParams params;
      params.method = m;
      cv::Mat flow;
      // The GT is forward (first -> second); our flow is backward (current -> previous), so the
      // first image plays "current" and the second "previous".
      vision::compute_flow(first, second, params, flow);
      const eval::FlowAccuracy a = eval::flow_accuracy(flow, gt);
      std::printf("%-16s %-14s %9.3f %8.2f\n", pair.name.c_str(), core::to_string(m), a.epe,
                  a.bad3_percent);
      sums[core::to_string(m)].first += a.epe;
      sums[core::to_string(m)].second += a.bad3_percent;
      rows.push_back({{"pair", pair.name},
                      {"method", core::to_string(m)},
                      {"epe_px", a.epe},
                      {"bad3_percent", a.bad3_percent},
                      {"valid_pixels", a.valid_pixels}});
    }
  }
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
                  "with --stereo: bm, sgbm, fast, fast-sad, fast-census, longseq, comma-separated "
                  "(default bm,sgbm,fast,fast-census)");
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
