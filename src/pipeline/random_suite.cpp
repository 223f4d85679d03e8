#include "sg/pipeline/random_suite.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "sg/core/error.hpp"
#include "sg/par/jobs.hpp"
#include "sg/pipeline/evaluation.hpp"
#include "sg/sim/random_scene.hpp"
#include "sg/sim/renderer.hpp"

namespace sg::pipeline {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// Nearest-rank percentile of sorted values, p in (0, 1].
double percentile(const std::vector<double>& sorted, double p) {
  const auto rank = static_cast<std::size_t>(std::ceil(p * static_cast<double>(sorted.size())));
  return sorted[std::clamp<std::size_t>(rank, 1, sorted.size()) - 1];
}

nlohmann::json distribution_json(const Distribution& d) {
  return {{"count", d.count}, {"mean", d.mean}, {"p10", d.p10}, {"p50", d.p50}, {"p90", d.p90}};
}

nlohmann::json optional_json(const std::optional<double>& v) {
  return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
}

RandomSuiteSummary summarise(const std::vector<RandomSceneResult>& scenes) {
  RandomSuiteSummary s;
  s.scenes = static_cast<int>(scenes.size());
  std::vector<double> recall, lead, lead_entering, delay, false_alarms;
  for (const RandomSceneResult& r : scenes) {
    if (r.colliding()) {
      ++s.colliding;
      recall.push_back(r.report.recall_settled);
      if (r.lead_s)
        lead.push_back(*r.lead_s);
      else
        ++s.missed;
      if (r.first_alarm_delay_s) delay.push_back(*r.first_alarm_delay_s);
      if (r.lead_entering_s)
        lead_entering.push_back(*r.lead_entering_s);
      else if (r.entering > 0)
        ++s.missed_entering;
    } else {
      ++s.clear;
      false_alarms.push_back(r.report.false_alarm_rate);
    }
  }
  s.recall_settled = distribution(recall);
  s.lead_s = distribution(lead);
  s.lead_entering_s = distribution(lead_entering);
  s.first_alarm_delay_s = distribution(delay);
  s.false_alarm_rate = distribution(false_alarms);
  std::vector<std::size_t> order(scenes.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return scenes[a].badness() > scenes[b].badness();
  });
  for (std::size_t i = 0; i < order.size() && i < 10; ++i)
    if (scenes[order[i]].badness() > 0) s.worst_seeds.push_back(scenes[order[i]].seed);
  return s;
}

