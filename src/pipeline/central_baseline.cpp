#include "sg/pipeline/central_baseline.hpp"

#include <algorithm>
#include <chrono>
#include <vector>

#include "sg/core/error.hpp"
#include "sg/eval/truth_log.hpp"
#include "sg/vision/central_median.hpp"

namespace sg::pipeline {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto rank = static_cast<std::size_t>(p * static_cast<double>(v.size() - 1) + 0.5);
  return v[std::min(rank, v.size() - 1)];
}

}  // namespace

CentralBaseline::CentralBaseline(CentralBaselineOptions options, const core::Camera& camera)
    : options_(std::move(options)), camera_(camera) {}

core::Detection CentralBaseline::process(const core::StereoFrame& frame) {
  const Clock::time_point start = Clock::now();
  cv::Mat disp;
  vision::match_sgbm_baseline(frame.left, frame.right, options_.params.bm, disp);
  const vision::CentralMedian centre = vision::central_median(disp, camera_);

  while (!history_.empty() && history_.front().first < frame.time_s - options_.window_s)
    history_.pop_front();
  if (centre.distance_m) history_.emplace_back(frame.time_s, *centre.distance_m);
  std::optional<double> closing;
  if (centre.distance_m && static_cast<int>(history_.size()) >= options_.min_frames) {
    std::vector<double> ts, ds;
    for (const auto& [t, d] : history_) ts.push_back(t), ds.push_back(d);
    if (const std::optional<double> slope = eval::fit_slope(ts, ds)) closing = -*slope;
  }

  const core::Envelope& envelope = options_.params.envelope;
  core::Detection out;
  out.frame = frame.index;
  out.time_s = frame.time_s;
  if (centre.distance_m) {
    const double distance = *centre.distance_m;
    core::Obstacle o;
    o.bbox = centre.box;
    o.pixels = centre.valid_px;
    o.distance_m = distance;
    if (closing) o.closing_speed_mps = *closing;
    const bool reached = distance <= envelope.z_contact_m;
    if (closing && *closing > options_.min_closing_mps)
      o.ttc_s = std::max(0.0, (distance - envelope.z_contact_m) / *closing);
    out.signal = reached || (o.ttc_s && *o.ttc_s <= envelope.horizon_s);
    if (out.signal) {
      const bool danger = reached || *o.ttc_s <= options_.params.signal.ttc_danger_s;
      out.severity = danger ? core::Severity::kDanger : core::Severity::kWarning;
    }
    out.obstacles.push_back(o);
  }
  out.regions.push_back({"centre", out.signal, 0});
  if (options_.keep_maps) out.disparity = disp;
  out.latency_ms = ms_since(start);
  return out;
}

RunSummary run_central_baseline(core::FrameSource& source, const CentralBaselineOptions& options,
                                const DetectionSink& sink) {
  const core::Camera& camera = source.camera();
  core::throw_if_invalid(core::validate(options.params, camera), "invalid parameters");
  CentralBaseline baseline(options, camera);
  RunSummary summary;
  summary.mode = "central-median";
  summary.tokens = 1;
  std::vector<double> latencies;
  const Clock::time_point start = Clock::now();
  std::optional<int> last_index;
  while (std::optional<core::StereoFrame> frame = source.next()) {
    if (last_index && frame->index > *last_index + 1)
      summary.dropped += frame->index - *last_index - 1;
    last_index = frame->index;
    const core::Detection d = baseline.process(*frame);
    ++summary.frames;
    latencies.push_back(d.latency_ms);
    if (d.signal) {
      ++summary.alarm_frames;
      if (!summary.first_alarm_frame) {
        summary.first_alarm_frame = d.frame;
        summary.first_alarm_time_s = d.time_s;
      }
    }
    if (sink) sink(*frame, d);
  }
  summary.wall_s = ms_since(start) / 1000.0;
  if (summary.wall_s > 0) summary.throughput_fps = summary.frames / summary.wall_s;
  if (summary.frames > 0) summary.service_ms = 1000.0 * summary.wall_s / summary.frames;
  summary.latency_p50_ms = percentile(latencies, 0.50);
  summary.latency_p95_ms = percentile(latencies, 0.95);
  summary.latency_p99_ms = percentile(latencies, 0.99);
  summary.latency_max_ms = percentile(latencies, 1.0);
  for (double l : latencies) summary.latency_mean_ms += l / static_cast<double>(latencies.size());
  return summary;
}

}  // namespace sg::pipeline
