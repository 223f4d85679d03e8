#pragma once
/// The stereoguard commands. Each registers its subcommand; the callback runs it.
#include <CLI/CLI.hpp>

namespace sg::apps {

void add_run_command(CLI::App& app);
void add_simulate_command(CLI::App& app);
void add_eval_command(CLI::App& app);
void add_bench_command(CLI::App& app);
void add_scenarios_command(CLI::App& app);
void add_calibrate_command(CLI::App& app);

}  // namespace sg::apps
