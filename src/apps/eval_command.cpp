// `stereoguard eval`: detection accuracy against ground truth.
#include <fstream>
#include <iostream>

#include "commands.hpp"
#include "options.hpp"
#include "sg/core/error.hpp"
#include "sg/io/stereo_folder.hpp"
#include "sg/pipeline/evaluation.hpp"

namespace sg::apps {
namespace {

struct EvalArgs {
  InputOptions input;
  DetectorOptions detector;
  std::string json;
};

void eval_main(const EvalArgs& args) {
  const pipeline::RunOptions options = make_run_options(args.detector);
  OpenedInput in = open_input(args.input);
  pipeline::TruthLookup truth_of;
  if (in.scenario) {
    truth_of = [s = in.scenario](int) {
      return pipeline::FrameTruthView{s->last_truth(), s->last_maps().danger};
    };
  } else {
    io::FolderSource* folder = in.folder;
    if (!folder->has_truth()) {
      throw core::InputError(in.name + " has no ground truth (gt/frames.jsonl)");
    }
    truth_of = [folder](int i) {
      return pipeline::FrameTruthView{folder->truth(i), folder->truth_maps(i).danger};
    };
  }
  const pipeline::Evaluation result = pipeline::evaluate(*in.source, truth_of, options);
  std::cout << "eval " << in.name << " (mode " << core::to_string(options.params.mode) << ")\n"
            << result.report.table();
  if (!args.json.empty()) {
    std::ofstream out(args.json);
    if (!out) throw core::InputError("cannot write " + args.json);
    nlohmann::json j = result.report.to_json();
    j["input"] = in.name;
    j["mode"] = core::to_string(options.params.mode);
    j["gaps"] = options.params.stereo.gaps;
    out << j.dump(2) << "\n";
    std::cout << "json              " << args.json << "\n";
  }
}

}  // namespace

void add_eval_command(CLI::App& app) {
  auto args = std::make_shared<EvalArgs>();
  CLI::App* cmd = app.add_subcommand(
      "eval", "score detections against ground truth (a scenario, or a stereo folder with gt/)");
  add_input_options(*cmd, args->input);
  add_detector_options(*cmd, args->detector);
  cmd->add_option("--json", args->json, "write the metrics as JSON");
  cmd->callback([args] { eval_main(*args); });
}

}  // namespace sg::apps
