#include "sg/vision/scene_flow.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <random>
#include <sstream>

#include "sg/core/error.hpp"

namespace sg::vision {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr int kMaxChainStride = 16;  ///< the sparsest grid of followed pixels, however near
constexpr float kSqrt2 = 1.41421356f;

// Splits a coordinate into integer cell and fraction; false outside [0, n-1] or not finite.
inline bool split(float v, int n, int& i, float& f) {
  if (!(v >= 0.0f) || !(v <= static_cast<float>(n - 1))) return false;  // also rejects NaN
  i = static_cast<int>(v);
  f = v - static_cast<float>(i);
  return true;
}

void check_same(const cv::Mat& ref, const cv::Mat& m, int type, const char* what) {
  if (m.type() != type || m.size() != ref.size()) {
    std::ostringstream s;
    s << "scene flow: " << what << " must be " << cv::typeToString(type) << " of size " << ref.cols
      << "x" << ref.rows << " (got " << cv::typeToString(m.type()) << " " << m.cols << "x" << m.rows
      << ")";
    throw core::InputError(s.str());
  }
}

/// One gap's verdict for one pixel.
struct GapResult {
  bool velocity_known = false;
  bool dangerous = false;
  cv::Vec3d velocity;
  double ttc = 0.0;
};

/// The per-pixel test of DESIGN 3.2 once the source position q and D_{i-k}(q) are known; the
/// camera constants are hoisted out of the pixel loop (same maths as point_velocity).
class PixelTest {
 public:
  PixelTest(const core::Camera& cam, const core::Envelope& env, const SceneFlowParams& p)
      : fb_(cam.focal_px * cam.baseline_m),
        inv_f_(1.0 / cam.focal_px),
        cx_(cam.cx),
        cy_(cam.cy),
        max_speed2_(p.max_speed_mps * p.max_speed_mps),
        env_(env),
        p_(p) {}

  /// The 3D point seen at (x, y) with disparity d > 0, m.
  cv::Vec3d point(float x, float y, float d) const {
    const double z = fb_ / d;
    return {(x - cx_) * z * inv_f_, (y - cy_) * z * inv_f_, z};
  }

  /// The verdict for the point P_i = point(x, y, d_cur) moving at V (m/s), measured over span_s
  /// seconds: the noise gate (the disparity P_i had span_s seconds earlier at that velocity is at
  /// least min_delta_d_px below d_cur), the speed gate, then heads_into_envelope.
  GapResult verdict(const cv::Vec3d& P, float d_cur, const cv::Vec3d& V, double span_s) const {
    GapResult r;
    r.velocity = V;
    r.velocity_known = true;
    const double z_before = P[2] - V[2] * span_s;
    if (!(z_before > 0.0) || static_cast<double>(d_cur) - fb_ / z_before < p_.min_delta_d_px ||
        V.dot(V) > max_speed2_)
      return r;
    r.dangerous = heads_into_envelope(cv::Point3d(P), V, env_, p_.v_min_mps, r.ttc);
    return r;
  }

  /// derotate (may be null): turns P_{i-k} into frame i's orientation.
  GapResult operator()(float x, float y, float d_cur, cv::Point2f q, float d_prev, double span_s,
                       const cv::Matx33d* derotate = nullptr) const {
    GapResult r;
    if (!(d_prev > 0.0f)) return r;  // d_cur > 0 was checked by the caller
    const cv::Vec3d P = point(x, y, d_cur);
    cv::Vec3d Pp = point(q.x, q.y, d_prev);
    if (derotate) Pp = *derotate * Pp;
    r.velocity = (P - Pp) * (1.0 / span_s);
    r.velocity_known = true;
    if (static_cast<double>(d_cur) - d_prev < p_.min_delta_d_px ||
        r.velocity.dot(r.velocity) > max_speed2_)
      return r;
    r.dangerous = heads_into_envelope(cv::Point3d(P), r.velocity, env_, p_.v_min_mps, r.ttc);
    return r;
  }

 private:
  double fb_, inv_f_, cx_, cy_, max_speed2_;
  const core::Envelope& env_;
  const SceneFlowParams& p_;
};

/// Weighted least-squares line through a point's 3D positions over time: t = 0 now, t < 0 in
/// the past frames of its chain; the slope is its velocity.
struct VelocityFit {
  double sw = 0.0, st = 0.0, stt = 0.0;
  cv::Vec3d sp, stp;
  double span_s = 0.0;  ///< the oldest sample's distance in time, s
  int n = 0;
  cv::Vec3d now;  ///< the position at t = 0

