// `stereoguard simulate`: renders a scenario into a stereo folder with its ground truth.
#include <iostream>

#include "commands.hpp"
#include "sg/core/error.hpp"
#include "sg/io/stereo_folder.hpp"
#include "sg/sim/renderer.hpp"

namespace sg::apps {
namespace {

struct SimulateArgs {
  std::string scenario;
  std::string out;
  std::optional<int> frames;
};

void simulate_main(const SimulateArgs& args) {
  sim::Scenario scenario = sim::resolve_scenario(args.scenario);
  if (args.frames) {
    if (*args.frames < 2) {
      throw core::InputError("frames=" + std::to_string(*args.frames) + ": must be >= 2");
    }
    scenario.frames = *args.frames;
  }
  const sim::Renderer renderer(scenario);
  io::FolderWriter writer(args.out, scenario.camera, /*with_truth=*/true);
  int alarms = 0;
  for (int i = 0; i < scenario.frames; ++i) {
    const sim::RenderedFrame r = renderer.render(i);
    writer.write(r.frame, &r.truth, &r.maps);
    alarms += r.truth.alarm ? 1 : 0;
  }
  std::cout << "wrote " << writer.frames_written() << " frames of '" << scenario.name << "' to "
            << args.out << " (" << alarms << " ground-truth alarm frames)\n";
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
  cmd->add_option("--scenario", args->scenario, "built-in scenario name or scenario YAML file")
      ->required();
  cmd->add_option("--out", args->out, "output folder")->required();
  cmd->add_option("--frames", args->frames, "render only the first N frames");
  cmd->callback([args] { simulate_main(*args); });
}

}  // namespace sg::apps
