#pragma once
/// A source of frames held in memory (benchmarks, tests): reading costs nothing.
#include <vector>

#include "sg/core/source.hpp"

namespace sg::io {

class MemorySource : public core::FrameSource {
 public:
  /// `frames` must outlive the source; next() hands out shallow copies (shared pixels).
  MemorySource(const std::vector<core::StereoFrame>& frames, const core::Camera& camera)
      : frames_(frames), camera_(camera) {}
  std::optional<core::StereoFrame> next() override {
    if (next_ >= frames_.size()) return std::nullopt;
    return frames_[next_++];
  }
  const core::Camera& camera() const override { return camera_; }
  int size() const override { return static_cast<int>(frames_.size()); }

 private:
  const std::vector<core::StereoFrame>& frames_;
  core::Camera camera_;
  size_t next_ = 0;
};

}  // namespace sg::io
