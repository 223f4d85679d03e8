#pragma once
/// The YAML configuration file: mirrors the command-line flags (docs/usage.md, "The config file").
#include <filesystem>
#include <optional>
#include <string>

#include "sg/core/params.hpp"
#include "sg/io/source_factory.hpp"

namespace sg::io {

/// A `workers` or `tiles` value chosen from the cores (`auto`).
inline constexpr int kAuto = 0;

/// Parses a `workers` / `tiles` value: "auto" gives kAuto, a positive integer itself. Throws
/// core::InputError naming `what` for anything else.
int parse_count_or_auto(const std::string& text, const std::string& what);

/// Settings of a config file that are not detector parameters.
struct RunSettings {
  double pace_fps = 0.0;  ///< `fps:` pace the emitter, Hz (0 = as fast as possible)
  int workers = kAuto;    ///< `workers:` W, farm workers (`auto`: pipeline::auto_configuration)
  int tiles = kAuto;      ///< `tiles:` T, row tiles per task (`auto`: the same)
  int tokens = 0;         ///< `tokens:` frames in flight (0 = automatic)
  int threads = 0;        ///< `threads:` task-arena size (0 = all cores)
  /// `input:` section: left, right, sbs, sbs_camera, kitti, kitti_color, euroc, camera [I, J],
  /// calib, focal_px, baseline_m, cx, cy, fps (the rate of an input without one). Flags win.
  SourceSpec input;
  double scale = 1.0;     ///< `scale:` resize factor of the input images (run --scale)
  std::string csv;        ///< `csv:` per-frame metrics CSV file, empty = none (--csv)
  std::string dump;       ///< `dump:` folder of per-frame PNGs, empty = none (--dump)
  /// `platform:` preset name (core::apply_platform); read here, applied by the caller before the
  /// file's other keys (see config_platform).
  std::string platform;
};

/// The `platform:` key of a config file, if it has one (for applying the preset first). Throws
/// core::InputError like apply_config_file for a missing file or bad YAML.
std::optional<std::string> config_platform(const std::filesystem::path& path);

/// Overwrites the fields of `params` (and `settings`) that the file sets; others keep their value.
/// Sections: mode, fps, stereo, label, envelope, signal, flow, scene_flow (with scene_flow.ground)
/// (see docs/usage.md and docs/stereo-flow.md). Throws core::InputError
/// naming the file and the key for a missing file, bad YAML, an unknown key or a wrong type.
/// Does not validate the values: call core::validate afterwards.
void apply_config_file(const std::filesystem::path& path, core::DetectorParams& params,
                       RunSettings& settings);

}  // namespace sg::io
