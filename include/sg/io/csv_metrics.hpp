#pragma once
/// `--csv FILE`: one row of per-frame metrics per detection, under a header line, flushed as
/// written so that a failed run leaves only complete rows.
#include <filesystem>
#include <fstream>
#include <string>

#include "sg/core/detection.hpp"

namespace sg::io {

/// The header: frame, time_s, signal (0/1), severity (none/warning/danger), steering
/// (straight/left/right/stop), regions (fired region names separated by spaces), dangerous_px
/// (dangerous pixels over all regions, before hysteresis), obstacles (count), nearest_m (median
/// depth of the nearest obstacle, m), min_ttc_s (smallest obstacle TTC, s), latency_ms
/// (acquisition to detection, ms). Empty field = no value (no obstacle, no TTC, timing off).
inline constexpr const char* kCsvHeader =
    "frame,time_s,signal,severity,steering,regions,dangerous_px,obstacles,nearest_m,min_ttc_s,"
    "latency_ms";

/// One row (no newline) for `d`; latency_ms is left empty when `timing` is false.
std::string csv_row(const core::Detection& d, bool timing);

class CsvWriter {
 public:
  /// Opens (truncates) `path` and writes the header; throws core::InputError when it cannot.
  CsvWriter(const std::filesystem::path& path, bool timing);
  /// Writes one row and flushes it.
  void write(const core::Detection& d);

 private:
  std::ofstream out_;
  std::filesystem::path path_;
  bool timing_;
};

}  // namespace sg::io
