#include "sg/io/source_factory.hpp"

#include <cmath>
#include <filesystem>
#include <iostream>

#include "sg/core/error.hpp"
#include "sg/io/calibration.hpp"
#include "sg/io/sources.hpp"

namespace sg::io {
namespace fs = std::filesystem;
namespace {

constexpr double kAssumedFps = 30.0;

enum class PathKind { kVideo, kImageList };

PathKind kind_of(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec) || path.find_first_of("*?[") != std::string::npos) {
    return PathKind::kImageList;
  }
  if (fs::is_regular_file(path, ec)) return PathKind::kVideo;
  throw core::InputError("not found: " + path +
                         " (expected a video, an image folder or a glob pattern)");
}

/// The camera of an input, before its source knows the image size.
struct CameraPlan {
  core::Camera camera;                      ///< rectified camera (cx, cy NaN = image centre)
  std::optional<StereoCalibration> stereo;  ///< raw calibration: rectify after reading
  bool fps_known = false;
};

CameraPlan plan_camera(const SourceSpec& spec) {
  CameraPlan plan;
  plan.camera.cx = plan.camera.cy = std::nan("");
  Calibration calib;
  if (!spec.calib.empty()) calib = read_calibration(spec.calib, spec.kitti_color);
  const bool flags = spec.focal_px || spec.baseline_m || spec.cx || spec.cy;
  if (calib.stereo) {
    if (flags) {
      throw core::InputError("--focal/--baseline/--cx/--cy describe a rectified camera; " +
                             spec.calib + " is a raw calibration that gives them after rectifying");
    }
    plan.stereo = calib.stereo;
    plan.camera.focal_px = calib.stereo->M1.at<double>(0, 0);
    return plan;
  }
  if (calib.rectified) {
    plan.camera = *calib.rectified;
    plan.fps_known = plan.camera.fps > 0;
  } else if (!(spec.focal_px && spec.baseline_m)) {
    throw core::InputError(
        "no calibration for " + spec.name() +
        ": give --calib FILE (OpenCV stereo calibration, KITTI calib_cam_to_cam.txt or "
        "camera.yaml) or, for rectified input, --focal PX --baseline M [--cx PX --cy PX]");
  }
  if (spec.focal_px) plan.camera.focal_px = *spec.focal_px;
  if (spec.baseline_m) plan.camera.baseline_m = *spec.baseline_m;
  for (const auto& [flag, value] : {std::pair{"--cx", spec.cx}, {"--cy", spec.cy}}) {
    if (value && !std::isfinite(*value)) {
      throw core::InputError(std::string(flag) + "=" + std::to_string(*value) +
                             ": must be a number");
    }
  }
  if (spec.cx) plan.camera.cx = *spec.cx;
  if (spec.cy) plan.camera.cy = *spec.cy;
  return plan;
}

/// Sets the frame rate of a stream without timestamps: --input-fps, else the calibration's, else
/// an assumed 30 Hz. Returns true when assumed (the caller warns once the input has opened).
bool set_nominal_fps(CameraPlan& plan, const SourceSpec& spec) {
  if (spec.input_fps) {
    plan.camera.fps = *spec.input_fps;
  } else if (!plan.fps_known) {
    plan.camera.fps = kAssumedFps;
    return true;
  }
  return false;
}

/// The sources take the camera as planned; a principal point left open becomes the image centre
/// once the size is known, and a raw stream is wrapped in the rectifying decorator.
std::unique_ptr<core::FrameSource> finish(std::unique_ptr<core::FrameSource> source,
                                          const CameraPlan& plan, const SourceSpec& spec) {
  if (plan.stereo) {
    return std::make_unique<RectifiedSource>(std::move(source), *plan.stereo, spec.calib);
  }
  return source;
}

}  // namespace

bool SourceSpec::any() const {
  return !left.empty() || !right.empty() || !sbs.empty() || sbs_camera || !kitti.empty() ||
         !euroc.empty() || !camera.empty();
}

