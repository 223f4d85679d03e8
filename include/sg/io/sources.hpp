#pragma once
/// Frame sources for real inputs (docs/inputs.md): image pairs (two folders, two glob patterns,
/// KITTI raw, EuRoC), videos and V4L2 cameras (two, or one side-by-side), and the rectifying
/// decorator that wraps any of them.
///
/// Every source here gives the same frames through next() as through next_pending() + load():
/// next() is next_pending() followed by load().
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <opencv2/videoio.hpp>
#include <string>
#include <vector>

#include "sg/core/source.hpp"
#include "sg/io/calibration.hpp"

namespace sg::io {

/// A source whose next() is next_pending() + load(), so both ways give the same frames.
class DeferredSource : public core::FrameSource {
 public:
  std::optional<core::StereoFrame> next() final;
};

/// One stereo pair of image files and its acquisition time.
struct ImagePair {
  std::filesystem::path left, right;
  double time_s = 0.0;  ///< stream time, s (0 for the first frame)
};

/// Image pairs read lazily. The constructor reads the first pair (so an unreadable file or left and
/// right sizes that differ fail at once) and sets camera().width/height from it. next_pending()
/// defers imread + gray conversion to load(), which checks that the frame has the first frame's
/// size (InputError naming the file otherwise).
class ImageListSource : public DeferredSource {
 public:
  /// `camera`: focal, baseline, cx, cy, fps of the stream (width/height are overwritten).
  ImageListSource(std::vector<ImagePair> pairs, const core::Camera& camera);
  std::optional<core::PendingFrame> next_pending() override;
  const core::Camera& camera() const override { return camera_; }
  int size() const override { return static_cast<int>(pairs_.size()); }

 private:
  std::vector<ImagePair> pairs_;
  core::Camera camera_;
  int next_index_ = 0;
};

/// Videos and cameras through cv::VideoCapture: two captures (left, right), or one side-by-side
/// capture whose left half is the left image. Frames are grabbed and decoded serially in
/// next_pending(); gray conversion and the split happen in load(). Recorded videos are stamped
/// index / fps (the container's nominal rate); cameras by the clock at the grab, paced by the
/// camera. When one of two videos ends before the other the stream stops at the shorter, with one
/// warning line on stderr. A video that ends well before the frame count its container states
/// (truncated) or stops decoding is an InputError.
///
/// Cameras are live (DESIGN section 1): the camera paces the stream, and a frame that waited in
/// the driver's queue while the pipeline had no free token is dropped in favour of the newest one
/// (LiveFrameClock). Frame indices count camera frames from the capture stamps, so every frame
/// lost, whether here or by the driver, is a gap in them (the pipeline counts it as dropped). A
/// camera that stops giving images is an InputError after a few seconds, not a hang.
/// The frame policy of a live camera at `fps` (pure, for testing): which camera frame a capture
/// stamp is, and whether a grabbed frame is stale (its successor has been captured already).
class LiveFrameClock {
 public:
  explicit LiveFrameClock(double fps = 30.0) : period_s_(1.0 / fps) {}
  /// Camera frame number of a frame captured at `stamp_s` (the first call is frame 0): the
  /// rounded number of periods since the first stamp, and always above the previous result (a
  /// jittery stamp never repeats or reverses an index).
  int index_of(double stamp_s);
  /// True when a frame captured at `stamp_s` is stale at `now_s`: one period or more has passed,
  /// so the camera has captured a newer frame, which waits in the driver's queue.
  bool stale(double stamp_s, double now_s) const { return now_s - stamp_s >= period_s_; }
  /// Capture stamp of the first frame, s.
  double first_stamp() const { return first_; }

 private:
  double period_s_;
  double first_ = 0.0;
  int last_ = -1;
};

class CaptureSource : public DeferredSource {
 public:
  /// Two video files. `camera` gives focal, baseline, cx, cy, and fps when the videos have none.
  static std::unique_ptr<CaptureSource> open_videos(const std::string& left,
                                                    const std::string& right,
                                                    const core::Camera& camera);
  /// One side-by-side video file (even width).
  static std::unique_ptr<CaptureSource> open_sbs_video(const std::string& path,
                                                       const core::Camera& camera);
  /// V4L2 devices /dev/video<left>, /dev/video<right>; right < 0 = one side-by-side device.
  /// A device that does not exist or does not open is an InputError at once.
  static std::unique_ptr<CaptureSource> open_cameras(int left, int right,
                                                     const core::Camera& camera);

  std::optional<core::PendingFrame> next_pending() override;
  const core::Camera& camera() const override { return camera_; }
  int size() const override { return frame_count_; }
  bool live() const override { return live_; }