  void reset(const cv::Vec3d& position) {
    *this = VelocityFit{};
    now = position;
    add(0.0, position, 1.0);
  }
  void add(double t, const cv::Vec3d& P, double w) {
    sw += w;
    st += w * t;
    stt += w * t * t;
    sp += w * P;
    stp += (w * t) * P;
    span_s = std::max(span_s, -t);
    ++n;
  }
  /// False with fewer than two samples at distinct times.
  bool slope(cv::Vec3d& v) const {
    if (n < 2) return false;
    const double tb = st / sw, spread = stt - st * tb;  // sum w (t - tb)^2
    if (!(spread > 0.0)) return false;
    v = (stp - tb * sp) * (1.0 / spread);
    return true;
  }
};

/// Each followed pixel's samples of one row's velocity fits: its depth and weight at each sample
/// time (depth NaN: no sample), for the outlier test and the residuals. Slot 0 is now, slot
/// gi + 1 the gi-th gap's frame.
struct ChainSamples {
  int slots = 0;
  std::vector<double> times;  ///< per slot, s (<= 0)
  std::vector<float> depths;  ///< per pixel, then slot, m
  std::vector<double> weights;

  ChainSamples(const std::vector<GapSource>& gaps, int cols)
      : slots(1 + static_cast<int>(gaps.size())),
        times(static_cast<size_t>(slots), 0.0),
        depths(static_cast<size_t>(slots) * cols),
        weights(depths.size()) {
    for (size_t j = 1; j < times.size(); ++j) times[j] = -gaps[j - 1].span_s;
  }
  float* depth(int x) { return &depths[static_cast<size_t>(x) * slots]; }
  const float* depth(int x) const { return &depths[static_cast<size_t>(x) * slots]; }
  const double* weight(int x) const { return &weights[static_cast<size_t>(x) * slots]; }
  void start(int x, double z_now) {
    float* z = depth(x);
    std::fill(z, z + slots, kNaN);
    z[0] = static_cast<float>(z_now);
    weights[static_cast<size_t>(x) * slots] = 1.0;
  }
  void add(int x, size_t gi, double z, double w) {
    depths[static_cast<size_t>(x) * slots + gi + 1] = static_cast<float>(z);
    weights[static_cast<size_t>(x) * slots + gi + 1] = w;
  }
};

/// Whether a sample of pixel x's velocity fit `f` is an outlier: its disparity departs from the
/// line fitted through the chain's other samples by more than p.chain_outlier_px and more than
/// p.chain_outlier_fraction of its own disparity. A repetitive texture matched one period off in
/// some frames, or a flow that slid onto another surface, steps by whole pixels; the matcher's
/// noise stays under the pixel bound, a smooth change of speed under the fraction.
bool chain_has_outlier(const VelocityFit& f, const ChainSamples& s, int x, double fb,
                       const SceneFlowParams& p) {
  if (f.n < 3) return false;  // two samples left make a line through both: nothing to test
  const float* z = s.depth(x);
  const double* w = s.weight(x);
  const double* t = s.times.data();
  for (int j = 0; j < s.slots; ++j) {
    if (std::isnan(z[j])) continue;
    const double sw = f.sw - w[j], st = f.st - w[j] * t[j], stt = f.stt - w[j] * t[j] * t[j];
    const double sz = f.sp[2] - w[j] * z[j], stz = f.stp[2] - w[j] * t[j] * z[j];
    const double tb = st / sw, spread = stt - st * tb;
    if (!(sw > 0.0) || !(spread > 1e-12)) continue;  // the others share one time
    const double line = sz / sw + (stz - tb * sz) / spread * (t[j] - tb);
    if (!(line > 0.0)) return true;  // the others' line leaves the space before the camera
    const double d = fb / z[j];
    if (std::abs(d - fb / line) > std::max(p.chain_outlier_px, p.chain_outlier_fraction * d))
      return true;
  }
  return false;
}

/// mark_depth_edges at one pixel: the valid disparities of the window around (x, y) span more
/// than `step`. Used for the past source q of the few pixels that pass every other test.
bool near_depth_edge(const cv::Mat& disp, int x, int y, int r, float step) {
  float hi = -1.0f, lo = std::numeric_limits<float>::max();
  for (int yy = std::max(0, y - r); yy <= std::min(disp.rows - 1, y + r); ++yy) {
    const float* row = disp.ptr<float>(yy);
    for (int xx = std::max(0, x - r); xx <= std::min(disp.cols - 1, x + r); ++xx) {
      if (row[xx] < 0.0f) continue;
      hi = std::max(hi, row[xx]);
      lo = std::min(lo, row[xx]);
    }
  }
  return hi >= 0.0f && hi - lo > step;
}

}  // namespace

ChainStrides::ChainStrides(const core::Camera& cam, const SceneFlowParams& p)
    : stride_(p.pool_surface_motion ? p.chain_stride : 1),
      d_stride_(stride_ > 1 ? static_cast<float>(cam.focal_px * cam.baseline_m / p.chain_stride_z_m)
                            : std::numeric_limits<float>::infinity()) {}