std::string SourceSpec::name() const {
  if (!euroc.empty()) return "euroc " + euroc;
  if (!kitti.empty()) return "kitti " + kitti;
  if (!camera.empty()) {
    std::string s = "camera " + std::to_string(camera[0]);
    if (camera.size() > 1) s += "," + std::to_string(camera[1]);
    return sbs_camera ? s + " (side by side)" : s;
  }
  if (!sbs.empty()) return sbs;
  return left + " + " + right;
}

std::unique_ptr<core::FrameSource> open_source(const SourceSpec& spec) {
  const int kinds = (!spec.left.empty() || !spec.right.empty()) + !spec.kitti.empty() +
                    !spec.euroc.empty() + !spec.camera.empty() +
                    (!spec.sbs.empty() && spec.camera.empty());
  if (kinds != 1) {
    throw core::InputError(kinds == 0 ? "no input given"
                                      : "give one input: --left/--right, --sbs, --kitti, --euroc "
                                        "or --camera");
  }
  if (!spec.euroc.empty()) {
    if (!spec.calib.empty() || spec.focal_px || spec.baseline_m) {
      throw core::InputError(
          "--euroc takes its calibration from cam0/cam1 sensor.yaml; drop "
          "--calib/--focal/--baseline");
    }
    return open_euroc(spec.euroc);
  }
  if (!spec.kitti.empty()) {
    if (spec.focal_px || spec.baseline_m || spec.cx || spec.cy) {
      throw core::InputError(
          "--kitti takes its camera from calib_cam_to_cam.txt; drop --focal/"
          "--baseline/--cx/--cy (or give another file with --calib)");
    }
    return open_kitti(spec.kitti, spec.kitti_color, spec.calib);
  }
  CameraPlan plan = plan_camera(spec);
  std::unique_ptr<core::FrameSource> source;
  bool fps_assumed = false;
  if (!spec.camera.empty()) {
    if (spec.camera.size() > 2 || (spec.camera.size() == 1) != spec.sbs_camera) {
      throw core::InputError("--camera takes two indices I,J, or one index with --sbs");
    }
    plan.camera.fps = kAssumedFps;  // replaced by the device's rate when it reports one
    source = CaptureSource::open_cameras(spec.camera[0],
                                         spec.camera.size() > 1 ? spec.camera[1] : -1, plan.camera);
  } else if (!spec.sbs.empty()) {
    plan.camera.fps = spec.input_fps.value_or(plan.fps_known ? plan.camera.fps : kAssumedFps);
    source = CaptureSource::open_sbs_video(spec.sbs, plan.camera);
  } else {
    if (spec.left.empty() || spec.right.empty()) {
      throw core::InputError("--left and --right go together");
    }
    const PathKind left = kind_of(spec.left), right = kind_of(spec.right);
    if (left != right) {
      throw core::InputError("--left " + spec.left + " and --right " + spec.right +
                             " are not the same kind of input (videos, folders or globs)");
    }
    if (left == PathKind::kVideo) {
      plan.camera.fps = spec.input_fps.value_or(plan.fps_known ? plan.camera.fps : kAssumedFps);
      source = CaptureSource::open_videos(spec.left, spec.right, plan.camera);
    } else {
      fps_assumed = set_nominal_fps(plan, spec);
      const auto l = list_images(spec.left), r = list_images(spec.right);
      const size_t n = shorter_count(l.size(), r.size(), spec.left, spec.right);
      std::vector<ImagePair> pairs(n);
      for (size_t i = 0; i < n; ++i) pairs[i] = {l[i], r[i], i / plan.camera.fps};
      source = std::make_unique<ImageListSource>(std::move(pairs), plan.camera);
    }
  }
  source = finish(std::move(source), plan, spec);
  core::throw_if_invalid(core::validate(source->camera()), "invalid camera for " + spec.name());
  if (fps_assumed) {
    std::cerr << "stereoguard: warning: " << spec.name() << " states no frame rate; assuming "
              << kAssumedFps << " Hz (give --input-fps)\n";
  }
  return source;
}

}  // namespace sg::io
