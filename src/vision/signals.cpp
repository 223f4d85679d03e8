#include "sg/vision/signals.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "sg/core/error.hpp"
#include "sg/vision/components.hpp"
#include "sg/vision/order_stats.hpp"

namespace sg::vision {
namespace {

struct Blob {
  std::vector<float> disparities;  ///< > 0
  std::vector<float> ttcs;
  cv::Vec3d velocity_sum{0.0, 0.0, 0.0};
  int velocity_count = 0;
};

/// The median of the depths of `disparities` (> 0): depth falls as disparity grows, so the
/// depths' middle ranks are the disparities' middle ranks, and no depth needs computing but those.
double median_depth(const std::vector<float>& disparities, const core::Camera& camera) {
  const size_t mid = disparities.size() / 2;
  if (disparities.size() % 2 == 1) return camera.depth(kth_smallest(disparities, mid));
  const auto [lower, upper] = adjacent_smallest(disparities, mid);
  return 0.5 * (camera.depth(upper) + camera.depth(lower));
}

}  // namespace

std::vector<core::Obstacle> extract_obstacles(cv::Mat& mask, const cv::Mat& disp,
                                              const cv::Mat& ttc, const core::Camera& camera,
                                              const core::SignalParams& p,
                                              const cv::Mat& velocity,
                                              std::vector<ObstacleRun>* obstacle_runs) {
  const bool with_velocity = !velocity.empty();
  if (with_velocity && (velocity.type() != CV_32FC3 || velocity.size() != mask.size()))
    throw core::InputError("obstacles: the velocity map must be CV_32FC3 of the mask's size");
  if (p.open_size > 1) {
    const cv::Mat kernel =
        cv::getStructuringElement(cv::MORPH_RECT, cv::Size(p.open_size, p.open_size));
    cv::morphologyEx(mask, mask, cv::MORPH_OPEN, kernel);
  }
  std::vector<ComponentRun> runs;
  std::vector<ComponentStats> stats;
  const int count = connected_runs(mask, runs, stats);

  std::vector<Blob> blobs(static_cast<size_t>(count));
  std::vector<std::uint8_t> kept_blob(static_cast<size_t>(count), 0);
  for (int l = 1; l < count; ++l)
    kept_blob[static_cast<size_t>(l)] = stats[static_cast<size_t>(l)].area >= p.min_area_px;
  // Run by run in raster order: each blob's pixels come in raster order, as in a pixel scan.
  for (const ComponentRun& run : runs) {
    uchar* m = mask.ptr<uchar>(run.y);
    if (!kept_blob[static_cast<size_t>(run.label)]) {
      std::fill(m + run.x0, m + run.x1, 0);
      continue;
    }
    Blob& b = blobs[static_cast<size_t>(run.label)];
    if (b.disparities.capacity() == 0) {
      const auto area = static_cast<size_t>(stats[static_cast<size_t>(run.label)].area);
      b.disparities.reserve(area);
      b.ttcs.reserve(area);
    }
    const float* d = disp.ptr<float>(run.y);
    const float* t = ttc.ptr<float>(run.y);
    const cv::Vec3f* v = with_velocity ? velocity.ptr<cv::Vec3f>(run.y) : nullptr;
    for (int x = run.x0; x < run.x1; ++x) {
      if (d[x] > 0.0f) b.disparities.push_back(d[x]);
      if (std::isfinite(t[x])) b.ttcs.push_back(t[x]);
      if (v && std::isfinite(v[x][0]) && std::isfinite(v[x][1]) && std::isfinite(v[x][2])) {
        b.velocity_sum += cv::Vec3d(v[x]);
        ++b.velocity_count;
      }
    }
  }

  // Labels are numbered in the raster order of the blobs' first pixels.
  std::vector<core::Obstacle> out;
  std::vector<int> index_of(static_cast<size_t>(count), -1);
  for (int l = 1; l < count; ++l) {
    if (!kept_blob[static_cast<size_t>(l)]) continue;
    index_of[static_cast<size_t>(l)] = static_cast<int>(out.size());
    Blob& b = blobs[static_cast<size_t>(l)];
    core::Obstacle o;
    o.bbox = stats[static_cast<size_t>(l)].bbox;
    o.pixels = stats[static_cast<size_t>(l)].area;
    o.distance_m = b.disparities.empty() ? 0.0 : median_depth(b.disparities, camera);
    if (!b.ttcs.empty()) o.ttc_s = median_of(b.ttcs);
    if (b.velocity_count > 0) o.velocity = b.velocity_sum * (1.0 / b.velocity_count);
    out.push_back(o);
  }
  if (obstacle_runs) {
    obstacle_runs->clear();
    for (const ComponentRun& run : runs)
      if (kept_blob[static_cast<size_t>(run.label)])
        obstacle_runs->push_back({run.y, run.x0, run.x1, index_of[static_cast<size_t>(run.label)]});
  }
  return out;
}

bool clear_obstacles(cv::Mat& mask, const std::vector<ObstacleRun>& runs,
                     const std::vector<bool>& keep) {
  bool cleared = false;
  for (const ObstacleRun& run : runs) {
    if (keep[static_cast<size_t>(run.obstacle)]) continue;
    uchar* m = mask.ptr<uchar>(run.y);
    std::fill(m + run.x0, m + run.x1, 0);
    cleared = true;
  }
  return cleared;
}

std::vector<std::string> region_names(int columns) {
  if (columns == 3) return {"left", "centre", "right"};
  std::vector<std::string> names;
  for (int i = 0; i < columns; ++i) {
    std::string name = "r";  // not "r" + ...: GCC 12 warns falsely (-Wrestrict, PR 105329)
    name += std::to_string(i);
    names.push_back(name);
  }
  return names;
}

std::vector<int> count_region_pixels(const cv::Mat& mask, int columns) {
  std::vector<int> counts(static_cast<size_t>(columns), 0);
  for (int c = 0; c < columns; ++c) {
    const int x0 = c * mask.cols / columns;
    const int x1 = (c + 1) * mask.cols / columns;
    if (x1 > x0)
      counts[static_cast<size_t>(c)] = cv::countNonZero(mask.colRange(x0, x1));
  }
  return counts;
}

RegionHysteresis::RegionHysteresis(const core::SignalParams& p) : p_(p) {}

std::vector<core::RegionSignal> RegionHysteresis::update(const std::vector<int>& region_pixels) {
  const size_t n = region_pixels.size();
  if (history_.size() != n) {  // first frame (or a new grid): start clear
    history_.assign(n, {});
    clear_run_.assign(n, 0);
    on_.assign(n, false);
  }
  const std::vector<std::string> names = region_names(static_cast<int>(n));
  std::vector<core::RegionSignal> out(n);
  for (size_t r = 0; r < n; ++r) {
    const bool dangerous = region_pixels[r] > p_.region_min_px;
    std::deque<bool>& h = history_[r];
    h.push_back(dangerous);
    while (static_cast<int>(h.size()) > p_.on_n) h.pop_front();
    clear_run_[r] = dangerous ? 0 : clear_run_[r] + 1;
    if (!on_[r]) {
      if (std::count(h.begin(), h.end(), true) >= p_.on_k) on_[r] = true;
    } else if (clear_run_[r] >= p_.off_m) {
      on_[r] = false;
      h.clear();  // so that old dangerous frames cannot turn it straight back on
    }
    out[r] = {names[r], on_[r], region_pixels[r]};
  }
  return out;
}

core::Severity severity_of(bool signal, const std::vector<core::Obstacle>& obstacles,
                           const core::SignalParams& p) {
  if (!signal) return core::Severity::kNone;
  double min_ttc = std::numeric_limits<double>::infinity();
  bool any = false;
  for (const core::Obstacle& o : obstacles) {
    if (!o.ttc_s) continue;
    any = true;
    min_ttc = std::min(min_ttc, *o.ttc_s);
  }
  // A signal held on by hysteresis over a frame without obstacles is still a warning.
  if (!any) return core::Severity::kWarning;
  if (min_ttc <= p.ttc_danger_s) return core::Severity::kDanger;
  if (min_ttc <= p.ttc_warning_s) return core::Severity::kWarning;
  return core::Severity::kNone;
}

core::Steering steering_hint(const std::vector<core::RegionSignal>& regions) {
  const int n = static_cast<int>(regions.size());
  const bool any_fired = std::any_of(regions.begin(), regions.end(),
                                     [](const core::RegionSignal& r) { return r.fired; });
  if (!any_fired) return core::Steering::kStraight;
  // The centre-most clear column wins; among equally central ones the one with fewer dangerous
  // pixels, then the left one. Positions are doubled so that the centre (n - 1) / 2 is integral.
  int best = -1;
  for (int c = 0; c < n; ++c) {
    if (regions[static_cast<size_t>(c)].fired) continue;
    if (best < 0) {
      best = c;
      continue;
    }
    const int dc = std::abs(2 * c - (n - 1));
    const int db = std::abs(2 * best - (n - 1));
    if (dc < db || (dc == db && regions[static_cast<size_t>(c)].dangerous_px <
                                    regions[static_cast<size_t>(best)].dangerous_px))
      best = c;
  }
  if (best < 0) return core::Steering::kStop;
  const int side = 2 * best - (n - 1);
  if (side == 0) return core::Steering::kStraight;
  return side < 0 ? core::Steering::kLeft : core::Steering::kRight;
}

}  // namespace sg::vision