cv::Size ChainStrides::at(float d) const {
  if (!(d >= d_stride_)) return {1, 1};
  // Each sqrt(2) nearer doubles one of the two strides, columns first, then rows: an object's
  // pixels grow as 1 / Z^2, the ones followed stay about as many at every distance, not only at
  // each halving. (Rows first raised the false alarms of the thin pole, a column few pixels wide,
  // from 0.014 to 0.027.)
  int sx = stride_;
  int sy = stride_;
  for (float next = kSqrt2 * d_stride_; d >= next && sx < kMaxChainStride; next *= kSqrt2) {
    if (sy == sx) {
      sx *= 2;
    } else {
      sy *= 2;
    }
  }
  return {sx, sy};
}

void mark_depth_edges(const cv::Mat& disp, int margin_px, double step_px, cv::Mat& mask) {
  if (disp.type() != CV_32FC1) throw core::InputError("depth edges: disparity must be CV_32F");
  mask.create(disp.size(), CV_8UC1);
  if (margin_px <= 0) {
    mask.setTo(0);
    return;
  }
  // Invalid pixels (< 0) must not count: they are already below any valid value for the maximum,
  // and are lifted above any for the minimum.
  cv::Mat lifted = disp.clone();
  lifted.setTo(std::numeric_limits<float>::max(), disp < 0.0f);
  const cv::Mat kernel =
      cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * margin_px + 1, 2 * margin_px + 1));
  cv::Mat hi, lo;
  cv::dilate(disp, hi, kernel, cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(-1.0));
  cv::erode(lifted, lo, kernel, cv::Point(-1, -1), 1, cv::BORDER_CONSTANT,
            cv::Scalar(std::numeric_limits<float>::max()));
  const float step = static_cast<float>(step_px);
  for (int y = 0; y < disp.rows; ++y) {
    const float* h = hi.ptr<float>(y);
    const float* l = lo.ptr<float>(y);
    uint8_t* m = mask.ptr<uint8_t>(y);
    for (int x = 0; x < disp.cols; ++x) m[x] = h[x] >= 0.0f && h[x] - l[x] > step ? 255 : 0;
  }
}

bool sample_disparity_bilinear(const cv::Mat& disp, float x, float y, float& out, float max_step) {
  int x0, y0;
  float fx, fy;
  if (!split(x, disp.cols, x0, fx) || !split(y, disp.rows, y0, fy)) return false;
  const float* r0 = disp.ptr<float>(y0) + x0;
  const float* r1 = fy > 0.0f ? disp.ptr<float>(y0 + 1) + x0 : r0;
  const float d00 = r0[0];
  const float d01 = fx > 0.0f ? r0[1] : 0.0f;
  const float d10 = fy > 0.0f ? r1[0] : 0.0f;
  const float d11 = fx > 0.0f && fy > 0.0f ? r1[1] : 0.0f;
  if (d00 < 0.0f || d01 < 0.0f || d10 < 0.0f || d11 < 0.0f) return false;
  if (max_step < std::numeric_limits<float>::infinity()) {
    // Unused neighbours stand in as d00 so that they do not widen the spread.
    const float a = fx > 0.0f ? d01 : d00, b = fy > 0.0f ? d10 : d00;
    const float c = fx > 0.0f && fy > 0.0f ? d11 : d00;
    const float hi = std::max({d00, a, b, c}), lo = std::min({d00, a, b, c});
    if (hi - lo > max_step) return false;
  }
  out = (1.0f - fy) * ((1.0f - fx) * d00 + fx * d01) + fy * ((1.0f - fx) * d10 + fx * d11);
  return true;
}

bool sample_flow_bilinear(const cv::Mat& flow, float x, float y, cv::Vec2f& out) {
  int x0, y0;
  float fx, fy;
  if (!split(x, flow.cols, x0, fx) || !split(y, flow.rows, y0, fy)) return false;
  const float* r0 = flow.ptr<float>(y0) + 2 * x0;
  const float* r1 = fy > 0.0f ? flow.ptr<float>(y0 + 1) + 2 * x0 : r0;
  // Unused neighbours read as zero; a used non-finite one makes the sum non-finite.
  float u = (1.0f - fx) * r0[0], v = (1.0f - fx) * r0[1];
  if (fx > 0.0f) u += fx * r0[2], v += fx * r0[3];
  if (fy > 0.0f) {
    float u1 = (1.0f - fx) * r1[0], v1 = (1.0f - fx) * r1[1];
    if (fx > 0.0f) u1 += fx * r1[2], v1 += fx * r1[3];
    u = (1.0f - fy) * u + fy * u1;
    v = (1.0f - fy) * v + fy * v1;
  }
  if (!std::isfinite(u) || !std::isfinite(v)) return false;
  out = cv::Vec2f(u, v);
  return true;
}

bool point_velocity(cv::Point2f p, float d_cur, cv::Point2f q, float d_prev,
                    const core::Camera& camera, double dt, cv::Vec3d& velocity,
                    cv::Point3d& position) {
  if (!(d_cur > 0.0f) || !(d_prev > 0.0f) || !(dt > 0.0)) return false;
  const cv::Point3d now = camera.point(p.x, p.y, d_cur);
  const cv::Point3d before = camera.point(q.x, q.y, d_prev);
  velocity = cv::Vec3d(now - before) / dt;
  position = now;
  return true;
}

