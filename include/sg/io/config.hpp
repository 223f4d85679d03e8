#pragma once
/// The YAML configuration file: mirrors the command-line flags (README "Configuration").
#include <filesystem>

#include "sg/core/params.hpp"

namespace sg::io {

/// Settings of a config file that are not detector parameters.
struct RunSettings {
  double pace_fps = 0.0;  ///< `fps:` pace the emitter, Hz (0 = as fast as possible)
};

/// Overwrites the fields of `params` (and `settings`) that the file sets; others keep their value.
/// Sections: mode, fps, stereo, label, envelope, signal (see README). Throws core::InputError
/// naming the file and the key for a missing file, bad YAML, an unknown key or a wrong type.
/// Does not validate the values: call core::validate afterwards.
void apply_config_file(const std::filesystem::path& path, core::DetectorParams& params,
                       RunSettings& settings);

}  // namespace sg::io
