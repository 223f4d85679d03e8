// stereoguard: warns when something is about to hit a stereo camera. See README.md.
#include <malloc.h>

#include <CLI/CLI.hpp>
#include <iostream>

#include "commands.hpp"
#include "sg/core/error.hpp"

int main(int argc, char** argv) {
  // Every frame allocates full-size maps (0.3 to 3.7 MB each) and frees those of an older frame.
  // By default glibc serves such blocks with mmap, or trims them off the heap, and the kernel
  // then faults every page in again on the next frame: about 6 % of a Stereo-Flow run's CPU time
  // (perf). Kept on the heap, freed maps are reused as they are.
  mallopt(M_MMAP_THRESHOLD, 32 << 20);  // glibc's largest allowed value
  mallopt(M_TRIM_THRESHOLD, 512 << 20);
  // One heap for every thread: a farm worker's maps then reuse the blocks other threads freed,
  // and the heap run and eval touch before the first frame (RunOptions::prefault_heap). A few
  // dozen large blocks a frame: no contention worth the per-thread arenas.
  mallopt(M_ARENA_MAX, 1);
  CLI::App app{"stereoguard: obstacle warnings from a stereo camera"};
  app.require_subcommand(0, 1);
  sg::apps::add_run_command(app);
  sg::apps::add_simulate_command(app);
  sg::apps::add_eval_command(app);
  sg::apps::add_bench_command(app);
  sg::apps::add_scenarios_command(app);
  sg::apps::add_calibrate_command(app);
  try {
    if (argc == 1) {
      // No arguments: the main job on its built-in scenario.
      const char* run_args[] = {argv[0], "run"};
      app.parse(2, run_args);
    } else {
      app.parse(argc, argv);
    }
    if (app.get_subcommands().empty()) throw CLI::CallForHelp();
  } catch (const sg::apps::ExitStatus& e) {
    return e.status;
  } catch (const CLI::Success& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // One line like every other user error (CLI11's own exit() adds a second, generic line).
    std::cerr << "stereoguard: error: " << e.what() << " (see --help)\n";
    return 2;
  } catch (const sg::core::InputError& e) {
    std::cerr << "stereoguard: error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "stereoguard: internal error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
