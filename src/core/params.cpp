#include "sg/core/params.hpp"

#include <cmath>
#include <sstream>

#include "sg/core/error.hpp"

namespace sg::core {
namespace {

/// Collects "<section>.<field>=<value>: <rule>" lines.
class Checker {
 public:
  Checker(std::vector<std::string>& out, const char* section) : out_(out), section_(section) {}
  template <typename T>
  void require(bool ok, const char* field, const T& value, const char* rule) {
    if (ok) return;
    std::ostringstream s;
    s << section_ << "." << field << "=" << value << ": " << rule;
    out_.push_back(s.str());
  }

 private:
  std::vector<std::string>& out_;
  const char* section_;
};

bool finite_positive(double v) { return std::isfinite(v) && v > 0; }

}  // namespace

const char* to_string(Mode m) { return m == Mode::kStereo ? "stereo" : "stereo-flow"; }

Mode parse_mode(const std::string& text) {
  if (text == "stereo") return Mode::kStereo;
  if (text == "stereo-flow") return Mode::kStereoFlow;
  throw InputError("mode=" + text + ": must be stereo or stereo-flow");
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
  Checker c(out, "stereo");
  c.require(p.bm.min_disparity + p.bm.num_disparities < camera.width, "num_disparities",
            p.bm.num_disparities, "min_disparity + num_disparities must be below the image width");
  c.require(p.bm.block_size < camera.height, "block_size", p.bm.block_size,
            "must be below the image height");
  return out;
}

}  // namespace sg::core
