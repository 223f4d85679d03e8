#pragma once
/// Options shared by the commands: input selection and detector parameters.
#include <CLI/CLI.hpp>
#include <memory>
#include <optional>
#include <string>

#include "sg/pipeline/setup.hpp"

namespace sg::apps {

// The setup itself lives in the pipeline layer (the Python module shares it).
using pipeline::camera_fit;
using pipeline::DetectorOptions;
using pipeline::input_platform;
using pipeline::InputOptions;
using pipeline::make_run_options;
using pipeline::open_input;
using pipeline::OpenedInput;

/// `left_right`: add --left/--right too (eval has its own for --flow and copies them over).
void add_input_options(CLI::App& app, InputOptions& options, bool left_right = true);
/// Only the real-input flags (--left/--right, --sbs, --kitti, --euroc, --camera, --calib, ...).
void add_source_options(CLI::App& app, InputOptions& options, bool left_right = true);
/// "WxH" as a size; InputError "<name>=<text>: must look like <example>" otherwise.
cv::Size parse_size(const std::string& text, const std::string& name, const std::string& example);

/// Detector flags (--config, --mode, --num-disparities, --block-size, --gaps, --fps, ...).
void add_detector_options(CLI::App& app, DetectorOptions& options);
/// A distance for a person to read: "0.47" below 10 m, "20" from there.
std::string format_metres(double m);

}  // namespace sg::apps
