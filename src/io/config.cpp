#include "sg/io/config.hpp"

#include <yaml-cpp/yaml.h>

#include <charconv>
#include <functional>
#include <map>
#include <optional>
#include <string>

#include "sg/core/error.hpp"
#include "sg/core/yaml_text.hpp"

namespace sg::io {
namespace {

/// Reads the keys of one YAML map into fields; unknown keys are errors.
class Section {
 public:
  Section(const YAML::Node& node, std::string where) : node_(node), where_(std::move(where)) {
    if (node_ && !node_.IsMap()) fail(where_, "must be a map");
  }
  template <typename T>
  Section& field(const char* key, T& out) {
    known_[key] = true;
    if (const YAML::Node v = node_[key]) {
      try {
        out = v.as<T>();
      } catch (const YAML::Exception&) {
        fail(where_ + "." + key, "has the wrong type");
      }
    }
    return *this;
  }
  Section& field(const char* key, std::optional<double>& out) {
    if (node_ && node_[key]) {
      double value = 0;
      field(key, value);
      out = value;
    }
    known_[key] = true;
    return *this;
  }
  /// Marks `key` as a sub-section read by its own Section.
  Section& section(const char* key) {
    known_[key] = true;
    return *this;
  }
  void done() const {
    if (!node_) return;
    for (const auto& kv : node_) {
      // A complex key ("? [a, b]") has no name (found by fuzz_config: YAML bad conversion).
      if (!kv.first.IsScalar()) fail(where_, "has a key that is not a name");
      const std::string key = kv.first.as<std::string>();
      if (!known_.count(key)) fail(where_ + "." + key, "is not a known setting");
    }
  }
  [[noreturn]] static void fail(const std::string& key, const std::string& rule) {
    throw core::InputError(key + " " + rule);
  }

