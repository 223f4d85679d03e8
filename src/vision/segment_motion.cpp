#include "sg/vision/segment_motion.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "sg/core/error.hpp"
#include "sg/vision/scene_flow.hpp"
#include "sg/vision/surface_test.hpp"
#include "mask_scan.hpp"
#include "union_find.hpp"

namespace sg::vision {
namespace {

using detail::find_root;
using detail::next_set;
using detail::unite_roots;

bool finite(const cv::Vec3f& v) {
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

/// The last pixels of a column's few most recent runs of distinct disparity: a run that resumes
/// within bridge_rows_per_px * d rows at a similar disparity d is the same surface seen past a
/// stretch the matcher got wrong or left out. `node` names the union-find node of the pixel (a
/// pixel in the reference, a row segment in label_surfaces).
struct Run {
  int node = -1, row = 0;
  float d = 0.0f;
};
constexpr int kRuns = 3;

/// Bridges the member at row y with disparity d (union-find node `node`) to the runs of its
/// column `col` (kRuns entries) that ended within `reach` rows at a disparity within `step`, by
/// join(node, other); then records it in the run it continues, or in place of the one seen
/// longest ago.
template <class Join>
void bridge_column(Run* col, int y, float d, double reach, float step, int node, Join&& join) {
  Run* slot = nullptr;
  for (int k = 0; k < kRuns; ++k) {
    Run& r = col[k];
    if (r.node >= 0 && y - r.row <= reach && std::abs(r.d - d) <= step) {
      join(node, r.node);
      if (!slot) slot = &r;
    }
  }
  if (!slot) {  // a new run: it replaces the one seen longest ago
    slot = col;
    for (int k = 1; k < kRuns; ++k)
      if (col[k].node < 0 || col[k].row < slot->row) slot = &col[k];
  }
  *slot = Run{node, y, d};
}

/// The inputs of label_surfaces: a CV_32F disparity and a CV_8U member mask of one size.
void check_surface_inputs(const cv::Mat& disp, const cv::Mat& member) {
  if (disp.type() != CV_32FC1 || member.type() != CV_8UC1 || member.size() != disp.size())
    throw core::InputError("surfaces: a CV_32F disparity and a CV_8U member mask of one size");
}

/// pool_surface_motion's doubt of each surface s with a middle half [vz_low[s], vz_high[s]] of
/// its V_z (NaN: not doubted, doubt[s] left as is): slope_doubt of the mean residual at each
/// sample time over the pixels of that middle half.
void surface_doubts(const cv::Mat& labels, const cv::Mat& disp, const ChainStrides& strides,
                    const cv::Mat& velocity, const ChainResiduals& startup,
                    const std::vector<float>& vz_low, const std::vector<float>& vz_high,
                    double doubt_se, std::vector<double>& doubt) {
  const size_t slots = startup.times_s.size();
  std::vector<double> sum(vz_low.size() * slots, 0.0);
  std::vector<int> count(sum.size(), 0);
  for (int y = 0; y < labels.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    const float* d = disp.ptr<float>(y);
    const cv::Vec3f* v = velocity.ptr<cv::Vec3f>(y);
    const float* r = startup.residuals_m.ptr<float>(y);
    for (int x = 0; x < labels.cols; ++x) {
      const auto s = static_cast<size_t>(l[x]);
      // NaN bounds (no surface, or not doubted) fail the comparison.
      if (!(v[x][2] >= vz_low[s] && v[x][2] <= vz_high[s]) || !finite(v[x])) continue;
      const int w = strides.weight(d[x]);  // the pixels it stands for, as in the pooling
      const float* rx = r + static_cast<size_t>(x) * slots;
      for (size_t j = 0; j < slots; ++j)
        if (!std::isnan(rx[j])) {
          sum[s * slots + j] += static_cast<double>(w) * rx[j];
          count[s * slots + j] += w;
        }
    }
  }
  std::vector<double> mean(slots);
  for (size_t s = 1; s < vz_low.size(); ++s) {
    if (std::isnan(vz_low[s])) continue;
    for (size_t j = 0; j < slots; ++j) {
      const size_t i = s * slots + j;
      mean[j] = count[i] > 0 ? sum[i] / count[i] : std::numeric_limits<double>::quiet_NaN();
    }
    doubt[s] = slope_doubt(startup.times_s, mean, doubt_se);
  }
}

}  // namespace

int label_surfaces_reference(const cv::Mat& disp, const cv::Mat& member, float step,
                             double bridge_rows_per_px, cv::Mat& labels) {
  check_surface_inputs(disp, member);
  const int w = disp.cols, h = disp.rows;
  std::vector<int> parent(static_cast<size_t>(w) * static_cast<size_t>(h), -1);
  auto unite = [&parent](int a, int b) { unite_roots(parent, a, b); };
  // Per column, the last pixels of its few most recent runs (bridge_column).
  std::vector<Run> runs(bridge_rows_per_px > 0.0 ? static_cast<size_t>(w) * kRuns : 0);
  for (int y = 0; y < h; ++y) {
    const float* d = disp.ptr<float>(y);
    const float* du = y > 0 ? disp.ptr<float>(y - 1) : nullptr;
    const std::uint8_t* m = member.ptr<std::uint8_t>(y);
    const std::uint8_t* mu = y > 0 ? member.ptr<std::uint8_t>(y - 1) : nullptr;
    for (int x = 0; x < w; ++x) {
      if (!m[x]) continue;
      const int i = y * w + x;
      parent[static_cast<size_t>(i)] = i;
      if (x > 0 && m[x - 1] && std::abs(d[x - 1] - d[x]) <= step) unite(i, i - 1);
      if (mu) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int xx = x + dx;
          if (xx < 0 || xx >= w || !mu[xx] || std::abs(du[xx] - d[x]) > step) continue;
          unite(i, i - w + dx);
        }
      }
      if (runs.empty()) continue;
      bridge_column(&runs[static_cast<size_t>(x) * kRuns], y, d[x], bridge_rows_per_px * d[x],
                    step, i, unite);
    }
  }
  labels.create(disp.size(), CV_32SC1);
  std::vector<int> id(parent.size(), 0);
  int count = 1;
  for (int y = 0; y < h; ++y) {
    int* l = labels.ptr<int>(y);
    for (int x = 0; x < w; ++x) {
      const int i = y * w + x;
      if (parent[static_cast<size_t>(i)] < 0) {
        l[x] = 0;
        continue;
      }
      const int r = find_root(parent, i);
      if (id[static_cast<size_t>(r)] == 0) id[static_cast<size_t>(r)] = count++;
      l[x] = id[static_cast<size_t>(r)];
    }
  }
  return count;
}