 private:
  struct Capture {
    std::string name;  ///< file path or /dev/videoN, for messages
    cv::VideoCapture capture;
    int declared_frames = -1;  ///< the container's frame count, -1 unknown
  };
  CaptureSource(std::vector<Capture> captures, bool live, const core::Camera& camera);
  /// Reads one frame of every capture; false at the end of the stream.
  bool grab(std::vector<cv::Mat>& frames);
  /// Live: grabs the newest frame of every camera (dropping queued stale ones) and decodes it;
  /// returns its capture stamp, s on the steady clock.
  double grab_newest(std::vector<cv::Mat>& frames);

  std::vector<Capture> captures_;
  bool live_;
  core::Camera camera_;
  int frame_count_ = -1;
  int next_index_ = 0;
  std::vector<cv::Mat> first_;  ///< the first frame, read by the constructor to learn the size
  double first_stamp_s_ = 0.0;  ///< live: capture stamp of first_
  LiveFrameClock clock_;        ///< live only
};

/// Decorator: rectifies the frames of `inner` with maps computed once from a raw calibration.
/// load() chains the inner load() then remaps (bilinear). camera() is the rectified camera with the
/// inner source's fps.
class RectifiedSource : public DeferredSource {
 public:
  RectifiedSource(std::unique_ptr<core::FrameSource> inner, const StereoCalibration& calib,
                  const std::string& where);
  std::optional<core::PendingFrame> next_pending() override;
  const core::Camera& camera() const override { return rectification_->camera; }
  int size() const override { return inner_->size(); }

 private:
  std::unique_ptr<core::FrameSource> inner_;
  std::shared_ptr<const Rectification> rectification_;
};

/// Rectifies one pair with `r` (what RectifiedSource::load does).
void rectify(const Rectification& r, core::StereoFrame& frame);

/// Images of a folder (png, jpg, jpeg, bmp, pgm, ppm, tif, tiff), or the files matching a glob
/// pattern (`dir/left*.jpg`), sorted by name. Throws InputError when the folder or pattern gives no
/// image.
std::vector<std::filesystem::path> list_images(const std::string& folder_or_glob);

/// Sets cx, cy to the image centre ((width - 1) / 2, (height - 1) / 2) where they are NaN (not
/// given); ImageListSource and CaptureSource call it once they know the size.
void centre_unknown_principal_point(core::Camera& camera);

/// min(left, right); when they differ, prints one line "stereoguard: warning: ..." on stderr
/// naming both (a stream stops at the shorter side).
size_t shorter_count(size_t left, size_t right, const std::string& left_name,
                     const std::string& right_name);

/// Frame rate from acquisition times: 1 / median interval, Hz; 0 when fewer than 2 times or the
/// median is not positive.
double fps_from_times(const std::vector<double>& times_s);

/// KITTI raw timestamps.txt: one "YYYY-MM-DD hh:mm:ss.fffffffff" a line (blank lines skipped),
/// as seconds since the whole second of the first line. Throws InputError naming the file and line
/// when a line is not such a timestamp (a field out of range included: month 13, minute
/// 74327100, ...).
std::vector<double> read_kitti_times(const std::filesystem::path& path);

/// EuRoC CAM_DIR/data.csv: "timestamp_ns,file name" lines ('#' comments and blank lines skipped)
/// as timestamp -> CAM_DIR/data/<file name>. Throws InputError naming the file and line when a
/// line is malformed or its timestamp is negative or out of range.
std::map<std::int64_t, std::filesystem::path> read_euroc_csv(const std::filesystem::path& cam_dir);

/// KITTI raw drive: DIR/image_00/data/*.png + image_01 (or image_02/03 when `color`),
/// DIR/image_0X/timestamps.txt ("YYYY-MM-DD hh:mm:ss.fffffffff", optional: else `camera.fps`),
/// calibration from `calib` (default: calib_cam_to_cam.txt in DIR or in its parent, as KITTI
/// unpacks it). The images are taken as rectified (the synced+rectified product).
std::unique_ptr<core::FrameSource> open_kitti(const std::filesystem::path& dir, bool color,
                                              const std::filesystem::path& calib);

/// EuRoC MAV folder (the mav0 folder, or its parent): cam0 (left), cam1 (right), each with
/// data.csv (timestamp ns, file name), data/ and sensor.yaml. Left and right are paired by equal
/// timestamps (frames without a partner are skipped); rectified with the sensor.yaml pair.
std::unique_ptr<core::FrameSource> open_euroc(const std::filesystem::path& dir);

}  // namespace sg::io