/// One histogram in `panel`: bins of width `bin` from 0, the last one open-ended; `extra` (may
/// be empty) is one more bar labelled extra_label, drawn in red.
void draw_histogram(cv::Mat panel, const std::vector<double>& values, double bin, int bins,
                    const std::string& title, const std::string& unit, int extra,
                    const std::string& extra_label) {
  panel.setTo(cv::Scalar(255, 255, 255));
  std::vector<int> counts(static_cast<std::size_t>(bins), 0);
  for (double v : values)
    ++counts[static_cast<std::size_t>(std::clamp(static_cast<int>(v / bin), 0, bins - 1))];
  const int bars = bins + (extra_label.empty() ? 0 : 1);
  const int highest = std::max(1, std::max(extra, *std::max_element(counts.begin(), counts.end())));
  const int left = 40, right = panel.cols - 30, top = 60, bottom = panel.rows - 50;
  const double width = static_cast<double>(right - left) / bars;
  const auto font = cv::FONT_HERSHEY_SIMPLEX;
  cv::putText(panel, title, {left, 25}, font, 0.55, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  for (int i = 0; i < bars; ++i) {
    const bool is_extra = i == bins;
    const int count = is_extra ? extra : counts[static_cast<std::size_t>(i)];
    const int x0 = left + static_cast<int>(i * width) + 1;
    const int x1 = left + static_cast<int>((i + 1) * width) - 1;
    const int y0 = bottom - static_cast<int>((bottom - top) * count / static_cast<double>(highest));
    if (count > 0)
      cv::rectangle(panel, {x0, y0}, {x1, bottom},
                    is_extra ? cv::Scalar(60, 60, 220) : cv::Scalar(200, 120, 40), cv::FILLED);
    if (count > 0)
      cv::putText(panel, std::to_string(count), {x0, y0 - 4}, font, 0.4, cv::Scalar(0, 0, 0), 1,
                  cv::LINE_AA);
    char label[32];
    if (is_extra)
      std::snprintf(label, sizeof(label), "%s", extra_label.c_str());
    else
      std::snprintf(label, sizeof(label), "%.3g", i * bin);
    if (is_extra || i % 2 == 0)
      cv::putText(panel, label, {x0, bottom + 16}, font, 0.38, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
  cv::line(panel, {left, bottom}, {right, bottom}, cv::Scalar(0, 0, 0));
  cv::putText(panel, unit, {left, bottom + 38}, font, 0.45, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
}

}  // namespace

cv::Mat plot_random_suite(const RandomSuiteResult& result) {
  std::vector<double> leads, false_alarms;
  int missed = 0;
  for (const RandomSceneResult& r : result.scenes) {
    if (!r.colliding())
      false_alarms.push_back(r.report.false_alarm_rate);
    else if (r.lead_s)
      leads.push_back(*r.lead_s);
    else
      ++missed;
  }
  cv::Mat image(360, 900, CV_8UC3);
  draw_histogram(image(cv::Rect(0, 0, 450, 360)), leads, 0.25, 14,
                 "lead, colliding scenes (" + std::to_string(leads.size() + missed) + ")",
                 "lead s (last bin: 3.25 s and more)", missed, "missed");
  draw_histogram(image(cv::Rect(450, 0, 450, 360)), false_alarms, 0.05, 12,
                 "false alarm rate, clear scenes (" + std::to_string(false_alarms.size()) + ")",
                 "false alarm frames / clear frames", 0, "");
  return image;
}

std::vector<std::string> validate(const RandomSuiteOptions& o) {
  std::vector<std::string> out;
  if (o.count < 1) out.push_back("count=" + std::to_string(o.count) + ": must be >= 1");
  if (o.count > 1 && o.first_seed > UINT32_MAX - static_cast<std::uint32_t>(o.count - 1))
    out.push_back("seed=" + std::to_string(o.first_seed) +
                  ": seed + count - 1 must be <= " + std::to_string(UINT32_MAX));
  if (o.max_size.width < 0 || o.max_size.height < 0 ||
      (o.max_size.width > 0 && o.max_size.width < 32) ||
      (o.max_size.height > 0 && o.max_size.height < 32))
    out.push_back("max-size=" + std::to_string(o.max_size.width) + "x" +
                  std::to_string(o.max_size.height) + ": each side must be >= 32");
  if (o.max_frames != 0 && o.max_frames < 2)
    out.push_back("max-frames=" + std::to_string(o.max_frames) + ": must be 0 (no cap) or >= 2");
  if (o.jobs < 0 || o.jobs > 256)
    out.push_back("jobs=" + std::to_string(o.jobs) + ": must be in 0..256 (0 = all cores)");
  return out;
}

double RandomSceneResult::badness() const {
  if (!colliding()) return report.false_alarm_rate;
  return (1.0 - report.recall_settled) + (lead_s ? 0.0 : 1.0);
}

Distribution distribution(std::vector<double> values) {
  Distribution d;
  d.count = static_cast<int>(values.size());
  if (values.empty()) return d;
  std::sort(values.begin(), values.end());
  d.mean = std::accumulate(values.begin(), values.end(), 0.0) / static_cast<double>(d.count);
  d.p10 = percentile(values, 0.1);
  d.p50 = percentile(values, 0.5);
  d.p90 = percentile(values, 0.9);
  return d;
}

namespace {

RandomSceneTraits scene_traits(const sim::Scenario& s, const sim::RandomSceneInfo& info) {
  const std::vector<std::string>& texture = sim::texture_kind_names();
  RandomSceneTraits t;
  t.ego_motion = info.ego_motion;
  t.focal_baseline_px_m = s.camera.focal_px * s.camera.baseline_m;
  t.noise_sigma = s.noise_sigma;
  t.jpeg_quality = s.effects.jpeg_quality;
  t.exposure_ms = s.effects.exposure_time_s * 1e3;
  t.shadow_casters = static_cast<int>(s.shadows.casters.size());
  t.ground_texture = texture[static_cast<std::size_t>(s.ground_texture)];
  t.background_texture = texture[static_cast<std::size_t>(s.background_texture)];
  t.shapes = info.shapes;
  t.paths = info.paths;
  for (const sim::Box& b : s.obstacles)
    t.textures.push_back(texture[static_cast<std::size_t>(b.texture)]);
  return t;
}

}  // namespace

RandomSceneResult score_random_scene(std::uint32_t seed, const RandomSuiteOptions& options) {
  const Clock::time_point start = Clock::now();
  sim::RandomSceneInfo info;
  sim::Scenario scenario = sim::random_scenario(seed, &info);
  sim::cap_scenario(scenario, options.max_size, options.max_frames);
  RunOptions run_options =
      make_run_options(options.detector, scenario.platform, nullptr, &scenario.camera);
  run_options.workers = 1;  // the suite runs scenes side by side instead
  run_options.tiles = 1;
  run_options.tokens = 0;
  run_options.threads = 1;

  RandomSceneResult r;
  r.seed = seed;
  r.description = scenario.description;
  r.platform = scenario.platform;
  r.width = scenario.camera.width;
  r.height = scenario.camera.height;
  r.frames = scenario.frames;
  r.fps = scenario.camera.fps;
  r.traits = scene_traits(scenario, info);
  sim::ScenarioSource source(scenario);
  std::vector<char> gt_alarm(static_cast<std::size_t>(scenario.frames), 0);
  std::vector<char> fired(gt_alarm.size(), 0);
  std::map<int, double> entry_ttc_s;  // per obstacle id, its GT TTC at its first colliding frame
  const TruthLookup truth_of = [&](int index) {
    gt_alarm[static_cast<std::size_t>(index)] = source.last_truth().alarm ? 1 : 0;
    for (const core::ObstacleTruth& o : source.last_truth().obstacles)
      if (o.colliding && o.ttc_s) entry_ttc_s.try_emplace(o.id, *o.ttc_s);
    return FrameTruthView{source.last_truth(), source.last_maps().danger};
  };
  const Evaluation evaluation = evaluate(
      source, truth_of, run_options, [&](const core::StereoFrame&, const core::Detection& d) {
        fired[static_cast<std::size_t>(d.frame)] = d.signal ? 1 : 0;
      });
  r.report = evaluation.report;
  if (r.colliding()) {
    bool entering_missed = false;
    for (const auto& [id, lead] : r.report.lead_times_s) {
      if (lead) r.lead_s = r.lead_s ? std::min(*r.lead_s, *lead) : *lead;
      const auto entry = entry_ttc_s.find(id);
      if (entry == entry_ttc_s.end() ||
          entry->second < kEnteringShare * scenario.envelope.horizon_s)
        continue;
      ++r.entering;
      if (!lead) entering_missed = true;
      else r.lead_entering_s = r.lead_entering_s ? std::min(*r.lead_entering_s, *lead) : *lead;
    }
    if (entering_missed) r.lead_entering_s.reset();
    const auto first_gt = std::find(gt_alarm.begin(), gt_alarm.end(), 1);
    const auto first_fired =
        std::find(fired.begin() + (first_gt - gt_alarm.begin()), fired.end(), 1);
    if (first_fired != fired.end())
      r.first_alarm_delay_s =
          static_cast<double>((first_fired - fired.begin()) - (first_gt - gt_alarm.begin())) /
          scenario.camera.fps;
  }
  r.wall_s = seconds_since(start);
  return r;
}

RandomSuiteResult run_random_suite(const RandomSuiteOptions& options,
                                   const std::function<void()>& scene_done) {
  core::throw_if_invalid(validate(options), "eval --suite random");
  const Clock::time_point start = Clock::now();
  RandomSuiteResult result;
  result.scenes.resize(static_cast<std::size_t>(options.count));
  // Scenes side by side, one per thread; each scene's pipeline runs on one thread.
  par::for_each_job(
      options.count, options.jobs,
      [&](int i) {
        result.scenes[static_cast<std::size_t>(i)] =
            score_random_scene(options.first_seed + static_cast<std::uint32_t>(i), options);
      },
      scene_done);
  result.summary = summarise(result.scenes);
  result.summary.wall_s = seconds_since(start);
  return result;
}

nlohmann::json RandomSuiteResult::to_json() const {
  nlohmann::json rows = nlohmann::json::array();
  for (const RandomSceneResult& r : scenes) {
    nlohmann::json row = r.report.to_json();
    row["seed"] = r.seed;
    row["description"] = r.description;
    row["platform"] = r.platform;
    row["width"] = r.width;
    row["height"] = r.height;
    row["frames"] = r.frames;
    row["fps"] = r.fps;
    const RandomSceneTraits& t = r.traits;
    row["scene"] = {{"ego_motion", t.ego_motion},
                    {"focal_baseline_px_m", t.focal_baseline_px_m},
                    {"noise_sigma", t.noise_sigma},
                    {"jpeg_quality", t.jpeg_quality},
                    {"exposure_ms", t.exposure_ms},
                    {"shadow_casters", t.shadow_casters},
                    {"ground_texture", t.ground_texture},
                    {"background_texture", t.background_texture},
                    {"shapes", t.shapes},
                    {"paths", t.paths},
                    {"textures", t.textures}};
    row["colliding"] = r.colliding();
    row["lead_s"] = optional_json(r.lead_s);
    row["lead_entering_s"] = optional_json(r.lead_entering_s);
    row["entering"] = r.entering;
    row["first_alarm_delay_s"] = optional_json(r.first_alarm_delay_s);
    row["badness"] = r.badness();
    row["wall_s"] = r.wall_s;
    rows.push_back(row);
  }
  const RandomSuiteSummary& s = summary;
  nlohmann::json j;
  j["summary"] = {{"scenes", s.scenes},
                  {"colliding", s.colliding},
                  {"clear", s.clear},
                  {"recall_settled", distribution_json(s.recall_settled)},
                  {"lead_s", distribution_json(s.lead_s)},
                  {"missed", s.missed},
                  {"lead_entering_s", distribution_json(s.lead_entering_s)},
                  {"missed_entering", s.missed_entering},
                  {"first_alarm_delay_s", distribution_json(s.first_alarm_delay_s)},
                  {"false_alarm_rate", distribution_json(s.false_alarm_rate)},
                  {"worst_seeds", s.worst_seeds},
                  {"wall_s", s.wall_s}};
  j["scenes"] = rows;
  return j;
}

std::string RandomSuiteResult::table() const {
  const RandomSuiteSummary& s = summary;
  char line[256];
  std::ostringstream out;
  std::snprintf(line, sizeof(line), "scenes %d (colliding %d, clear %d) in %.1f s\n", s.scenes,
                s.colliding, s.clear, s.wall_s);
  out << line;
  // A distribution over no scene reads "-".
  const auto figure = [](const Distribution& d, double value, const char* format) {
    if (d.count == 0) return std::string("-");
    char text[32];
    std::snprintf(text, sizeof(text), format, value);
    return std::string(text);
  };
  out << "colliding: recall_settled mean "
      << figure(s.recall_settled, s.recall_settled.mean, "%.3f") << " p10 "
      << figure(s.recall_settled, s.recall_settled.p10, "%.3f") << "; lead p10 "
      << figure(s.lead_s, s.lead_s.p10, "%.2f s") << " median "
      << figure(s.lead_s, s.lead_s.p50, "%.2f s") << " (" << s.lead_s.count << " warned, "
      << s.missed << " missed)\n           entering the horizon in view: lead p10 "
      << figure(s.lead_entering_s, s.lead_entering_s.p10, "%.2f s") << " median "
      << figure(s.lead_entering_s, s.lead_entering_s.p50, "%.2f s") << " ("
      << s.lead_entering_s.count << " warned, " << s.missed_entering
      << " missed)\n           first alarm after the horizon p90 "
      << figure(s.first_alarm_delay_s, s.first_alarm_delay_s.p90, "%.2f s") << " ("
      << s.first_alarm_delay_s.count << ")\n";
  out << "clear: false alarm rate mean "
      << figure(s.false_alarm_rate, s.false_alarm_rate.mean, "%.3f") << " p90 "
      << figure(s.false_alarm_rate, s.false_alarm_rate.p90, "%.3f") << "\n";
  if (!s.worst_seeds.empty())
    out << "worst scenes (stereoguard simulate --random --seed S --out DIR):\n";
  for (std::uint32_t seed : s.worst_seeds) {
    const auto it = std::find_if(scenes.begin(), scenes.end(),
                                 [seed](const RandomSceneResult& r) { return r.seed == seed; });
    std::snprintf(line, sizeof(line), "  seed %u  %s  recall_settled %.2f  false alarms %.3f  ",
                  seed, it->colliding() ? "colliding" : "clear    ", it->report.recall_settled,
                  it->report.false_alarm_rate);
    out << line << it->description << "\n";
  }
  return out.str();
}

}  // namespace sg::pipeline
