#include "sg/pipeline/runner.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <thread>

#include "sg/core/error.hpp"
#include "sg/vision/detector.hpp"

namespace sg::pipeline {
namespace {

using Clock = std::chrono::steady_clock;

double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

/// Nearest-rank percentile of sorted samples.
double percentile(const std::vector<double>& sorted, double q) {
  if (sorted.empty()) return 0.0;
  const auto rank = static_cast<size_t>(std::ceil(q * static_cast<double>(sorted.size())));
  return sorted[std::clamp<size_t>(rank, 1, sorted.size()) - 1];
}

}  // namespace

std::vector<std::string> validate(const RunOptions& options, const core::Camera& camera) {
  std::vector<std::string> out = core::validate(options.params, camera);
  if (!std::isfinite(options.pace_fps) || options.pace_fps < 0) {
    std::ostringstream s;
    s << "fps=" << options.pace_fps << ": must be >= 0 (0 = as fast as possible)";
    out.push_back(s.str());
  }
  return out;
}

RunSummary run(core::FrameSource& source, const RunOptions& options, const DetectionSink& sink) {
  core::throw_if_invalid(validate(options, source.camera()), "invalid parameters");
  vision::Detector detector(options.params, source.camera());

  RunSummary summary;
  std::vector<double> latencies;
  const Clock::time_point start = Clock::now();
  Clock::time_point last_done = start;
  double service_sum_ms = 0.0;
  while (true) {
    if (options.pace_fps > 0) {
      const auto due = start + std::chrono::duration_cast<Clock::duration>(
                                   std::chrono::duration<double>(summary.frames / options.pace_fps));
      std::this_thread::sleep_until(due);
    }
    std::optional<core::StereoFrame> frame = source.next();
    if (!frame) break;
    const Clock::time_point acquired = Clock::now();
    vision::FrameMaps maps;
    vision::compute_disparity(*frame, options.params, maps.disparity);
    core::Detection detection = detector.process(*frame, maps);
    const Clock::time_point done = Clock::now();
    detection.latency_ms = ms_between(acquired, done);
    latencies.push_back(detection.latency_ms);
    if (summary.frames > 0) service_sum_ms += ms_between(last_done, done);
    last_done = done;

    ++summary.frames;
    if (detection.signal) {
      ++summary.alarm_frames;
      if (!summary.first_alarm_frame) {
        summary.first_alarm_frame = detection.frame;
        summary.first_alarm_time_s = detection.time_s;
      }
    }
    sink(*frame, detection);
  }
  summary.wall_s = std::chrono::duration<double>(last_done - start).count();
  summary.throughput_fps = summary.wall_s > 0 ? summary.frames / summary.wall_s : 0.0;
  summary.service_ms = summary.frames > 1 ? service_sum_ms / (summary.frames - 1) : 0.0;
  std::sort(latencies.begin(), latencies.end());
  summary.latency_p50_ms = percentile(latencies, 0.50);
  summary.latency_p95_ms = percentile(latencies, 0.95);
  summary.latency_p99_ms = percentile(latencies, 0.99);
  summary.latency_max_ms = latencies.empty() ? 0.0 : latencies.back();
  return summary;
}

nlohmann::json RunSummary::to_json() const {
  auto opt = [](const auto& v) { return v ? nlohmann::json(*v) : nlohmann::json(); };
  return {{"frames", frames},
          {"alarm_frames", alarm_frames},
          {"first_alarm_frame", opt(first_alarm_frame)},
          {"first_alarm_time_s", opt(first_alarm_time_s)},
          {"wall_s", wall_s},
          {"throughput_fps", throughput_fps},
          {"service_ms", service_ms},
          {"latency_ms",
           {{"p50", latency_p50_ms},
            {"p95", latency_p95_ms},
            {"p99", latency_p99_ms},
            {"max", latency_max_ms}}}};
}

std::string RunSummary::text() const {
  std::ostringstream s;
  s << std::fixed << std::setprecision(1);
  s << "frames processed  " << frames << "\n";
  s << "alarm frames      " << alarm_frames << "\n";
  s << "first alarm       ";
  if (first_alarm_frame) {
    s << "frame " << *first_alarm_frame << " (t = " << std::setprecision(2)
      << *first_alarm_time_s << " s)\n" << std::setprecision(1);
  } else {
    s << "none\n";
  }
  s << "throughput        " << throughput_fps << " fps (" << wall_s << " s wall)\n";
  s << "latency ms        p50 " << latency_p50_ms << "  p95 " << latency_p95_ms << "  p99 "
    << latency_p99_ms << "  max " << latency_max_ms << "\n";
  return s.str();
}

}  // namespace sg::pipeline
