// `stereoguard simulate`: renders a scenario into a stereo folder with its ground truth.
#include <filesystem>
#include <iostream>
#include <limits>

#include "commands.hpp"
#include "options.hpp"
#include "sg/core/error.hpp"
#include "sg/io/stereo_folder.hpp"
#include "sg/sim/random_scene.hpp"
#include "sg/sim/renderer.hpp"

namespace sg::apps {
namespace {

struct SimulateArgs {
  std::string scenario;
  std::string out;
  std::optional<int> frames;
  bool random = false;
  std::optional<long long> seed;
  std::string max_size;  ///< "WxH": scale a larger scene down to fit (as eval --suite does)
};

/// The scenario the flags name: --scenario, or --random with --seed.
sim::Scenario chosen_scenario(const SimulateArgs& args) {
  if (args.random) {
    if (!args.scenario.empty())
      throw core::InputError("give either --scenario or --random --seed S, not both");
    if (!args.seed) throw core::InputError("--random needs --seed S");
    if (*args.seed < 0 || *args.seed > std::numeric_limits<std::uint32_t>::max())
      throw core::InputError("seed=" + std::to_string(*args.seed) + ": must be in 0..4294967295");
    return sim::random_scenario(static_cast<std::uint32_t>(*args.seed));
  }
  if (args.seed) throw core::InputError("--seed needs --random");
  if (args.scenario.empty())
    throw core::InputError("give --scenario NAME|FILE or --random --seed S");
  return sim::resolve_scenario(args.scenario);
}

void simulate_main(const SimulateArgs& args) {
  sim::Scenario scenario = chosen_scenario(args);
  if (args.frames) {
    if (*args.frames < 2) {
      throw core::InputError("frames=" + std::to_string(*args.frames) + ": must be >= 2");
    }
    scenario.frames = *args.frames;
  }
  if (!args.max_size.empty()) {
    const cv::Size cap = parse_size(args.max_size, "max-size", "320x240");
    if (cap.width < 32 || cap.height < 32)
      throw core::InputError("max-size=" + args.max_size + ": each side must be >= 32");
    sim::cap_scenario(scenario, cap, 0);
  }
  const sim::Renderer renderer(scenario);
  io::FolderWriter writer(args.out, scenario.camera, /*with_truth=*/true);
  int alarms = 0;
  for (int i = 0; i < scenario.frames; ++i) {
    const sim::RenderedFrame r = renderer.render(i);
    writer.write(r.frame, &r.truth, &r.maps);
    alarms += r.truth.alarm ? 1 : 0;
  }
  // The scene itself beside its frames: `simulate --scenario` and `eval --scenario` replay it.
  sim::save_scenario_file(scenario, (std::filesystem::path(args.out) / "scenario.yaml").string());
  std::cout << "wrote " << writer.frames_written() << " frames of '" << scenario.name << "' to "
            << args.out << " (" << alarms << " ground-truth alarm frames) and its scenario.yaml\n";
  if (args.random) std::cout << scenario.description << "\n";
}

}  // namespace

void add_scenarios_command(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand("scenarios", "list the built-in scenarios");
  cmd->callback([] {
    for (const std::string& name : sim::builtin_scenario_names()) {
      const sim::Scenario s = sim::builtin_scenario(name);
      std::cout << name << std::string(name.size() < 15 ? 15 - name.size() : 1, ' ')
                << s.frames << " frames  " << s.description << "\n";
    }
  });
}

void add_simulate_command(CLI::App& app) {
  auto args = std::make_shared<SimulateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "simulate", "render a scenario into a stereo folder with ground truth (gt/)");
  cmd->add_option("--scenario", args->scenario, "built-in scenario name or scenario YAML file");
  cmd->add_flag("--random", args->random,
                "a generated scene instead (with --seed; docs/random-suite.md)");
  cmd->add_option("--seed", args->seed, "with --random: the scene's seed, 0..4294967295");
  cmd->add_option("--max-size", args->max_size,
                  "scale a larger scene down to fit WxH (the scene eval --suite random "
                  "--max-size scores)");
  cmd->add_option("--out", args->out, "output folder")->required();
  cmd->add_option("--frames", args->frames, "render only the first N frames");
  cmd->callback([args] { simulate_main(*args); });
}

}  // namespace sg::apps