bool heads_into_envelope(const cv::Point3d& P, const cv::Vec3d& V, const core::Envelope& e,
                         double v_min, double& t_contact) {
  if (!(V[2] <= -v_min)) return false;
  const double t_c = (P.z - e.z_contact_m) / -V[2];
  if (!(t_c > 0.0) || t_c > e.horizon_s) return false;
  const double x = P.x + V[0] * t_c;
  const double y = P.y + V[1] * t_c;
  if (std::abs(x) > e.half_width_m || y < e.y_top_m || y > e.y_bottom_m) return false;
  t_contact = t_c;
  return true;
}

bool heads_into_envelope_turning(const cv::Point3d& P, const cv::Vec3d& V, double yaw_rate_rps,
                                 const core::Envelope& e, double v_min, double& t_contact) {
  const double w = yaw_rate_rps;
  if (w == 0.0) return heads_into_envelope(P, V, e, v_min, t_contact);
  if (!(V[2] <= -v_min) || !(P.z > e.z_contact_m)) return false;
  // P(t) - C turns counter-clockwise in (X, Z) by w t: (x, z) -> (x cos - z sin, x sin + z cos).
  const double cx = -V[2] / w, cz = V[0] / w;
  const double dx = P.x - cx, dz = P.z - cz;
  const double h = e.z_contact_m - cz;  // the contact plane, relative to C
  const double r2 = dx * dx + dz * dz;
  // Cheap refusals first (most pixels): Z falls no faster than the speed |w| r on the circle, so
  // the plane is at least (P_z - z_contact) / (|w| r) away; and the crossing is one of the two
  // points where the circle meets the plane, both outside the envelope's width here.
  const double to_plane = P.z - e.z_contact_m, reach = e.horizon_s * w;
  if (to_plane * to_plane > reach * reach * r2) return false;
  const double s2 = r2 - h * h;
  if (!(s2 >= 0.0)) return false;  // its circle never reaches the plane
  const double s = std::sqrt(s2);
  if (std::abs(cx + s) > e.half_width_m && std::abs(cx - s) > e.half_width_m) return false;
  // The first of the two crossings along the travel: the smaller angle from (dx, dz) to
  // (qx, h) in the direction of travel, compared by a pseudo-angle that grows with it over
  // [0, 2 pi) (atan2 only for the one chosen).
  const auto along = [&](double qx, double& sine, double& cosine) {
    sine = (w < 0.0 ? -1.0 : 1.0) * (dx * h - dz * qx);
    cosine = dx * qx + dz * h;
    const double p = cosine / (std::abs(sine) + std::abs(cosine));
    return sine >= 0.0 ? 1.0 - p : 3.0 + p;
  };
  double sin_a = 0.0, cos_a = 0.0, sin_b = 0.0, cos_b = 0.0;
  const bool first = along(s, sin_a, cos_a) <= along(-s, sin_b, cos_b);
  const double best_x = cx + (first ? s : -s);
  double a = first ? std::atan2(sin_a, cos_a) : std::atan2(sin_b, cos_b);
  if (a < 0.0) a += 2.0 * CV_PI;
  const double best = a / std::abs(w);
  if (!(best > 0.0) || best > e.horizon_s) return false;
  const double y = P.y + V[1] * best;
  if (std::abs(best_x) > e.half_width_m || y < e.y_top_m || y > e.y_bottom_m) return false;
  t_contact = best;
  return true;
}

std::vector<int> sampled_gaps(const SceneFlowParams& p) {
  if (!p.fit_velocity || p.gaps.empty()) return p.gaps;
  std::vector<int> all(
      static_cast<size_t>(std::max(1, *std::max_element(p.gaps.begin(), p.gaps.end()))));
  std::iota(all.begin(), all.end(), 1);
  return all;
}

void label_stereo_flow(const cv::Mat& disp_cur, const cv::Mat& disp_prev, const cv::Mat& flow,
                       const core::Camera& cam, const core::Envelope& env, const SceneFlowParams& p,
                       double dt, cv::Mat& danger, cv::Mat& ttc, cv::Mat& velocity) {
  SceneFlowParams one = p;
  one.gaps = {1};
  label_stereo_flow_window(disp_cur, {&disp_prev}, {&flow}, cam, env, one, dt, danger, ttc,
                           velocity);
}

