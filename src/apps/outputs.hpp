#pragma once
/// Per-frame outputs of `run` and `eval` beside the events: --csv, --dump, the progress bar, and
/// --scale (run only: the ground truth of eval is not rescaled).
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <string>

#include "sg/core/detection.hpp"
#include "sg/io/config.hpp"
#include "sg/io/csv_metrics.hpp"
#include "sg/io/dump.hpp"
#include "sg/io/progress.hpp"

namespace sg::apps {

/// The flags as given; unset ones fall back to the config file (io::RunSettings).
struct OutputOptions {
  std::optional<std::string> csv, dump;
  std::optional<double> scale;
};

/// Adds --csv, --dump and, when `with_scale`, --scale.
void add_output_options(CLI::App& app, OutputOptions& options, bool with_scale);

/// Writes `j` (indented) to `path` (an eval --json file) and names it on stdout in a line
/// "json" padded to `column`, the value column of the command's table. Throws InputError when
/// the file cannot be written.
void write_json_output(const std::string& path, const nlohmann::json& j, int column = 18);

/// Flags over the config file's settings.
struct ResolvedOutputs {
  std::string csv;     ///< CSV file, empty = none
  std::string dump;    ///< PNG folder, empty = none
  double scale = 1.0;  ///< input resize factor
};
ResolvedOutputs resolve_outputs(const OutputOptions& options, const io::RunSettings& settings);

/// The opened per-frame sinks of one run. Opening checks the paths (core::InputError naming
/// --csv or --dump), so a bad path fails before the first frame.
class FrameOutputs {
 public:
  /// total = frames of the source or -1; progress = draw the bar on stderr.
  FrameOutputs(const ResolvedOutputs& outputs, bool timing, bool progress, int total,
               double max_disparity_px);
  /// Erases the progress line, so that an error message starts on a clean line.
  ~FrameOutputs() { clear_progress(); }
  FrameOutputs(const FrameOutputs&) = delete;
  FrameOutputs& operator=(const FrameOutputs&) = delete;
  /// CSV row, dump PNGs, progress tick.
  void write(const core::Detection& d);
  /// Erases the progress line before other text goes to the terminal.
  void clear_progress();
  /// Erases the progress bar and prints one line per file output.
  void finish(std::ostream& out);

 private:
  ResolvedOutputs outputs_;
  std::optional<io::CsvWriter> csv_;
  std::optional<io::DumpWriter> dump_;
  std::optional<io::ProgressBar> progress_;
  int frames_ = 0;
};

}  // namespace sg::apps
