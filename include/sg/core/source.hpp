#pragma once
#include <optional>

#include "sg/core/camera.hpp"
#include "sg/core/frame.hpp"

namespace sg::core {

/// A stream of stereo frames (a folder, a video, a simulated scenario, a camera).
/// next() throws InputError when the input turns out to be broken mid-stream.
class FrameSource {
 public:
  virtual ~FrameSource() = default;
  /// The next frame, or nullopt at the end of the stream.
  virtual std::optional<StereoFrame> next() = 0;
  /// The calibrated camera of the stream (width/height filled in).
  virtual const Camera& camera() const = 0;
  /// Number of frames when known in advance, else -1.
  virtual int size() const { return -1; }
};

}  // namespace sg::core