void label_stereo_flow_window(const cv::Mat& disp_cur,
                              const std::vector<const cv::Mat*>& past_disps,
                              const std::vector<const cv::Mat*>& past_flows,
                              const core::Camera& cam, const core::Envelope& env,
                              const SceneFlowParams& p, double dt, cv::Mat& danger, cv::Mat& ttc,
                              cv::Mat& velocity, const cv::Mat* edges_cur,
                              const std::vector<const cv::Mat*>* edges_past) {
  if (disp_cur.type() != CV_32FC1) throw core::InputError("scene flow: disparity must be CV_32F");
  const int history = static_cast<int>(std::min(past_disps.size(), past_flows.size()));
  std::vector<GapSource> gaps;
  for (int k : sampled_gaps(p)) {
    if (k < 1 || k > history) continue;
    const cv::Mat* edges = nullptr;
    if (edges_past) {
      if (k > static_cast<int>(edges_past->size()))
        throw core::InputError("scene flow: fewer past depth-edge masks than past disparities");
      edges = (*edges_past)[static_cast<size_t>(k - 1)];
    }
    gaps.push_back({k, past_disps[static_cast<size_t>(k - 1)], edges, k * dt});
  }
  cv::Mat own_edges;
  if (!edges_cur) mark_depth_edges(disp_cur, p.edge_margin_px, p.edge_step_px, own_edges);
  const cv::Mat& edges = edges_cur ? *edges_cur : own_edges;
  allocate_stereo_flow_outputs(disp_cur.size(), danger, ttc, velocity);
  label_stereo_flow_rows(disp_cur, edges, past_flows, gaps, cam, env, p, danger, ttc, velocity,
                         cv::Range(0, disp_cur.rows));
}

void allocate_stereo_flow_outputs(cv::Size size, cv::Mat& danger, cv::Mat& ttc, cv::Mat& velocity) {
  danger.create(size, CV_8UC1);
  ttc.create(size, CV_32FC1);
  velocity.create(size, CV_32FC3);
}

namespace {

/// label_stereo_flow_rows' inputs for one call: the gaps ascending by chain length (one per
/// length: the chain is walked once per pixel), the pixel test and the sampling bounds.
struct RowInputs {
  const cv::Mat& disp_cur;
  std::vector<GapSource> gaps;
  const SceneFlowParams& p;
  PixelTest test;
  float max_step;
  double fb;

  /// Whether the source `at` of gap g lies near a depth edge of its past disparity.
  bool past_edge(const GapSource& g, cv::Point2f at) const {
    if (p.edge_margin_px <= 0) return false;
    const int x = std::clamp(cvRound(at.x), 0, disp_cur.cols - 1);
    const int y = std::clamp(cvRound(at.y), 0, disp_cur.rows - 1);
    if (g.edges) return g.edges->at<uint8_t>(y, x) != 0;
    return near_depth_edge(*g.disparity, x, y, p.edge_margin_px,
                           static_cast<float>(p.edge_step_px));
  }
};

/// One row's outputs.
struct RowOutputs {
  uint8_t* danger;
  float* ttc;
  cv::Vec3f* velocity;
  float* residuals;  ///< slots per pixel, or null
};

/// With fit_velocity: gap gi's sample of every live pixel's chain (now at q[x]) goes into its fit
/// unless its past disparity is invalid, mixes a depth edge, or lies near one.
void add_fit_samples(const RowInputs& in, size_t gi, const std::vector<int>& live,
                     const std::vector<cv::Point2f>& q, const float* d_row,
                     std::vector<VelocityFit>& fits, ChainSamples& samples) {
  const GapSource& g = in.gaps[gi];
  for (const int x : live) {
    float d_prev;
    if (!sample_disparity_bilinear(*g.disparity, q[x].x, q[x].y, d_prev, in.max_step) ||
        !(d_prev > 0.0f) || in.past_edge(g, q[x]))
      continue;
    cv::Vec3d P = in.test.point(q[x].x, q[x].y, d_prev);
    if (g.derotate) P = *g.derotate * P;
    // Weight 1 / var(Z) relative to now's: Z's error grows as Z^2 = (f B / d)^2.
    const double rel = static_cast<double>(d_prev) / d_row[x];
    const double w = rel * rel * rel * rel;
    fits[x].add(-g.span_s, P, w);
    samples.add(x, gi, P[2], w);
  }
}

/// Without fit_velocity: gap gi's verdict for every live pixel of row y (its chain now at q[x]).
void apply_gap_verdicts(const RowInputs& in, size_t gi, int y, const std::vector<int>& live,
                        const std::vector<cv::Point2f>& q, const float* d_row,
                        const RowOutputs& out) {
  const GapSource& g = in.gaps[gi];
  const cv::Vec3f unknown(kNaN, kNaN, kNaN);
  for (const int x : live) {
    float d_prev;
    if (!sample_disparity_bilinear(*g.disparity, q[x].x, q[x].y, d_prev, in.max_step)) continue;
    const GapResult res = in.test(static_cast<float>(x), static_cast<float>(y), d_row[x], q[x],
                                  d_prev, g.span_s, g.derotate);
    if (!res.velocity_known) continue;
    // A source near a past depth edge pairs the object now with the background before (or
    // the reverse): neither its verdict nor its velocity can be trusted.
    const bool at_edge = in.past_edge(g, q[x]);
    const bool dangerous = res.dangerous && !at_edge;
    const cv::Vec3f v = at_edge ? unknown : cv::Vec3f(res.velocity);
    if (in.p.longest_gap_decides) {
      // Gaps ascend: each known estimate replaces those of the shorter, noisier gaps.
      out.danger[x] = dangerous ? 255 : 0;
      out.ttc[x] = dangerous ? static_cast<float>(res.ttc) : kNaN;
      out.velocity[x] = v;
    } else if (dangerous) {
      if (out.danger[x] == 0 || res.ttc < out.ttc[x]) {
        out.ttc[x] = static_cast<float>(res.ttc);
        out.velocity[x] = cv::Vec3f(res.velocity);
      }
      out.danger[x] = 255;
    } else if (out.danger[x] == 0 && !at_edge) {
      out.velocity[x] = v;  // larger gaps come later: least noisy wins
    }
  }
}

/// With fit_velocity: each candidate's fitted velocity, verdict and residuals, unless its chain
/// has an outlier (then its velocity is unknown).
void conclude_fits(const RowInputs& in, const std::vector<int>& candidates,
                   const std::vector<VelocityFit>& fits, const ChainSamples& samples,
                   const float* d_row, const RowOutputs& out) {
  const int slots = samples.slots;
  const bool outlier_test = in.p.chain_outlier_px > 0.0;
  for (const int x : candidates) {
    cv::Vec3d V;
    float* r_px = out.residuals ? out.residuals + x * slots : nullptr;
    const VelocityFit& f = fits[x];
    if (!f.slope(V) || (outlier_test && chain_has_outlier(f, samples, x, in.fb, in.p))) {
      if (r_px) std::fill_n(r_px, slots, kNaN);
      continue;
    }
    const GapResult res = in.test.verdict(f.now, d_row[x], V, f.span_s);
    out.danger[x] = res.dangerous ? 255 : 0;
    out.ttc[x] = res.dangerous ? static_cast<float>(res.ttc) : kNaN;
    out.velocity[x] = cv::Vec3f(res.velocity);
    if (!r_px) continue;
    // Z's distance from the fitted line at each sample: now, then the past frames' samples.
    const double tb = f.st / f.sw, zb = f.sp[2] / f.sw;
    const float* z = samples.depth(x);
    for (int j = 0; j < slots; ++j)
      r_px[j] = std::isnan(z[j]) ? kNaN
                                 : static_cast<float>(z[j] - (zb + V[2] * (samples.times[j] - tb)));
  }
}

}  // namespace

