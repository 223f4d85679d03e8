#include "outputs.hpp"

#include <algorithm>
#include <fstream>
#include <iostream>

#include "sg/core/error.hpp"

namespace sg::apps {

void add_output_options(CLI::App& app, OutputOptions& o, bool with_scale) {
  app.add_option("--csv", o.csv,
                 "write per-frame metrics (frame, time, signal, severity, regions, obstacles, "
                 "nearest distance, min TTC, latency) to this CSV file");
  app.add_option("--dump", o.dump,
                 "write per-frame PNGs (colour-mapped disparity, flow, danger mask) into this "
                 "folder, created if missing");
  if (with_scale) {
    app.add_option("--scale", o.scale,
                   "resize the input images by this factor before processing (0 < S <= 4; "
                   "camera focal length and principal point follow)");
  }
}

ResolvedOutputs resolve_outputs(const OutputOptions& o, const io::RunSettings& settings) {
  ResolvedOutputs r;
  r.csv = o.csv.value_or(settings.csv);
  r.dump = o.dump.value_or(settings.dump);
  r.scale = o.scale.value_or(settings.scale);
  return r;
}

FrameOutputs::FrameOutputs(const ResolvedOutputs& outputs, bool timing, bool progress, int total,
                           double max_disparity_px)
    : outputs_(outputs) {
  if (!outputs.csv.empty()) csv_.emplace(outputs.csv, timing);
  if (!outputs.dump.empty()) dump_.emplace(outputs.dump, max_disparity_px);
  if (progress) progress_.emplace(std::cerr, total);
}

void FrameOutputs::write(const core::Detection& d) {
  if (csv_) csv_->write(d);
  if (dump_) dump_->write(d);
  if (progress_) progress_->tick();
  ++frames_;
}

void FrameOutputs::clear_progress() {
  if (progress_) progress_->clear();
}

void FrameOutputs::finish(std::ostream& out) {
  if (progress_) progress_->finish();
  if (csv_) out << "csv               " << outputs_.csv << " (" << frames_ << " rows)\n";
  if (dump_) out << "dump              " << outputs_.dump << "/ (" << frames_ << " frames)\n";
}

void write_json_output(const std::string& path, const nlohmann::json& j, int column) {
  std::ofstream out(path);
  if (!out) throw core::InputError("cannot write " + path);
  out << j.dump(2) << "\n";
  std::cout << std::string("json") + std::string(static_cast<size_t>(std::max(1, column - 4)), ' ')
            << path << "\n";
}

}  // namespace sg::apps