int label_surfaces(const cv::Mat& disp, const cv::Mat& member, float step,
                   double bridge_rows_per_px, cv::Mat& labels) {
  check_surface_inputs(disp, member);
  const int w = disp.cols, h = disp.rows;
  // The nodes are segments: a row's runs of members whose left neighbours are continuous, so
  // that the union-find holds thousands of nodes, not every pixel. Segments are made in raster
  // order, as the reference meets pixels. The partition does not depend on the order of the
  // unions, so a row is done in three passes: its segments, their joins to the row above (one
  // union per pair of segments that touch: the first continuous pixel pair found is enough), and
  // the bridges, which must see every pixel.
  struct Segment {
    int y, x0, x1;  ///< row, first and one past the last column
  };
  std::vector<Segment> segments;
  std::vector<int> parent;
  std::vector<int> above(static_cast<size_t>(w), -1), here(static_cast<size_t>(w), -1);
  // Per column, as in the reference, its few most recent runs (bridge_column), naming segments.
  std::vector<Run> runs(bridge_rows_per_px > 0.0 ? static_cast<size_t>(w) * kRuns : 0);
  for (int y = 0; y < h; ++y) {
    const float* d = disp.ptr<float>(y);
    const float* du = y > 0 ? disp.ptr<float>(y - 1) : nullptr;
    const std::uint8_t* m = member.ptr<std::uint8_t>(y);
    const size_t first = segments.size();
    std::fill(here.begin(), here.end(), -1);
    int* h_row = here.data();
    for (int x = next_set(m, 0, w); x < w; x = next_set(m, x, w)) {
      const int seg = static_cast<int>(segments.size());
      const int x0 = x;
      h_row[x++] = seg;
      while (x < w && m[x] && std::abs(d[x - 1] - d[x]) <= step) h_row[x++] = seg;
      segments.push_back({y, x0, x});
      parent.push_back(seg);
    }
    for (size_t s = first; du && s < segments.size(); ++s) {
      // Above neighbours of [x0, x1) lie in [x0 - 1, x1]; walk them by stretches of one segment.
      const Segment g = segments[s];
      const int seg = static_cast<int>(s);
      const int end = std::min(w - 1, g.x1);
      for (int xx = std::max(0, g.x0 - 1); xx <= end;) {
        const int a = above[static_cast<size_t>(xx)];
        if (a < 0) {
          ++xx;
          continue;
        }
        bool touch = false;
        for (; xx <= end && above[static_cast<size_t>(xx)] == a; ++xx) {
          if (touch) continue;
          const int lo = std::max(g.x0, xx - 1), hi = std::min(g.x1 - 1, xx + 1);
          for (int x = lo; x <= hi && !touch; ++x) touch = std::abs(du[xx] - d[x]) <= step;
        }
        if (touch) unite_roots(parent, seg, a);
      }
    }
    if (!runs.empty()) {
      for (size_t s = first; s < segments.size(); ++s) {
        // Along a segment its pixels meet the same runs' segments over and over: only the first
        // meeting needs the union-find.
        const int seg = static_cast<int>(s);
        int joined = seg;
        auto join = [&parent, &joined](int node, int other) {
          if (other == joined) return;
          unite_roots(parent, node, other);
          joined = other;
        };
        for (int x = segments[s].x0; x < segments[s].x1; ++x)
          bridge_column(&runs[static_cast<size_t>(x) * kRuns], y, d[x], bridge_rows_per_px * d[x],
                        step, seg, join);
      }
    }
    std::swap(above, here);
  }
  labels.create(disp.size(), CV_32SC1);
  labels.setTo(0);
  // Numbered as the reference numbers them: in the raster order of each surface's first pixel,
  // which is the first pixel of its first segment.
  std::vector<int> id(segments.size(), 0);
  int count = 1;
  for (size_t s = 0; s < segments.size(); ++s) {
    const int r = find_root(parent, static_cast<int>(s));
    if (id[static_cast<size_t>(r)] == 0) id[static_cast<size_t>(r)] = count++;
    const Segment& g = segments[s];
    int* l = labels.ptr<int>(g.y);
    std::fill(l + g.x0, l + g.x1, id[static_cast<size_t>(r)]);
  }
  return count;
}