 private:
  YAML::Node node_;
  std::string where_;
  std::map<std::string, bool> known_;
};

}  // namespace

int parse_count_or_auto(const std::string& text, const std::string& what) {
  if (text == "auto") return kAuto;
  int value = 0;
  const char* end = text.data() + text.size();
  const auto [at, error] = std::from_chars(text.data(), end, value);
  if (error != std::errc() || at != end || value < 1)
    throw core::InputError(what + " must be a positive integer or auto (got '" + text + "')");
  return value;
}

std::optional<std::string> config_platform(const std::filesystem::path& path) {
  core::DetectorParams ignored;
  RunSettings settings;
  apply_config_file(path, ignored, settings);
  if (settings.platform.empty()) return std::nullopt;
  return settings.platform;
}

void apply_config_file(const std::filesystem::path& path, core::DetectorParams& p,
                       RunSettings& settings) {
  const std::string file = path.string();
  if (!std::filesystem::is_regular_file(path)) {
    throw core::InputError("config file " + file + " does not exist");
  }
  const std::string text = core::read_yaml_text(path, "config file " + file);
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw core::InputError("config file " + file + ": " + e.what());
  }
  if (!root || root.IsNull()) return;
  try {
    if (!root.IsMap()) Section::fail("top level", "must be a map");
    std::string mode = core::to_string(p.mode);
    std::string workers, tiles;
    Section(root, "config")
        .field("mode", mode)
        .field("detector", mode)
        .field("fps", settings.pace_fps)
        .field("workers", workers)
        .field("tiles", tiles)
        .field("tokens", settings.tokens)
        .field("threads", settings.threads)
        .field("scale", settings.scale)
        .field("csv", settings.csv)
        .field("dump", settings.dump)
        .field("platform", settings.platform)
        .section("stereo")
        .section("label")
        .section("envelope")
        .section("signal")
        .section("flow")
        .section("scene_flow")
        .section("motion_parallax")
        .section("relative_size")
        .section("elevation")
        .section("sceneflow_seg")
        .section("proximity")
        .section("input")
        .done();
    if (!workers.empty()) settings.workers = parse_count_or_auto(workers, "config.workers");
    if (!tiles.empty()) settings.tiles = parse_count_or_auto(tiles, "config.tiles");
    core::select_detector(p, core::parse_mode(mode));
    std::string matcher = core::to_string(p.bm.matcher), cost = core::to_string(p.bm.cost);
    Section(root["stereo"], "stereo")
        .field("matcher", matcher)
        .field("cost", cost)
        .field("min_disparity", p.bm.min_disparity)
        .field("num_disparities", p.bm.num_disparities)
        .field("block_size", p.bm.block_size)
        .field("prefilter_cap", p.bm.prefilter_cap)
        .field("texture_threshold", p.bm.texture_threshold)
        .field("uniqueness_ratio", p.bm.uniqueness_ratio)
        .field("speckle_window", p.bm.speckle_window)
        .field("speckle_range", p.bm.speckle_range)
        .field("lr_max_diff", p.bm.lr_max_diff)
        .field("left_band", p.bm.left_band)
        .field("coarse_fill", p.bm.coarse_fill)
        .field("periodic_ratio", p.bm.periodic_ratio)
        .field("longseq_cost_max", p.bm.longseq_cost_max)
        .field("longseq_best_max", p.bm.longseq_best_max)
        .field("longseq_both_ways", p.bm.longseq_both_ways)
        .done();
    p.bm.matcher = core::parse_matcher(matcher);
    p.bm.cost = core::parse_match_cost(cost);
    Section(root["label"], "label")
        .field("gaps", p.stereo.gaps)
        .field("z_max_m", p.stereo.z_max_m)
        .field("min_delta_d_px", p.stereo.min_delta_d_px)
        .field("max_growth", p.stereo.max_growth)
        .field("use_envelope_band", p.stereo.use_envelope_band)
        .done();
    Section(root["envelope"], "envelope")
        .field("half_width_m", p.envelope.half_width_m)
        .field("y_top_m", p.envelope.y_top_m)
        .field("y_bottom_m", p.envelope.y_bottom_m)
        .field("z_contact_m", p.envelope.z_contact_m)
        .field("horizon_s", p.envelope.horizon_s)
        .done();
    Section(root["signal"], "signal")
        .field("open_size", p.signal.open_size)
        .field("min_area_px", p.signal.min_area_px)
        .field("region_columns", p.signal.region_columns)
        .field("region_min_px", p.signal.region_min_px)
        .field("on_k", p.signal.on_k)
        .field("on_n", p.signal.on_n)
        .field("off_m", p.signal.off_m)
        .field("ttc_danger_s", p.signal.ttc_danger_s)
        .field("ttc_warning_s", p.signal.ttc_warning_s)
        .field("track_min_overlap", p.signal.track_min_overlap)
        .field("ttc_fit_window_s", p.signal.ttc_fit_window_s)
        .field("ttc_fit_min_frames", p.signal.ttc_fit_min_frames)
        .field("ttc_fit_min_span_s", p.signal.ttc_fit_min_span_s)
        .field("coast_near_range", p.signal.coast_near_range)
        .field("severity_off_frames", p.signal.severity_off_frames)
        .field("confirm_frames", p.signal.confirm_frames)
        .done();
    std::string method = core::to_string(p.flow.method);
    Section(root["flow"], "flow")
        .field("method", method)
        .field("tile_halo_px", p.flow.tile_halo_px)
        .field("fb_pyr_scale", p.flow.fb_pyr_scale)
        .field("fb_levels", p.flow.fb_levels)
        .field("fb_win_size", p.flow.fb_win_size)
        .field("fb_iterations", p.flow.fb_iterations)
        .field("fb_poly_n", p.flow.fb_poly_n)
        .field("fb_poly_sigma", p.flow.fb_poly_sigma)
        .done();
    p.flow.method = core::parse_flow_method(method);
    YAML::Node scene_flow = root["scene_flow"];
    Section(scene_flow, "scene_flow")
        .field("gaps", p.scene_flow.gaps)
        .field("v_min_mps", p.scene_flow.v_min_mps)
        .field("z_max_m", p.scene_flow.z_max_m)
        .field("min_delta_d_px", p.scene_flow.min_delta_d_px)
        .field("max_speed_mps", p.scene_flow.max_speed_mps)
        .field("chain_outlier_px", p.scene_flow.chain_outlier_px)
        .field("chain_outlier_fraction", p.scene_flow.chain_outlier_fraction)
        .field("startup_doubt_se", p.scene_flow.startup_doubt_se)
        .field("max_disparity_step_px", p.scene_flow.max_disparity_step_px)
        .field("edge_margin_px", p.scene_flow.edge_margin_px)
        .field("edge_step_px", p.scene_flow.edge_step_px)
        .field("keep_thin_structures", p.scene_flow.keep_thin_structures)
        .field("pool_surface_motion", p.scene_flow.pool_surface_motion)
        .field("surface_bridge_m", p.scene_flow.surface_bridge_m)
        .field("chain_stride", p.scene_flow.chain_stride)
        .field("chain_stride_z_m", p.scene_flow.chain_stride_z_m)
        .field("grow_into_edges", p.scene_flow.grow_into_edges)
        .field("compensate_rotation", p.scene_flow.compensate_rotation)
        .field("predict_turn", p.scene_flow.predict_turn)
        .field("longest_gap_decides", p.scene_flow.longest_gap_decides)
        .field("fit_velocity", p.scene_flow.fit_velocity)
        .field("use_envelope_band", p.scene_flow.use_envelope_band)
        .field("exclude_ground", p.scene_flow.exclude_ground)
        .section("ground")
        .done();
    if (scene_flow && scene_flow.IsMap()) {
      Section(scene_flow["ground"], "scene_flow.ground")
          .field("lower_fraction", p.scene_flow.ground.lower_fraction)
          .field("sample_step_px", p.scene_flow.ground.sample_step_px)
          .field("iterations", p.scene_flow.ground.iterations)
          .field("tolerance_m", p.scene_flow.ground.tolerance_m)
          .field("z_max_m", p.scene_flow.ground.z_max_m)
          .field("min_inliers", p.scene_flow.ground.min_inliers)
          .field("split_surfaces", p.scene_flow.ground.split_surfaces)
          .field("side_margin_px", p.scene_flow.ground.side_margin_px)
          .done();
    }
    Section(root["motion_parallax"], "motion_parallax")
        .field("smooth_px", p.motion_parallax.smooth_px)
        .field("flow_min_px_s", p.motion_parallax.flow_min_px_s)
        .done();
    core::RelativeSizeParams& rs = p.relative_size;
    Section(root["relative_size"], "relative_size")
        .field("max_features", rs.max_features)
        .field("ratio_test", rs.ratio_test)
        .field("template_px", rs.template_px)
        .field("patch_factor", rs.patch_factor)
        .field("scale_max", rs.scale_max)
        .field("scale_step", rs.scale_step)
        .field("s_min", rs.s_min)
        .field("max_error", rs.max_error)
        .field("cluster_radius_px", rs.cluster_radius_px)
        .field("cluster_min", rs.cluster_min)
        .field("gap_frames", rs.gap_frames)
        .done();
    core::ElevationParams& el = p.elevation;
    Section(root["elevation"], "elevation")
        .field("sample_step_px", el.sample_step_px)
        .field("fit_z_min_m", el.fit_z_min_m)
        .field("fit_z_max_m", el.fit_z_max_m)
        .field("fit_y_min_m", el.fit_y_min_m)
        .field("iterations", el.iterations)
        .field("tolerance_m", el.tolerance_m)
        .field("min_inliers", el.min_inliers)
        .field("seed", el.seed)
        .field("cell_m", el.cell_m)
        .field("half_width_m", el.half_width_m)
        .field("z_max_m", el.z_max_m)
        .field("height_min_m", el.height_min_m)
        .field("density_ratio", el.density_ratio)
        .field("min_points", el.min_points)
        .done();
    core::SceneFlowSegParams& sg = p.sceneflow_seg;
    Section(root["sceneflow_seg"], "sceneflow_seg")
        .field("sigma_disparity_px", sg.sigma_disparity_px)
        .field("sigma_flow_px", sg.sigma_flow_px)
        .field("sigma_change_px", sg.sigma_change_px)
        .field("xi_static", sg.xi_static)
        .field("lambda", sg.lambda)
        .field("contrast_a", sg.contrast_a)
        .field("grid_step_px", sg.grid_step_px)
        .field("v_min_mps", sg.v_min_mps)
        .done();
    Section(root["proximity"], "proximity")
        .field("alarm_distance_m", p.proximity.alarm_distance_m)
        .done();
    io::SourceSpec& in = settings.input;
    Section(root["input"], "input")
        .field("left", in.left)
        .field("right", in.right)
        .field("sbs", in.sbs)
        .field("sbs_camera", in.sbs_camera)
        .field("kitti", in.kitti)
        .field("kitti_color", in.kitti_color)
        .field("euroc", in.euroc)
        .field("camera", in.camera)
        .field("calib", in.calib)
        .field("focal_px", in.focal_px)
        .field("baseline_m", in.baseline_m)
        .field("cx", in.cx)
        .field("cy", in.cy)
        .field("fps", in.input_fps)
        .done();
  } catch (const core::InputError& e) {
    throw core::InputError("config file " + file + ": " + e.what());
  }
}

}  // namespace sg::io
