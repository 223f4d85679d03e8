#include "sg/vision/tracking.hpp"

#include <algorithm>
#include <cmath>
#include <tuple>

namespace sg::vision {
namespace {

// Slower closing than this (1 cm/s) is a standing obstacle: no TTC rather than a huge one.
constexpr double kMinClosingMps = 0.01;

}  // namespace

bool fit_line(const std::vector<double>& t, const std::vector<double>& z, double& distance_now,
              double& rate) {
  const size_t n = std::min(t.size(), z.size());
  if (n < 2) return false;
  const double t0 = t[n - 1];
  double st = 0, sz = 0, stt = 0, stz = 0;
  for (size_t i = 0; i < n; ++i) {
    const double x = t[i] - t0;
    st += x;
    sz += z[i];
    stt += x * x;
    stz += x * z[i];
  }
  const double den = n * stt - st * st;
  if (!(den > 1e-12)) return false;
  rate = (n * stz - st * sz) / den;
  distance_now = (sz - rate * st) / n;
  return true;
}

ObstacleTracker::ObstacleTracker(const core::SignalParams& p, double z_contact_m,
                                 double z_near_limit_m, double focal_baseline)
    : p_(p),
      z_contact_m_(z_contact_m),
      z_near_limit_m_(z_near_limit_m),
      focal_baseline_(focal_baseline) {}

bool ObstacleTracker::holds_together(double z_last, double z_now, double v_z, double dt) const {
  if (!(focal_baseline_ > 0.0)) return true;
  const double moved = v_z * dt;
  const double matching = (z_last * z_last + z_now * z_now) / focal_baseline_;
  const double tolerance = 0.1 * z_now + 0.25 * std::abs(moved) + 2.0 * matching;
  return std::abs(z_now - (z_last + moved)) <= tolerance;
}

bool ObstacleTracker::out_of_reach(const Track& track, double time_s) const {
  double z_now = 0;
  return p_.coast_near_range && track.predict(time_s, z_now) && track.fit_rate < -kMinClosingMps &&
         z_now < kNearRangeMargin * z_near_limit_m_;
}

void ObstacleTracker::set_from_fit(double z_now, double rate, core::Obstacle& o) const {
  o.distance_m = z_now;
  o.closing_speed_mps = -rate;
  if (z_now <= z_contact_m_) {
    o.ttc_s = 0.0;
  } else if (-rate > kMinClosingMps) {
    o.ttc_s = (z_now - z_contact_m_) / -rate;
  } else {
    o.ttc_s.reset();
  }
}

void ObstacleTracker::update(double time_s, std::vector<core::Obstacle>& obstacles) {
  // Every (age, likeness, track, obstacle) pair that overlaps enough, oldest track first, then
  // most alike. A pair overlaps enough when the intersection covers track_min_overlap of the
  // smaller box. Among the blobs of one track the one most like it by intersection over union
  // wins, so that when a blob splits (noise cuts a fragment off) its track goes on with the main
  // part, not with a fragment lying inside its old box, which would restart the main part's TTC
  // fit. Among the tracks of one blob the oldest wins: when the fragments of a thin pole merge
  // again, the blob keeps the longest history, not the fragment's that happens to fit its box best.
  std::vector<std::tuple<double, double, size_t, size_t>> pairs;
  for (size_t k = 0; k < tracks_.size(); ++k)
    for (size_t j = 0; j < obstacles.size(); ++j) {
      const cv::Rect& a = tracks_[k].bbox;
      const cv::Rect& b = obstacles[j].bbox;
      const double smaller = std::min(a.area(), b.area());
      if (smaller <= 0) continue;
      const double common = (a & b).area();
      if (common / smaller >= p_.track_min_overlap)
        pairs.emplace_back(tracks_[k].first_s, common / (a.area() + b.area() - common), k, j);
    }
  std::sort(pairs.begin(), pairs.end(), [](const auto& x, const auto& y) {
    if (std::get<0>(x) != std::get<0>(y)) return std::get<0>(x) < std::get<0>(y);
    return std::get<1>(x) > std::get<1>(y);
  });
  std::vector<int> track_of(obstacles.size(), -1);
  std::vector<bool> taken(tracks_.size(), false);
  for (const auto& [since, overlap, k, j] : pairs) {
    if (taken[k] || track_of[j] >= 0) continue;
    taken[k] = true;
    track_of[j] = static_cast<int>(k);
  }
  std::vector<Track> next;
  for (size_t j = 0; j < obstacles.size(); ++j) {
    core::Obstacle& o = obstacles[j];
    Track track;
    if (track_of[j] >= 0) {
      track = std::move(tracks_[static_cast<size_t>(track_of[j])]);
    } else {
      track.id = next_id_++;
      track.first_s = time_s;
    }
    const cv::Rect last_bbox = track.bbox;
    track.bbox = o.bbox;
    o.track_id = track.id;
    track.seen = track_of[j] >= 0 ? track.seen + 1 : 1;
    if (o.distance_m > 0) {
      if (track.last_z > 0 && o.velocity &&
          !holds_together(track.last_z, o.distance_m, (*o.velocity)[2], time_s - track.last_t))
        track.seen = 1;
      track.last_t = time_s;
      track.last_z = o.distance_m;
    }
    o.seen_frames = track.seen;
    // A blob measured nearer than the margin has a disparity at the top of the search range,
    // saturated or aliased: it does not enter the fit either.
    const bool measured_near = p_.coast_near_range && o.distance_m > 0 &&
                               o.distance_m < kNearRangeMargin * z_near_limit_m_;
    if (out_of_reach(track, time_s) ||
        (measured_near && track.fitted && track.fit_rate < -kMinClosingMps)) {
      // Its disparity is beyond the matcher's range: the measurement is not the obstacle's, and
      // the blob is at most a fragment of it (an approaching object does not shrink), so it keeps
      // the box it was last seen with too.
      track.bbox = last_bbox | o.bbox;
      o.bbox = track.bbox;
      double z_now = 0;
      track.predict(time_s, z_now);
      set_from_fit(z_now, track.fit_rate, o);
      o.predicted = true;
      next.push_back(std::move(track));
      continue;
    }
    if (o.distance_m > 0 && !measured_near) {
      track.t.push_back(time_s);
      track.z.push_back(o.distance_m);
    }
    while (!track.t.empty() && track.t.front() < time_s - p_.ttc_fit_window_s - 1e-9) {
      track.t.pop_front();
      track.z.pop_front();
    }
    double z_now = 0, rate = 0;
    if (static_cast<int>(track.t.size()) >= p_.ttc_fit_min_frames &&
        track.t.back() - track.t.front() >= p_.ttc_fit_min_span_s - 1e-9 &&
        fit_line({track.t.begin(), track.t.end()}, {track.z.begin(), track.z.end()}, z_now, rate)) {
      set_from_fit(z_now, rate, o);
      track.fitted = true;
      track.fit_t = track.t.back();
      track.fit_z = z_now;
      track.fit_rate = rate;
    }
    next.push_back(std::move(track));
  }
  // Tracks whose blob vanished where the matcher cannot see it go on by prediction until contact.
  for (size_t k = 0; k < tracks_.size(); ++k) {
    Track& track = tracks_[k];
    if (taken[k] || !out_of_reach(track, time_s)) continue;
    core::Obstacle o;
    double z_now = 0;
    track.predict(time_s, z_now);
    set_from_fit(z_now, track.fit_rate, o);
    if (!o.ttc_s || *o.ttc_s <= 0.0) continue;  // contact reached: the track ends
    o.bbox = track.bbox;
    o.track_id = track.id;
    o.predicted = true;
    o.seen_frames = ++track.seen;
    obstacles.push_back(o);
    next.push_back(std::move(track));
  }
  tracks_ = std::move(next);
}

core::Severity SeverityHold::update(bool signal, core::Severity wanted) {
  if (!signal) {
    current_ = core::Severity::kNone;
    lower_run_ = 0;
    return current_;
  }
  if (wanted >= current_) {
    current_ = wanted;
    lower_run_ = 0;
  } else if (++lower_run_ >= off_frames_) {
    current_ = wanted;
    lower_run_ = 0;
  }
  return current_;
}

}  // namespace sg::vision
