#include "sg/io/events.hpp"

#include <cmath>

#include "sg/core/error.hpp"

namespace sg::io {
namespace {

/// Rounds to `decimals` places so that event files are stable and readable; non-finite -> null.
nlohmann::json rounded(double v, int decimals) {
  if (!std::isfinite(v)) return nullptr;
  const double scale = std::pow(10.0, decimals);
  const double r = std::round(v * scale) / scale;
  return r == 0.0 ? 0.0 : r;  // no "-0.0"
}

}  // namespace

nlohmann::json detection_to_json(const core::Detection& d, bool timing) {
  nlohmann::json j;
  j["frame"] = d.frame;
  j["time_s"] = rounded(d.time_s, 4);
  j["signal"] = d.signal;
  j["severity"] = core::to_string(d.severity);
  j["steering"] = core::to_string(d.steering);
  j["regions"] = nlohmann::json::array();
  for (const auto& r : d.regions) {
    j["regions"].push_back({{"name", r.name}, {"fired", r.fired}, {"dangerous_px", r.dangerous_px}});
  }
  j["obstacles"] = nlohmann::json::array();
  for (const auto& o : d.obstacles) {
    nlohmann::json e;
    e["bbox"] = {o.bbox.x, o.bbox.y, o.bbox.width, o.bbox.height};
    e["pixels"] = o.pixels;
    e["distance_m"] = rounded(o.distance_m, 4);
    e["ttc_s"] = o.ttc_s ? rounded(*o.ttc_s, 4) : nlohmann::json(nullptr);
    if (o.velocity) {
      const cv::Vec3d& v = *o.velocity;
      e["velocity_mps"] = {rounded(v[0], 4), rounded(v[1], 4), rounded(v[2], 4)};
    }
    if (o.track_id > 0) e["id"] = o.track_id;
    if (o.closing_speed_mps) e["closing_speed_mps"] = rounded(*o.closing_speed_mps, 4);
    if (o.predicted) e["predicted"] = true;
    j["obstacles"].push_back(std::move(e));
  }
  if (timing) j["latency_ms"] = rounded(d.latency_ms, 3);
  return j;
}

EventWriter::EventWriter(const std::filesystem::path& path, bool timing)
    : out_(path, std::ios::trunc), path_(path), timing_(timing) {
  if (!out_) throw core::InputError("cannot open events file for writing: " + path_.string());
}

void EventWriter::write(const core::Detection& d) {
  out_ << detection_to_json(d, timing_).dump() << '\n';
  out_.flush();
  if (!out_) throw core::InputError("cannot write events file: " + path_.string());
}

}  // namespace sg::io