float interquartile_mean(std::vector<float>& v) { return interquartile_mean(v.data(), v.size()); }

float interquartile_mean(float* v, size_t n) {
  const size_t quarter = n / 4;
  float* const low = v + quarter;
  float* const high = v + (n - quarter);
  // Ranks below `quarter` go left of `low`; then, among the rest, ranks from n - quarter go right
  // of `high`: [low, high) holds exactly the middle ranks, in some order.
  std::nth_element(v, low, v + n);
  if (quarter > 0) std::nth_element(low, high, v + n);
  // In double, so that the order (not the sort's) changes the float result by a rounding at most.
  double sum = 0.0;
  for (const float* it = low; it != high; ++it) sum += *it;
  return static_cast<float>(sum / static_cast<double>(high - low));
}

namespace {

/// Weighted selection on a[lo, hi) (value, weight) pairs whose preceding elements weigh `base`:
/// partitions it (std::nth_element steps, expected O(hi - lo)) until the element k covering
/// weight position `pos` (base + weight of [lo, k) <= pos < that + its own weight) has only
/// values <= its own before it and >= after it. Returns k; `base` becomes the weight before k.
size_t weighted_select(std::pair<float, int>* a, size_t lo, size_t hi, long long& base,
                       long long pos) {
  while (hi - lo > 1) {
    const size_t mid = lo + (hi - lo) / 2;
    std::nth_element(a + lo, a + mid, a + hi);
    long long left = 0;
    for (size_t i = lo; i < mid; ++i) left += a[i].second;
    if (pos < base + left) {
      hi = mid;
    } else if (pos < base + left + a[mid].second) {
      base += left;
      return mid;
    } else {
      base += left + a[mid].second;
      lo = mid + 1;
    }
  }
  return lo;
}

}  // namespace

