#pragma once
/// The stereoguard commands. Each registers its subcommand; the callback runs it.
#include <CLI/CLI.hpp>

namespace sg::apps {

/// Thrown by a command that did its work but ends with a non-zero exit status (a run stopped by
/// SIGINT or SIGTERM: 128 + the signal number); main returns `status`.
struct ExitStatus {
  int status;
};

void add_run_command(CLI::App& app);
void add_simulate_command(CLI::App& app);
void add_eval_command(CLI::App& app);
void add_bench_command(CLI::App& app);
void add_scenarios_command(CLI::App& app);
void add_calibrate_command(CLI::App& app);

}  // namespace sg::apps
