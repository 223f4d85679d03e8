#include "sg/core/params.hpp"

#include <cmath>
#include <sstream>

#include "sg/core/checker.hpp"
#include "sg/core/error.hpp"

namespace sg::core {
namespace {

bool finite_positive(double v) { return std::isfinite(v) && v > 0; }

}  // namespace

const char* to_string(Mode m) {
  switch (m) {
    case Mode::kStereo: return "stereo";
    case Mode::kStereoFlow: return "stereo-flow";
    case Mode::kMotionParallax: return "motion-parallax";
    case Mode::kRelativeSize: return "relative-size";
    case Mode::kElevationMap: return "elevation-map";
    case Mode::kSceneFlowSeg: return "sceneflow-seg";
    case Mode::kLongSeq: return "longseq";
  }
  return "?";
}

std::vector<Mode> all_modes() {
  return {Mode::kStereo,       Mode::kStereoFlow,   Mode::kMotionParallax, Mode::kRelativeSize,
          Mode::kElevationMap, Mode::kSceneFlowSeg, Mode::kLongSeq};
}

Mode parse_mode(const std::string& text) {
  std::string names;
  for (Mode m : all_modes()) {
    if (text == to_string(m)) return m;
    names += std::string(names.empty() ? "" : ", ") + to_string(m);
  }
  throw InputError("detector=" + text + ": must be one of " + names);
}

Needs needs(Mode m) {
  switch (m) {
    case Mode::kStereoFlow: return {true, true, false};
    case Mode::kSceneFlowSeg: return {true, true, true};
    case Mode::kMotionParallax: return {false, true, false};
    case Mode::kRelativeSize: return {false, false, true};
    case Mode::kStereo:
    case Mode::kElevationMap:
    case Mode::kLongSeq: return {true, false, false};
  }
  return {};
}

bool is_surveyed(Mode m) { return m != Mode::kStereo && m != Mode::kStereoFlow; }

void select_detector(DetectorParams& p, Mode m) {
  p.mode = m;
  if (m == Mode::kLongSeq) p.bm.matcher = Matcher::kLongSeq;
}

const char* to_string(Matcher m) {
  switch (m) {
    case Matcher::kBm: return "bm";
    case Matcher::kSgbm: return "sgbm";
    case Matcher::kFast: return "fast";
    case Matcher::kLongSeq: return "longseq";
  }
  return "?";
}

Matcher parse_matcher(const std::string& text) {
  if (text == "bm") return Matcher::kBm;
  if (text == "sgbm") return Matcher::kSgbm;
  if (text == "fast") return Matcher::kFast;
  if (text == "longseq") return Matcher::kLongSeq;
  throw InputError("stereo.matcher=" + text + ": must be bm, sgbm, fast or longseq");
}

const char* to_string(MatchCost c) { return c == MatchCost::kSad ? "sad" : "census"; }

MatchCost parse_match_cost(const std::string& text) {
  if (text == "sad") return MatchCost::kSad;
  if (text == "census") return MatchCost::kCensus;
  throw InputError("stereo.cost=" + text + ": must be sad or census");
}

std::vector<std::string> validate(const BmParams& p) {
  std::vector<std::string> out;
  Checker c(out, "stereo");
  c.require(p.min_disparity >= 0, "min_disparity", p.min_disparity, "must be >= 0");
  c.require(p.num_disparities > 0 && p.num_disparities % 16 == 0, "num_disparities",
            p.num_disparities, "must be a positive multiple of 16");
  c.require(p.block_size % 2 == 1 && p.block_size >= 5 && p.block_size <= 255, "block_size",
            p.block_size, "must be odd and in 5..255");
  c.require(p.prefilter_cap >= 1 && p.prefilter_cap <= 63, "prefilter_cap", p.prefilter_cap,
            "must be in 1..63");
  c.require(p.texture_threshold >= 0, "texture_threshold", p.texture_threshold, "must be >= 0");
  c.require(p.uniqueness_ratio >= 0, "uniqueness_ratio", p.uniqueness_ratio, "must be >= 0");
  c.require(p.speckle_window >= 0, "speckle_window", p.speckle_window, "must be >= 0");
  c.require(p.speckle_range >= 0, "speckle_range", p.speckle_range, "must be >= 0");
  c.require(p.lr_max_diff >= -1, "lr_max_diff", p.lr_max_diff, "must be -1 (off) or >= 0");
  c.require(std::isfinite(p.periodic_ratio) && p.periodic_ratio >= 0 && p.periodic_ratio < 1,
            "periodic_ratio", p.periodic_ratio, "must be in [0, 1) (0: off)");
  if (p.matcher == Matcher::kLongSeq) {
    c.require(p.block_size <= 63, "block_size", p.block_size,
              "must be <= 63 with matcher longseq (its one-row window)");
    c.require(p.min_disparity == 0, "min_disparity", p.min_disparity,
              "must be 0 with matcher longseq");
    c.require(std::isfinite(p.longseq_cost_max) && p.longseq_cost_max >= 0 &&
                  p.longseq_cost_max <= 255,
              "longseq_cost_max", p.longseq_cost_max, "must be in 0..255 (grey levels)");
    c.require(std::isfinite(p.longseq_best_max) && p.longseq_best_max >= 0 &&
                  p.longseq_best_max <= p.longseq_cost_max,
              "longseq_best_max", p.longseq_best_max,
              "must be in 0..longseq_cost_max (grey levels)");
  }
  if (p.matcher == Matcher::kFast) {
    // The fast matcher sums block costs in 16-bit lanes: the largest block sum must fit.
    const int max_pixel_cost = p.cost == MatchCost::kSad ? 2 * p.prefilter_cap : 24;
    c.require(p.block_size * p.block_size * max_pixel_cost <= 65535, "block_size", p.block_size,
              "too large for the fast matcher (block_size^2 * max pixel cost must be <= 65535: "
              "block_size <= 31 with the default prefilter_cap, <= 51 with census)");
  }
  return out;
}

std::vector<std::string> validate(const Envelope& p) {
  std::vector<std::string> out;
  Checker c(out, "envelope");
  c.require(finite_positive(p.half_width_m), "half_width_m", p.half_width_m, "must be > 0");
  c.require(std::isfinite(p.y_top_m) && std::isfinite(p.y_bottom_m) && p.y_top_m < p.y_bottom_m,
            "y_top_m", p.y_top_m, "must be a number below y_bottom_m");
  c.require(finite_positive(p.z_contact_m), "z_contact_m", p.z_contact_m, "must be > 0");
  c.require(finite_positive(p.horizon_s), "horizon_s", p.horizon_s, "must be > 0");
  return out;
}

std::vector<std::string> validate(const StereoLabelParams& p) {
  std::vector<std::string> out;
  Checker c(out, "label");
  c.require(!p.gaps.empty(), "gaps", "[]", "must list at least one frame gap");
  for (int k : p.gaps) c.require(k >= 1 && k <= 60, "gaps", k, "each gap must be in 1..60");
  c.require(finite_positive(p.z_max_m), "z_max_m", p.z_max_m, "must be > 0");
  c.require(finite_positive(p.min_delta_d_px), "min_delta_d_px", p.min_delta_d_px, "must be > 0");
  c.require(p.max_growth == 0.0 || (std::isfinite(p.max_growth) && p.max_growth > 1.0),
            "max_growth", p.max_growth, "must be 0 (off) or > 1");
  return out;
}

std::vector<std::string> validate(const SignalParams& p) {
  std::vector<std::string> out;
  Checker c(out, "signal");
  c.require(p.open_size >= 1 && p.open_size % 2 == 1, "open_size", p.open_size,
            "must be odd and >= 1");
  c.require(p.min_area_px >= 1, "min_area_px", p.min_area_px, "must be >= 1");
  c.require(p.region_columns >= 1 && p.region_columns <= 16, "region_columns", p.region_columns,
            "must be in 1..16");
  c.require(p.region_min_px >= 1, "region_min_px", p.region_min_px, "must be >= 1");
  c.require(p.on_n >= 1, "on_n", p.on_n, "must be >= 1");
  c.require(p.on_k >= 1 && p.on_k <= p.on_n, "on_k", p.on_k, "must be in 1..on_n");
  c.require(p.off_m >= 1, "off_m", p.off_m, "must be >= 1");
  c.require(finite_positive(p.ttc_danger_s), "ttc_danger_s", p.ttc_danger_s, "must be > 0");
  c.require(std::isfinite(p.ttc_warning_s) && p.ttc_warning_s >= p.ttc_danger_s, "ttc_warning_s",
            p.ttc_warning_s, "must be >= ttc_danger_s");
  c.require(std::isfinite(p.track_min_overlap) && p.track_min_overlap > 0 &&
                p.track_min_overlap <= 1,
            "track_min_overlap", p.track_min_overlap, "must be in (0, 1]");
  c.require(finite_positive(p.ttc_fit_window_s), "ttc_fit_window_s", p.ttc_fit_window_s,
            "must be > 0");
  c.require(p.ttc_fit_min_frames >= 2, "ttc_fit_min_frames", p.ttc_fit_min_frames,
            "must be >= 2");
  c.require(std::isfinite(p.ttc_fit_min_span_s) && p.ttc_fit_min_span_s >= 0 &&
                p.ttc_fit_min_span_s <= p.ttc_fit_window_s,
            "ttc_fit_min_span_s", p.ttc_fit_min_span_s, "must be in [0, ttc_fit_window_s]");
  c.require(p.severity_off_frames >= 1, "severity_off_frames", p.severity_off_frames,
            "must be >= 1");
  c.require(p.confirm_frames >= 1, "confirm_frames", p.confirm_frames, "must be >= 1");
  return out;
}

const char* to_string(FlowMethod m) {
  switch (m) {
    case FlowMethod::kDisUltrafast:
      return "dis-ultrafast";
    case FlowMethod::kDisFast:
      return "dis-fast";
    case FlowMethod::kDisMedium:
      return "dis-medium";
    case FlowMethod::kFarneback:
      return "farneback";
  }
  return "?";
}

FlowMethod parse_flow_method(const std::string& text) {
  for (FlowMethod m : {FlowMethod::kDisUltrafast, FlowMethod::kDisFast, FlowMethod::kDisMedium,
                       FlowMethod::kFarneback})
    if (text == to_string(m)) return m;
  throw InputError("flow.method=" + text +
                   ": must be dis-ultrafast, dis-fast, dis-medium or farneback");
}

std::vector<std::string> validate(const FlowParams& p) {
  std::vector<std::string> out;
  Checker c(out, "flow");
  c.require(p.tile_halo_px >= 0, "tile_halo_px", p.tile_halo_px, "must be >= 0");
  if (p.method != FlowMethod::kFarneback) return out;
  c.require(std::isfinite(p.fb_pyr_scale) && p.fb_pyr_scale > 0 && p.fb_pyr_scale < 1,
            "fb_pyr_scale", p.fb_pyr_scale, "must be in (0, 1)");
  c.require(p.fb_levels >= 1, "fb_levels", p.fb_levels, "must be >= 1");
  c.require(p.fb_win_size >= 3, "fb_win_size", p.fb_win_size, "must be >= 3");
  c.require(p.fb_iterations >= 1, "fb_iterations", p.fb_iterations, "must be >= 1");
  c.require(p.fb_poly_n == 5 || p.fb_poly_n == 7, "fb_poly_n", p.fb_poly_n, "must be 5 or 7");
  c.require(finite_positive(p.fb_poly_sigma), "fb_poly_sigma", p.fb_poly_sigma, "must be > 0");
  return out;
}

std::vector<std::string> validate(const GroundParams& p) {
  std::vector<std::string> out;
  Checker c(out, "ground");
  c.require(std::isfinite(p.lower_fraction) && p.lower_fraction > 0 && p.lower_fraction <= 1,
            "lower_fraction", p.lower_fraction, "must be in (0, 1]");
  c.require(p.sample_step_px >= 1, "sample_step_px", p.sample_step_px, "must be >= 1");
  c.require(p.iterations >= 1, "iterations", p.iterations, "must be >= 1");
  c.require(finite_positive(p.tolerance_m), "tolerance_m", p.tolerance_m, "must be > 0");
  c.require(std::isfinite(p.side_margin_px) && p.side_margin_px >= 0, "side_margin_px",
            p.side_margin_px, "must be >= 0");
  c.require(finite_positive(p.z_max_m), "z_max_m", p.z_max_m, "must be > 0");
  c.require(p.min_inliers >= 3, "min_inliers", p.min_inliers, "must be >= 3");
  return out;
}

std::vector<std::string> validate(const SceneFlowParams& p) {
  std::vector<std::string> out;
  Checker c(out, "scene_flow");
  c.require(!p.gaps.empty(), "gaps", "[]", "must list at least one frame gap");
  for (int k : p.gaps) c.require(k >= 1 && k <= 60, "gaps", k, "each gap must be in 1..60");
  c.require(finite_positive(p.v_min_mps), "v_min_mps", p.v_min_mps, "must be > 0");
  c.require(finite_positive(p.z_max_m), "z_max_m", p.z_max_m, "must be > 0");
  c.require(std::isfinite(p.min_delta_d_px) && p.min_delta_d_px >= 0, "min_delta_d_px",
            p.min_delta_d_px, "must be >= 0");
  c.require(p.max_speed_mps > p.v_min_mps, "max_speed_mps", p.max_speed_mps,
            "must exceed v_min_mps");
  c.require(std::isfinite(p.startup_doubt_se) && p.startup_doubt_se >= 0, "startup_doubt_se",
            p.startup_doubt_se, "must be >= 0");
  c.require(std::isfinite(p.chain_outlier_px) && p.chain_outlier_px >= 0, "chain_outlier_px",
            p.chain_outlier_px, "must be >= 0 (0 disables)");
  c.require(std::isfinite(p.chain_outlier_fraction) && p.chain_outlier_fraction >= 0,
            "chain_outlier_fraction", p.chain_outlier_fraction, "must be >= 0");
  c.require(std::isfinite(p.surface_bridge_m) && p.surface_bridge_m >= 0 &&
                p.surface_bridge_m <= 5.0,
            "surface_bridge_m", p.surface_bridge_m, "must be in 0..5");
  c.require(p.max_disparity_step_px > 0, "max_disparity_step_px", p.max_disparity_step_px,
            "must be > 0 (infinity disables)");
  c.require(p.edge_margin_px >= 0 && p.edge_margin_px <= 50, "edge_margin_px", p.edge_margin_px,
            "must be in 0..50 (0 disables)");
  c.require(finite_positive(p.edge_step_px), "edge_step_px", p.edge_step_px, "must be > 0");
  c.require(p.chain_stride >= 1 && p.chain_stride <= 8, "chain_stride", p.chain_stride,
            "must be in 1..8 (1 follows every candidate)");
  c.require(finite_positive(p.chain_stride_z_m), "chain_stride_z_m", p.chain_stride_z_m,
            "must be > 0");
  if (p.exclude_ground) {
    std::vector<std::string> more = validate(p.ground);
    out.insert(out.end(), more.begin(), more.end());
  }
  return out;
}

std::vector<std::string> validate(const DetectorParams& p, const Camera& camera) {
  std::vector<std::string> out = validate(camera);
  auto append = [&out](std::vector<std::string> more) {
    out.insert(out.end(), more.begin(), more.end());
  };
  append(validate(p.bm));
  append(validate(p.envelope));
  append(validate(p.stereo));
  append(validate(p.signal));
  append(validate(p.flow));
  append(validate(p.scene_flow));
  append(validate(p.motion_parallax));
  append(validate(p.relative_size));
  append(validate(p.elevation));
  append(validate(p.sceneflow_seg));
  append(validate(p.proximity));
  if (p.mode == Mode::kLongSeq)
    Checker(out, "stereo").require(p.bm.matcher == Matcher::kLongSeq, "matcher",
                                   to_string(p.bm.matcher),
                                   "must be longseq with the longseq detector");
  if (p.mode == Mode::kLongSeq || p.mode == Mode::kElevationMap)
    Checker(out, "proximity").require(p.proximity.alarm_distance_m > p.envelope.z_contact_m,
                                      "alarm_distance_m", p.proximity.alarm_distance_m,
                                      "must exceed envelope.z_contact_m");
  Checker c(out, "stereo");
  c.require(p.bm.min_disparity + p.bm.num_disparities < camera.width, "num_disparities",
            p.bm.num_disparities, "min_disparity + num_disparities must be below the image width");
  c.require(p.bm.block_size < camera.height, "block_size", p.bm.block_size,
            "must be below the image height");
  return out;
}

}  // namespace sg::core