float weighted_interquartile_mean(const float* v, const int* w, size_t n,
                                  std::vector<std::pair<float, int>>& scratch, float* low,
                                  float* high) {
  scratch.resize(n);
  long long total = 0;
  for (size_t i = 0; i < n; ++i) {
    scratch[i] = {v[i], w[i]};
    total += w[i];
  }
  // The copies of the sorted values occupy positions [0, total): keep [trim, end). Two weighted
  // selections find the values on the borders; what lies between them is the middle, in some
  // order (a sort of a near surface's thousands of samples cost 1 ms a frame).
  const long long trim = total / 4, end = total - trim;
  std::pair<float, int>* a = scratch.data();
  long long before_first = 0;
  const size_t first = weighted_select(a, 0, n, before_first, trim);
  const long long first_to = std::min(before_first + a[first].second, end);
  if (low) *low = a[first].first;
  if (first_to >= end) {  // both borders in one value
    if (high) *high = a[first].first;
    return a[first].first;
  }
  long long before_last = before_first + a[first].second;
  const size_t last = weighted_select(a, first + 1, n, before_last, end - 1);
  if (high) *high = a[last].first;
  double sum = static_cast<double>(a[first].first) * static_cast<double>(first_to - trim);
  for (size_t i = first + 1; i < last; ++i)
    sum += static_cast<double>(a[i].first) * static_cast<double>(a[i].second);
  sum += static_cast<double>(a[last].first) * static_cast<double>(end - before_last);
  return static_cast<float>(sum / static_cast<double>(end - trim));
}

double slope_doubt(const std::vector<double>& times_s, const std::vector<double>& residuals,
                   double doubt_se) {
  // Student's t, 97.5 % quantile, by degrees of freedom 1..20; beyond, 1.96 + 2.4 / dof is
  // within 0.01 of it.
  static constexpr double kT975[] = {12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365,
                                     2.306,  2.262, 2.228, 2.201, 2.179, 2.160, 2.145,
                                     2.131,  2.120, 2.110, 2.101, 2.093, 2.086};
  double n = 0.0, st = 0.0, sr = 0.0;
  for (size_t j = 0; j < times_s.size(); ++j)
    if (std::isfinite(residuals[j])) {
      n += 1.0;
      st += times_s[j];
      sr += residuals[j];
    }
  if (n < 3.0) return std::numeric_limits<double>::infinity();
  const double tb = st / n, rb = sr / n;
  double stt = 0.0, str = 0.0, srr = 0.0;
  for (size_t j = 0; j < times_s.size(); ++j)
    if (std::isfinite(residuals[j])) {
      const double dt = times_s[j] - tb, dr = residuals[j] - rb;
      stt += dt * dt;
      str += dt * dr;
      srr += dr * dr;
    }
  if (!(stt > 0.0)) return std::numeric_limits<double>::infinity();
  // Unweighted: over the few frames of a short chain the pixels' weights (d_k / d_i)^4 stay near
  // one, except for near, fast approaches, which clear any doubt.
  const double dof = n - 2.0;
  const double ssr = std::max(0.0, srr - str * str / stt);
  const double se = std::sqrt(ssr / dof / stt);
  const double t = dof <= 20.0 ? kT975[static_cast<int>(dof) - 1] : 1.96 + 2.4 / dof;
  return doubt_se * (t / 1.96) * se;
}