void label_stereo_flow_rows(const cv::Mat& disp_cur, const cv::Mat& edges_cur,
                            const std::vector<const cv::Mat*>& flows,
                            const std::vector<GapSource>& gap_sources, const core::Camera& cam,
                            const core::Envelope& env, const SceneFlowParams& p, cv::Mat& danger,
                            cv::Mat& ttc, cv::Mat& velocity, cv::Range rows, cv::Mat* residuals) {
  if (disp_cur.type() != CV_32FC1) throw core::InputError("scene flow: disparity must be CV_32F");
  check_same(disp_cur, edges_cur, CV_8UC1, "the depth-edge mask");
  check_same(disp_cur, danger, CV_8UC1, "the danger output");
  check_same(disp_cur, ttc, CV_32FC1, "the TTC output");
  check_same(disp_cur, velocity, CV_32FC3, "the velocity output");
  RowInputs in{disp_cur, {}, p, PixelTest(cam, env, p),
               static_cast<float>(p.max_disparity_step_px), cam.focal_px * cam.baseline_m};
  std::vector<GapSource>& gaps = in.gaps;
  for (const GapSource& g : gap_sources) {
    if (g.steps < 1 || g.steps > static_cast<int>(flows.size()) || !(g.span_s > 0.0)) continue;
    check_same(disp_cur, *g.disparity, CV_32FC1, "a past disparity");
    if (g.edges) check_same(disp_cur, *g.edges, CV_8UC1, "a past depth-edge mask");
    gaps.push_back(g);
  }
  std::stable_sort(gaps.begin(), gaps.end(),
                   [](const GapSource& a, const GapSource& b) { return a.steps < b.steps; });
  gaps.erase(std::unique(gaps.begin(), gaps.end(),
                         [](const GapSource& a, const GapSource& b) { return a.steps == b.steps; }),
             gaps.end());
  const int longest = gaps.empty() ? 0 : gaps.back().steps;
  // The fit's residuals: one channel for now, then one per distinct chain length.
  const int slots = 1 + static_cast<int>(gaps.size());
  if (residuals && !p.fit_velocity) residuals = nullptr;
  if (residuals) check_same(disp_cur, *residuals, CV_32FC(slots), "the residual output");
  for (int j = 0; j < longest; ++j)
    check_same(disp_cur, *flows[static_cast<size_t>(j)], CV_32FC2, "a flow");
  const cv::Range r = rows == cv::Range::all() ? cv::Range(0, disp_cur.rows) : rows;

  const float d_min = static_cast<float>(in.fb / p.z_max_m);
  // Nearer than chain_stride_z_m only a grid of pixels is followed (pooling gives the others
  // their surface's velocity). By absolute row and column, so tiles follow the same pixels.
  const ChainStrides strides(cam, p);
  auto in_band = [&cam, &env](int y, float d) {
    const double Y = (y - cam.cy) * cam.baseline_m / d;  // (y - cy) * Z / f
    return Y >= env.y_top_m && Y <= env.y_bottom_m;
  };

  // Row by row, step-major: every live pixel of the row advances its chain by one flow before the
  // next step, so the independent chains overlap instead of waiting on one another. Only
  // candidates are followed (the chains are the cost of the labelling), kept in a compact list.
  std::vector<cv::Point2f> q(disp_cur.cols);
  std::vector<int> live, candidates;
  live.reserve(disp_cur.cols);
  candidates.reserve(disp_cur.cols);
  std::vector<VelocityFit> fits(p.fit_velocity ? disp_cur.cols : 0);
  ChainSamples samples(gaps, p.fit_velocity ? disp_cur.cols : 0);
  for (int y = r.start; y < r.end; ++y) {
    const float* d_row = disp_cur.ptr<float>(y);
    const uint8_t* edge_row = edges_cur.ptr<uint8_t>(y);
    const RowOutputs out{danger.ptr<uint8_t>(y), ttc.ptr<float>(y), velocity.ptr<cv::Vec3f>(y),
                         residuals ? residuals->ptr<float>(y) : nullptr};
    if (out.residuals)
      std::fill(out.residuals, out.residuals + static_cast<size_t>(slots) * disp_cur.cols, kNaN);
    live.clear();
    const auto fy = static_cast<float>(y);
    for (int x = 0; x < disp_cur.cols; ++x) {
      out.danger[x] = 0;
      out.ttc[x] = kNaN;
      out.velocity[x] = cv::Vec3f(kNaN, kNaN, kNaN);
      if (d_row[x] > 0.0f && d_row[x] >= d_min && edge_row[x] == 0 &&
          strides.followed(x, y, d_row[x]) && (!p.use_envelope_band || in_band(y, d_row[x]))) {
        q[x] = cv::Point2f(static_cast<float>(x), fy);
        live.push_back(x);
        if (p.fit_velocity) {
          fits[x].reset(in.test.point(static_cast<float>(x), fy, d_row[x]));
          samples.start(x, fits[x].now[2]);
        }
      }
    }
    if (p.fit_velocity) candidates = live;
    int step = 0;
    for (size_t gi = 0; gi < gaps.size(); ++gi) {
      for (; step < gaps[gi].steps && !live.empty(); ++step) {
        const cv::Mat& flow = *flows[static_cast<size_t>(step)];
        size_t kept = 0;
        for (const int x : live) {
          cv::Vec2f f;
          // A point that left the image is lost for every longer gap too.
          if (!sample_flow_bilinear(flow, q[x].x, q[x].y, f)) continue;
          q[x] += cv::Point2f(f[0], f[1]);
          live[kept++] = x;
        }
        live.resize(kept);
      }
      if (live.empty()) break;
      if (p.fit_velocity)
        add_fit_samples(in, gi, live, q, d_row, fits, samples);
      else
        apply_gap_verdicts(in, gi, y, live, q, d_row, out);
    }
    if (p.fit_velocity) conclude_fits(in, candidates, fits, samples, d_row, out);
  }
}

