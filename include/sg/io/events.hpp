#pragma once
/// Event output: one complete JSON object per line and frame, flushed as written.
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "sg/core/detection.hpp"

namespace sg::io {

/// {"frame", "time_s", "signal", "severity", "steering", "regions": [{name, fired, dangerous_px}],
///  "obstacles": [{bbox: [x, y, w, h], pixels, distance_m, ttc_s, velocity_mps?}], "latency_ms"?}
/// latency_ms is left out when timing is false, so that repeated runs are byte-identical.
nlohmann::json detection_to_json(const core::Detection& d, bool timing);

class EventWriter {
 public:
  /// Opens (truncates) `path`; throws core::InputError when it cannot.
  EventWriter(const std::filesystem::path& path, bool timing);
  /// Writes one line and flushes it, so that a crash later leaves only complete lines.
  void write(const core::Detection& d);

 private:
  std::ofstream out_;
  std::filesystem::path path_;
  bool timing_;
};

}  // namespace sg::io
