// `stereoguard bench`: throughput and latency of the pipeline configurations beside a plain
// sequential OpenCV loop measured in the same run.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <iostream>

#include "commands.hpp"
#include "options.hpp"
#include "sg/core/error.hpp"
#include "sg/pipeline/bench.hpp"
#include "sg/pipeline/runner.hpp"

namespace sg::apps {
namespace {

struct BenchArgs {
  std::vector<std::string> modes = {"stereo", "stereo-flow"};
  std::vector<int> workers = {1, 2, 3};
  std::vector<int> tiles = {1, 2, 4};
  std::vector<std::string> resolutions = {"640x480", "1242x375"};
  std::vector<double> pace = {0.8, 1.5};
  int capacity_runs = 3;
  int frames = 300;
  int num_disparities = 64;
  std::string matcher = "fast", cost = "sad";  // run's defaults
  int threads = 0;
  int tokens = 0;
  std::string scenario = "head-on";
  std::string csv = "stereoguard-bench.csv";
  std::string plot;
  InputOptions input;  ///< a real input instead of the scenario (--left/--right, --euroc, ...)
};

/// A spread of the capacity runs above this is the machine, not the pipeline (run to run, the
/// same configuration moves by a few per cent on a quiet machine).
constexpr double kNoisySpread = 0.10;

void print_row(const pipeline::BenchRow& r) {
  std::cout << std::left << std::setw(10) << r.kind << std::setw(16) << r.mode << std::right
            << std::setw(5) << r.resolution.width << "x" << std::left << std::setw(5)
            << r.resolution.height << std::right << std::setw(3) << r.workers << std::setw(4)
            << r.tiles << std::setw(4) << r.tokens << std::fixed << std::setprecision(1)
            << std::setw(8) << r.pace_fps << std::setw(8) << r.fps << std::setprecision(2)
            << std::setw(8) << r.speedup << std::setw(8) << r.speedup_1t << std::setprecision(1)
            << std::setw(8) << r.latency_p50_ms << std::setw(8) << r.latency_p99_ms << std::setw(7)
            << r.dropped << "  " << pipeline::same_detections_text(r) << std::endl;
}

/// What the paced rows below refer to, and whether to trust it (BenchRow::capacity_spread).
void print_capacity(const pipeline::BenchRow& r) {
  std::cout << std::fixed << std::setprecision(1) << "(paced rows: fractions of " << r.capacity_fps
            << " fps, the median of " << r.capacity_runs << " runs of W " << r.workers << " T "
            << r.tiles << ", spread " << 100.0 * r.capacity_spread << " %";
  if (r.capacity_spread > kNoisySpread)
    std::cout << "; over " << 100.0 * kNoisySpread
              << " %: the machine's speed changed between runs, so the pace may not be the "
                 "fraction asked for; run again";
  std::cout << ")" << std::endl;
}

/// Whether the machine kept the capacity's speed while the paced rows ran (a "recheck" row).
void print_recheck(const pipeline::BenchRow& r) {
  const double off = r.fps / r.capacity_fps - 1.0;
  std::cout << std::fixed << std::setprecision(1) << "(after the paced rows: W " << r.workers
            << " T " << r.tiles << " ran " << r.fps << " fps, " << 100.0 * off
            << " % against the capacity";
  if (std::abs(off) > kNoisySpread)
    std::cout << "; over " << 100.0 * kNoisySpread
              << " %: the machine's speed changed while the paced rows ran, so their pace may not "
                 "be the fraction asked for; run again";
  std::cout << ")" << std::endl;
}

/// Per detector and resolution: the W and T that `run` picks by default (--workers auto,
/// --tiles auto, for `threads`) beside the fastest configuration swept.
void print_auto(const std::vector<pipeline::BenchRow>& swept, int threads) {
  const pipeline::AutoConfiguration automatic = pipeline::auto_configuration(threads);
  std::vector<bool> told(swept.size(), false);
  for (size_t i = 0; i < swept.size(); ++i) {
    if (told[i]) continue;
    const pipeline::BenchRow* best = nullptr;
    const pipeline::BenchRow* picked = nullptr;
    for (size_t j = i; j < swept.size(); ++j) {
      const pipeline::BenchRow& r = swept[j];
      if (r.mode != swept[i].mode || r.resolution != swept[i].resolution) continue;
      told[j] = true;
      if (!best || r.fps > best->fps) best = &r;
      if (r.workers == automatic.workers && r.tiles == automatic.tiles) picked = &r;
    }
    std::cout << std::fixed << std::setprecision(1) << "(auto, run's default: " << best->mode
              << " " << best->resolution.width << "x" << best->resolution.height << ", W "
              << automatic.workers << " T " << automatic.tiles;
    if (picked)
      std::cout << ", " << picked->fps << " fps, " << 100.0 * picked->fps / best->fps
                << " % of the fastest swept";
    else
      std::cout << " (not swept)";
    std::cout << "; fastest: W " << best->workers << " T " << best->tiles << ", " << best->fps
              << " fps)\n";
  }
}

void write_plot(const std::string& csv, const std::string& png,
                const std::vector<std::string>& modes) {
  const std::string script = png + ".gnuplot";
  {
    std::ofstream g(script);
    g << "set datafile separator ','\n"
      << "set terminal pngcairo size 1100,700 noenhanced\n"
      << "set output '" << png << "'\n"
      << "set multiplot layout 1," << modes.size()
      << " title 'stereoguard bench: throughput against p99 latency, "
         "one point per configuration ("
      << csv << ")'\n"
      << "set xlabel 'p99 latency (ms)'\nset ylabel 'throughput (fps)'\nset grid\n"
      << "set key off\nset offsets graph 0.05, graph 0.25, graph 0.1, graph 0.1\n"
      << "label(k) = (k eq 'pipeline' || k eq 'paced') ? sprintf('%s W%s T%s', k, "
         "stringcolumn(5), stringcolumn(6)) : k\n";
    for (const std::string& mode : modes) {
      g << "set title '" << mode << "'\n"
        << "plot '" << csv << "' every ::1 using (stringcolumn(2) eq '" << mode
        << "' ? $15 : NaN):12 with points pt 7 ps 1.2, '' every ::1 using (stringcolumn(2) eq '"
        << mode
        << "' ? $15 : NaN):12:(label(stringcolumn(1)).' '.stringcolumn(3).'x'"
           ".stringcolumn(4)) with labels offset 0.5,0.6 left font ',7'\n";
    }
    g << "unset multiplot\n";
  }
  const std::string cmd = "gnuplot '" + script + "'";
  if (std::system("command -v gnuplot >/dev/null 2>&1") != 0) {
    throw core::InputError("--plot needs gnuplot (apt-get install gnuplot-nox); the CSV is " + csv);
  }
  if (std::system(cmd.c_str()) != 0) throw core::InputError("gnuplot failed on " + script);
  std::remove(script.c_str());
}

void bench_main(const BenchArgs& a) {
  pipeline::BenchConfig config;
  config.modes.clear();
  for (const auto& m : a.modes) config.modes.push_back(core::parse_mode(m));
  config.workers = a.workers;
  config.tiles = a.tiles;
  config.resolutions.clear();
  for (const auto& r : a.resolutions)
    config.resolutions.push_back(parse_size(r, "resolution", "640x480"));
  config.frames = a.frames;
  config.num_disparities = a.num_disparities;
  config.matcher = core::parse_matcher(a.matcher);
  config.cost = core::parse_match_cost(a.cost);
  config.threads = a.threads;
  config.tokens = a.tokens;
  config.scenario = a.scenario;
  config.pace_fractions = a.pace;
  config.capacity_runs = a.capacity_runs;
  if (a.input.spec.any() || a.input.sbs) {
    config.open_input = [input = a.input] { return open_input(input).source; };
  }
  core::throw_if_invalid(pipeline::validate(config), "invalid bench settings");

  std::ofstream csv(a.csv);
  if (!csv) throw core::InputError("cannot write " + a.csv);
  csv << pipeline::bench_csv_header() << "\n";
  const std::string what = config.open_input ? "input " + a.input.spec.name() + " (read once)"
                                             : "scenario " + a.scenario + " (rendered once)";
  std::cout << "stereoguard bench: " << what << ", " << a.frames
            << " frames per configuration held in memory; pipeline rows: matcher " << a.matcher
            << " (baselines: bm)\n"
            << "kind      detector          resolution  W   T tok  pace/s     fps  vs-mt   vs-1t"
               "     p50     p99   drop  same\n"
            << "(vs-mt: speedup against the plain loop with OpenCV's threads, the default a user "
               "gets; vs-1t: against the same loop on one thread)\n";
  std::string capacity_told;  // the mode whose capacity line was printed
  std::vector<pipeline::BenchRow> swept;  // the unpaced pipeline rows, for the auto line
  pipeline::run_bench(config, [&](const pipeline::BenchRow& row) {
    if (row.kind == "pipeline") swept.push_back(row);
    if (row.kind == "paced" && row.mode != capacity_told) {
      print_capacity(row);
      capacity_told = row.mode;
    }
    print_row(row);
    if (row.kind == "recheck") print_recheck(row);
    csv << pipeline::to_csv(row) << "\n" << std::flush;
  });
  print_auto(swept, a.threads);
  std::cout << "csv: " << a.csv << "\n";
  if (!a.plot.empty()) {
    csv.close();
    write_plot(a.csv, a.plot, a.modes);
    std::cout << "plot: " << a.plot << "\n";
  }
}

}  // namespace

void add_bench_command(CLI::App& app) {
  auto a = std::make_shared<BenchArgs>();
  CLI::App* cmd = app.add_subcommand(
      "bench", "throughput/latency sweep of modes x W x T against a plain OpenCV loop");
  cmd->add_option("--detectors,--modes", a->modes,
                  "detectors (as run's --detector), comma-separated (default stereo,stereo-flow)")
      ->delimiter(',');
  cmd->add_option("--workers", a->workers, "W values, comma-separated")->delimiter(',');
  cmd->add_option("--tiles", a->tiles, "T values, comma-separated")->delimiter(',');
  cmd->add_option("--resolutions", a->resolutions, "e.g. 640x480,1242x375")->delimiter(',');
  cmd->add_option("--frames", a->frames, "frames per configuration (default 300)");
  cmd->add_option("--num-disparities", a->num_disparities, "stereo search range (default 64)");
  cmd->add_option("--matcher", a->matcher,
                  "stereo matcher of the pipeline rows: fast (default), bm, sgbm or longseq (the "
                  "baselines stay StereoBM)");
  cmd->add_option("--cost", a->cost, "fast matcher cost: sad (default) or census");
  cmd->add_option("--threads", a->threads, "task-arena size (default 0 = all cores)");
  cmd->add_option("--tokens", a->tokens,
                  "frames in flight of the pipeline rows (default 0: W + 1)");
  cmd->add_option("--scenario", a->scenario, "scenario rendered for the frames (default head-on)");
  cmd->add_option("--pace", a->pace,
                  "also pace the best configuration (lowest p99 within 5 % of the top fps) at "
                  "these fractions of its capacity (first resolution; default 0.8,1.5)")
      ->delimiter(',');
  cmd->add_option("--capacity-runs", a->capacity_runs,
                  "the capacity the pace refers to: the median fps of this many runs of the best "
                  "configuration (its row and N - 1 'capacity' rows; 1..9, default 3)");
  add_source_options(*cmd, a->input);
  cmd->add_option("--csv", a->csv, "CSV output (default stereoguard-bench.csv)");
  cmd->add_option("--plot", a->plot, "draw throughput and latency to this PNG (needs gnuplot)");
  cmd->callback([a] { bench_main(*a); });
}

}  // namespace sg::apps
