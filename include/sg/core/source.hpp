#pragma once
#include <functional>
#include <optional>

#include "sg/core/camera.hpp"
#include "sg/core/frame.hpp"

namespace sg::core {

/// A frame the source has read and stamped, in stream order, but not yet decoded. The emitter
/// hands it on and `load` runs later, possibly on another thread and in parallel with the loads of
/// other frames: decoding, colour conversion, rectification and resizing belong there, so that one
/// core's serial decode does not cap the pipeline. `load` is called at most once; it must not touch
/// the source's mutable state, and it throws InputError when the frame turns out to be broken.
struct PendingFrame {
  int index = 0;        ///< 0-based frame number in the stream
  double time_s = 0.0;  ///< stream time of acquisition, s
  std::function<StereoFrame()> load;
  /// True when `load` runs in parallel itself (a renderer's rows): the emitter loads a frame it
  /// keeps at once, where one worker of the farm would run it alone, and never loads one it drops.
  bool load_where_read = false;
};

/// A stream of stereo frames (a folder, a video, a simulated scenario, a camera).
/// next() throws InputError when the input turns out to be broken mid-stream.
class FrameSource {
 public:
  virtual ~FrameSource() = default;
  /// The next frame, or nullopt at the end of the stream.
  virtual std::optional<StereoFrame> next() = 0;
  /// The next frame read but possibly not decoded, or nullopt at the end of the stream. The
  /// default decodes here (calls next()); a source whose frames decode independently overrides it
  /// to defer the work to PendingFrame::load. Use either next() or next_pending() on one source.
  virtual std::optional<PendingFrame> next_pending();
  /// The calibrated camera of the stream (width/height filled in).
  virtual const Camera& camera() const = 0;
  /// Number of frames when known in advance, else -1.
  virtual int size() const { return -1; }
  /// True for a live camera, which captures whether or not its frames are taken (a file can be
  /// read when the pipeline is ready).
  virtual bool live() const { return false; }
};

}  // namespace sg::core