GroundPlane fit_ground_plane(const cv::Mat& disp, const core::Camera& cam, const GroundParams& p) {
  if (disp.type() != CV_32FC1) throw core::InputError("ground plane: disparity must be CV_32F");
  std::vector<cv::Point3d> pts;
  const int y0 = disp.rows - std::max(1, static_cast<int>(disp.rows * p.lower_fraction));
  const int step = std::max(1, p.sample_step_px);
  for (int y = y0; y < disp.rows; y += step) {
    const float* row = disp.ptr<float>(y);
    for (int x = 0; x < disp.cols; x += step) {
      if (!(row[x] > 0.0f)) continue;
      const cv::Point3d P = cam.point(x, y, row[x]);
      if (P.z <= p.z_max_m) pts.push_back(P);
    }
  }
  GroundPlane best;
  if (pts.size() < 3) return best;
  const double kMinUp = std::cos(CV_PI / 4);  // |n_y| >= cos 45 deg: roughly horizontal
  // The points by coordinate, so that the inlier count is a tight loop over arrays.
  const std::size_t n_pts = pts.size();
  std::vector<double> xs(n_pts), ys(n_pts), zs(n_pts);
  for (std::size_t i = 0; i < n_pts; ++i) xs[i] = pts[i].x, ys[i] = pts[i].y, zs[i] = pts[i].z;
  // Inliers of the plane n.P + c = 0; stops once even all the points left could not make more
  // than `beat` (the count returned is then at most `beat`).
  auto count = [&](const cv::Vec3d& n, double c, int beat) {
    int inliers = 0;
    constexpr std::size_t kBlock = 256;
    for (std::size_t i0 = 0; i0 < n_pts; i0 += kBlock) {
      const std::size_t i1 = std::min(n_pts, i0 + kBlock);
      int in_block = 0;
      for (std::size_t i = i0; i < i1; ++i)
        in_block += std::abs(n[0] * xs[i] + n[1] * ys[i] + n[2] * zs[i] + c) <= p.tolerance_m;
      inliers += in_block;
      if (inliers + static_cast<int>(n_pts - i1) <= beat) return inliers;
    }
    return inliers;
  };
  std::mt19937_64 rng(p.seed);
  std::uniform_int_distribution<size_t> pick(0, pts.size() - 1);
  for (int it = 0; it < p.iterations; ++it) {
    const cv::Vec3d a(pts[pick(rng)]), b(pts[pick(rng)]), c(pts[pick(rng)]);
    cv::Vec3d n = (b - a).cross(c - a);
    const double len = cv::norm(n);
    if (len < 1e-9) continue;
    n /= len;
    if (n[1] > 0) n = -n;  // point up (y down)
    if (-n[1] < kMinUp) continue;
    const int inliers = count(n, -n.dot(a), best.inliers);
    if (inliers > best.inliers) best = {n, -n.dot(a), inliers, false};
  }
  if (best.inliers < std::max(3, p.min_inliers)) return GroundPlane{};
  // Least-squares refit on the inliers: the normal is the smallest-eigenvalue direction.
  cv::Vec3d mean(0, 0, 0);
  std::vector<cv::Vec3d> in;
  for (const auto& P : pts)
    if (std::abs(best.normal.dot(cv::Vec3d(P)) + best.offset) <= p.tolerance_m) in.emplace_back(P);
  for (const auto& P : in) mean += P;
  mean /= static_cast<double>(in.size());
  cv::Matx33d cov = cv::Matx33d::zeros();
  for (const auto& P : in) cov += (P - mean) * (P - mean).t();
  cv::Mat evals, evecs;
  cv::eigen(cov, evals, evecs);  // descending eigenvalues
  cv::Vec3d n(evecs.at<double>(2, 0), evecs.at<double>(2, 1), evecs.at<double>(2, 2));
  if (n[1] > 0) n = -n;
  if (-n[1] >= kMinUp) {
    best.normal = n;
    best.offset = -n.dot(mean);
    best.inliers = count(best.normal, best.offset, -1);
  }
  best.found = best.inliers >= p.min_inliers;
  return best;
}

