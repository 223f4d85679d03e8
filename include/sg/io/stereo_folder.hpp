#pragma once
/// The stereo folder (docs/inputs.md, "The stereo folder"):
///   DIR/camera.yaml   focal_px, baseline_m, cx, cy, fps (required numbers); width/height may be
///                     present but are informational: readers take them from the images.
///   DIR/left/*.png, DIR/right/*.png   sorted by file name; only .png files count; equal counts and
///                     sizes; gray or colour, 8- or 16-bit (converted to 8-bit gray, 16-bit / 257).
///   DIR/gt/ (optional ground truth, frame files named frame_file_name(i, ...) = NNNNNN):
///     frames.jsonl    one line per frame: {"frame":i,"alarm":bool,"obstacles":[{"id":k,
///                     "colliding":bool,"ttc_s":x or null,"pixels":n}]}
///     disp/NNNNNN.png   16-bit, disparity * 256, 0 = unknown (KITTI)
///     flow/NNNNNN.flo   Middlebury .flo, backward flow (i -> i-1); absent for frame 0
///     danger/NNNNNN.png 8-bit, 255 = dangerous pixel
///     ids/NNNNNN.png    16-bit object id, 0 = background
/// Frame i has time_s = i / fps.
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "sg/core/camera.hpp"
#include "sg/core/ground_truth.hpp"
#include "sg/core/source.hpp"

namespace sg::io {

/// Reads camera.yaml (focal_px, baseline_m, cx, cy, fps). width/height are left as given in
/// `size` (taken from the images). Throws core::InputError naming the file and the field.
core::Camera read_camera_yaml(const std::filesystem::path& path, cv::Size size);
void write_camera_yaml(const std::filesystem::path& path, const core::Camera& camera);

/// Reads a stereo folder lazily. The constructor checks the layout (folder, camera.yaml, equal
/// left/right counts, at least one frame, first pair readable and of equal size); next() checks each
/// pair (decodable, same size as the first). gt/frames.jsonl, when present, is parsed by the
/// constructor (a malformed line names "frames.jsonl:<line>"). Every problem is a core::InputError
/// naming the file. A frame whose files are broken throws from next() only when it is reached; the
/// stream has then moved past it.
class FolderSource : public core::FrameSource {
 public:
  explicit FolderSource(const std::filesystem::path& dir);
  std::optional<core::StereoFrame> next() override;
  /// The pair's files are decoded (imread, gray conversion, size check) in PendingFrame::load,
  /// which may run on another thread; a broken pair throws from load.
  std::optional<core::PendingFrame> next_pending() override;
  const core::Camera& camera() const override { return camera_; }
  int size() const override { return static_cast<int>(left_.size()); }

  bool has_truth() const;
  /// gt/frames.jsonl entry of frame i; throws InputError when absent or malformed.
  const core::FrameTruth& truth(int index) const;
  /// gt maps of frame i that exist on disk (others left empty).
  core::TruthMaps truth_maps(int index) const;

 private:
  std::filesystem::path dir_;
  core::Camera camera_;
  std::vector<std::filesystem::path> left_, right_;
  std::vector<core::FrameTruth> truth_;  ///< gt/frames.jsonl lines in file order
  bool has_truth_ = false;               ///< gt/frames.jsonl exists
  int next_index_ = 0;
};

/// Writes a stereo folder frame by frame (used by `simulate`). Files are written as frames arrive;
/// gt/frames.jsonl gets one complete, flushed line per frame. Frame files are numbered by arrival
/// order (0, 1, ...). Truth and maps are written only when the writer was made `with_truth`; a map
/// left empty in `maps` is not written (so frame 0 has no flow). Throws core::InputError when a
/// folder or file cannot be created.
class FolderWriter {
 public:
  FolderWriter(const std::filesystem::path& dir, const core::Camera& camera, bool with_truth);
  void write(const core::StereoFrame& frame, const core::FrameTruth* truth = nullptr,
             const core::TruthMaps* maps = nullptr);
  int frames_written() const { return frames_; }

 private:
  std::filesystem::path dir_;
  bool with_truth_;
  std::ofstream truth_out_;  ///< gt/frames.jsonl, open when with_truth_
  int frames_ = 0;
};

/// File name of frame i in a stereo folder: zero-padded to 6 digits + extension (".png"),
/// e.g. frame_file_name(12, ".flo") == "000012.flo".
std::string frame_file_name(int index, const char* extension);

/// Parses one gt/frames.jsonl line; throws InputError naming `where` when malformed.
core::FrameTruth parse_truth_line(const std::string& line, const std::string& where);
std::string truth_to_json_line(const core::FrameTruth& truth);

}  // namespace sg::io