void pool_surface_motion(const cv::Mat& disp, const core::Camera& cam, const core::Envelope& env,
                         const core::SceneFlowParams& p, double span_s, const cv::Mat& edges,
                         cv::Mat& danger, cv::Mat& ttc, cv::Mat& velocity,
                         const ChainResiduals& startup, double yaw_rate_rps,
                         const cv::Mat& ground_side) {
  if (!ground_side.empty() &&
      (ground_side.type() != CV_8UC1 || ground_side.size() != disp.size()))
    throw core::InputError("surface motion: the ground side must be CV_8U of the maps' size");
  if (disp.type() != CV_32FC1 || edges.type() != CV_8UC1 || danger.type() != CV_8UC1 ||
      ttc.type() != CV_32FC1 || velocity.type() != CV_32FC3 || edges.size() != disp.size() ||
      danger.size() != disp.size() || ttc.size() != disp.size() || velocity.size() != disp.size())
    throw core::InputError(
        "surface motion: maps must be CV_32F disparity, CV_8U danger, CV_32F TTC and CV_32FC3 "
        "velocity of one size");
  if (!startup.residuals_m.empty() &&
      (startup.residuals_m.type() != CV_32FC(static_cast<int>(startup.times_s.size())) ||
       startup.residuals_m.size() != disp.size()))
    throw core::InputError(
        "surface motion: the residuals must be CV_32F with one channel per sample time, of the "
        "maps' size");
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  // The labelling's candidates: valid, near enough, off the depth-edge margin, in the band.
  const float d_min = static_cast<float>(cam.focal_px * cam.baseline_m / p.z_max_m);
  // Surfaces: the same without the depth-edge test, joined where neighbours' disparities are
  // continuous: the margin keeps a pixel out of the test, not out of its object.
  cv::Mat candidate(disp.size(), CV_8UC1), member(disp.size(), CV_8UC1);
  for (int y = 0; y < disp.rows; ++y) {
    const float* d = disp.ptr<float>(y);
    const std::uint8_t* e = edges.ptr<std::uint8_t>(y);
    std::uint8_t* c = candidate.ptr<std::uint8_t>(y);
    std::uint8_t* m = member.ptr<std::uint8_t>(y);
    for (int x = 0; x < disp.cols; ++x) {
      bool ok = d[x] > 0.0f && d[x] >= d_min;
      if (ok && p.use_envelope_band) {
        const double Y = (y - cam.cy) * cam.baseline_m / d[x];
        ok = Y >= env.y_top_m && Y <= env.y_bottom_m;
      }
      m[x] = ok ? 255 : 0;
      c[x] = ok && e[x] == 0 ? 255 : 0;
    }
  }
  cv::Mat labels;
  // A gap of bridge_m at depth Z = f B / d spans bridge_m f / Z = (bridge_m / B) d rows.
  const float step = static_cast<float>(p.edge_step_px);
  const double bridge = p.surface_bridge_m / cam.baseline_m;
  int count = 0;
  if (ground_side.empty()) {
    count = label_surfaces(disp, member, step, bridge, labels);
  } else {
    // Each side labelled on its own, the off side's surfaces numbered after the ground side's.
    cv::Mat off_member, off_labels;
    cv::bitwise_and(member, ~ground_side, off_member);
    cv::bitwise_and(member, ground_side, member);
    const int on = label_surfaces(disp, member, step, bridge, labels);
    const int off = label_surfaces(disp, off_member, step, bridge, off_labels);
    cv::add(off_labels, cv::Scalar(on - 1), off_labels, off_member);
    off_labels.copyTo(labels, off_member);
    count = on + off - 1;
  }
  // Velocity components per surface, in raster order (each surface's values one after another
  // in three flat arrays: a count, then a fill), then their interquartile means.
  const auto surfaces = static_cast<size_t>(count);
  std::vector<size_t> start(surfaces + 1, 0);
  auto for_known = [&](auto&& f) {
    for (int y = 0; y < disp.rows; ++y) {
      const int* l = labels.ptr<int>(y);
      const float* d = disp.ptr<float>(y);
      const cv::Vec3f* v = velocity.ptr<cv::Vec3f>(y);
      for (int x = 0; x < disp.cols; ++x)
        if (l[x] != 0 && finite(v[x])) f(static_cast<size_t>(l[x]), v[x], d[x]);
    }
  };
  for_known([&start](size_t s, const cv::Vec3f&, float) { ++start[s + 1]; });
  for (size_t s = 0; s < surfaces; ++s) start[s + 1] += start[s];
  std::vector<float> vx(start[surfaces]), vy(vx.size()), vz(vx.size());
  // A velocity followed on a stride grid stands for the pixels of its cell: a surface reaching
  // from far (every pixel followed) to near (one in up to 256) is pooled as if every pixel had
  // been followed, not biased to its far part (a hand-carried 122 x 94 camera 1.3 m from a
  // cylinder joined to the floor behind it: -0.07 to -0.22 m/s pooled for a true -0.37).
  const ChainStrides strides(cam, p);
  std::vector<int> weight(vx.size());
  std::vector<std::uint8_t> uneven(surfaces, 0);  // weights differ within the surface
  std::vector<size_t> next(start.begin(), start.end() - 1);
  for_known([&](size_t s, const cv::Vec3f& v, float d) {
    const size_t i = next[s]++;
    vx[i] = v[0];
    vy[i] = v[1];
    vz[i] = v[2];
    weight[i] = strides.weight(d);
    if (i > start[s] && weight[i] != weight[start[s]]) uneven[s] = 1;
  });
  std::vector<cv::Vec3f> pooled(surfaces, cv::Vec3f(kNaN, kNaN, kNaN));
  // The middle half of each weighted surface's V_z, for the doubt below.
  std::vector<float> weighted_low(surfaces, kNaN), weighted_high(surfaces, kNaN);
  std::vector<std::pair<float, int>> scratch;
  for (size_t s = 1; s < surfaces; ++s) {
    const size_t n = start[s + 1] - start[s];
    if (n == 0) continue;
    if (uneven[s]) {
      const int* w = &weight[start[s]];
      pooled[s] = cv::Vec3f(
          weighted_interquartile_mean(&vx[start[s]], w, n, scratch),
          weighted_interquartile_mean(&vy[start[s]], w, n, scratch),
          weighted_interquartile_mean(&vz[start[s]], w, n, scratch, &weighted_low[s],
                                      &weighted_high[s]));
    } else {  // equal weights: the O(n) selection gives the same mean
      pooled[s] = cv::Vec3f(interquartile_mean(&vx[start[s]], n),
                            interquartile_mean(&vy[start[s]], n),
                            interquartile_mean(&vz[start[s]], n));
    }
  }

  // Per surface: whether its pixels are tested at all. Faster than max_speed_mps is a mismatch,
  // and V keep can reach the envelope's approach speed v_min_mps > 0 only if V does
  // (0 < keep <= 1).
  const double max_speed2 = p.max_speed_mps * p.max_speed_mps;
  std::vector<std::uint8_t> tested(pooled.size(), 0);
  for (size_t s = 1; s < pooled.size(); ++s) {
    const cv::Vec3d V(pooled[s]);
    tested[s] = finite(pooled[s]) && V.dot(V) <= max_speed2 && V[2] <= -p.v_min_mps;
  }
  // A chain short of its window: the doubt of each tested surface, from its own fit's scatter.
  // interquartile_mean left each equally weighted surface's V_z partitioned: its middle half is
  // the middle ranks.
  std::vector<double> doubt(surfaces, 0.0);
  if (!startup.residuals_m.empty()) {
    std::vector<float> vz_low(surfaces, kNaN), vz_high(surfaces, kNaN);
    for (size_t s = 1; s < surfaces; ++s) {
      if (!tested[s]) continue;
      if (uneven[s]) {
        vz_low[s] = weighted_low[s];
        vz_high[s] = weighted_high[s];
        continue;
      }
      const size_t n = start[s + 1] - start[s];
      const auto middle =
          std::minmax_element(vz.begin() + static_cast<std::ptrdiff_t>(start[s] + n / 4),
                              vz.begin() + static_cast<std::ptrdiff_t>(start[s + 1] - n / 4));
      vz_low[s] = *middle.first;
      vz_high[s] = *middle.second;
    }
    surface_doubts(labels, disp, strides, velocity, startup, vz_low, vz_high, p.startup_doubt_se,
                   doubt);
  }
  // Every candidate of a tested surface, a run of one surface's pixels at a time (SIMD).
  const SurfaceTest test = make_surface_test(cam, env, p, span_s, yaw_rate_rps);
  for (int y = 0; y < disp.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    const float* d = disp.ptr<float>(y);
    std::uint8_t* out = danger.ptr<std::uint8_t>(y);
    float* t = ttc.ptr<float>(y);
    cv::Vec3f* v = velocity.ptr<cv::Vec3f>(y);
    const std::uint8_t* c = candidate.ptr<std::uint8_t>(y);
    for (int x = 0; x < disp.cols;) {
      const auto s = static_cast<size_t>(l[x]);
      int end = x + 1;
      while (end < disp.cols && l[end] == l[x]) ++end;
      if (s == 0) {  // no surface: safe, no velocity
        std::fill(t + x, t + end, kNaN);
        std::fill(v + x, v + end, cv::Vec3f(kNaN, kNaN, kNaN));
        std::fill(out + x, out + end, std::uint8_t{0});
        x = end;
        continue;
      }
      // The slowest approach along the same path that the doubt allows decides.
      const double keep = 1.0 - doubt[s] / -static_cast<double>(pooled[s][2]);
      if (tested[s] && keep > 0.0)
        test_surface_run(test, cv::Vec3d(pooled[s]), keep, y, x, end, d, t);
      else
        std::fill(t + x, t + end, kNaN);
      for (; x < end; ++x) {
        v[x] = c[x] == 0 ? cv::Vec3f(kNaN, kNaN, kNaN) : pooled[s];  // pooled[0]: NaN
        if (c[x] == 0) t[x] = kNaN;  // on the depth-edge margin: never dangerous
        out[x] = std::isnan(t[x]) ? 0 : 255;
      }
    }
  }
}

}  // namespace sg::vision