void mark_ground(const cv::Mat& disp, const core::Camera& cam, const GroundPlane& plane,
                 double tolerance_m, cv::Mat& mask, const cv::Mat& only) {
  if (disp.type() != CV_32FC1) throw core::InputError("ground mask: disparity must be CV_32F");
  if (!only.empty() && (only.type() != CV_8UC1 || only.size() != disp.size()))
    throw core::InputError("ground mask: `only` must be CV_8U of the disparity's size");
  mask.create(disp.size(), CV_8UC1);
  mask.setTo(0);
  if (!plane.found) return;
  for (int y = 0; y < disp.rows; ++y) {
    const float* row = disp.ptr<float>(y);
    const uint8_t* wanted = only.empty() ? nullptr : only.ptr<uint8_t>(y);
    uint8_t* out = mask.ptr<uint8_t>(y);
    for (int x = 0; x < disp.cols; ++x) {
      if (!(row[x] > 0.0f) || (wanted && !wanted[x])) continue;
      const cv::Point3d P = cam.point(x, y, row[x]);
      if (plane.normal.dot(cv::Vec3d(P)) + plane.offset <= tolerance_m) out[x] = 255;
    }
  }
}

void mark_ground_side(const cv::Mat& disp, const core::Camera& cam, const GroundPlane& plane,
                      double tolerance_m, double margin_px, cv::Mat& mask) {
  mark_ground(disp, cam, plane, tolerance_m, mask);  // on or below the plane; all 0 without one
  if (!plane.found) return;
  // With P = (B / d) (x - cx, y - cy, f) in n . P + c = 0, the plane's disparity at (x, y) is
  // d_g = -B n . (x - cx, y - cy, f) / c, linear along a row.
  const cv::Vec3d& n = plane.normal;
  const double k = -cam.baseline_m / plane.offset;
  for (int y = 0; y < disp.rows; ++y) {
    const float* row = disp.ptr<float>(y);
    uint8_t* out = mask.ptr<uint8_t>(y);
    const double row_part = n[1] * (y - cam.cy) + n[2] * cam.focal_px;
    for (int x = 0; x < disp.cols; ++x)
      if (row[x] > 0.0f && row[x] <= k * (n[0] * (x - cam.cx) + row_part) + margin_px)
        out[x] = 255;
  }
}

}  // namespace sg::vision
