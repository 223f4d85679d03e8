#pragma once
/// A source that loses frames on purpose, as a loaded camera link does: to show what the detector
/// does under drops (eval --drop-every).
#include "sg/core/source.hpp"

namespace sg::pipeline {

/// Forwards `inner` but skips every `every`-th frame (frames every-1, 2 every-1, ...: 1/every of
/// them; every = 5 drops 20 %). Skipped frames keep their place in the index and time stamps, so
/// the pipeline sees a gap, as after a paced drop. every <= 1 drops nothing.
class DroppingSource : public core::FrameSource {
 public:
  DroppingSource(core::FrameSource& inner, int every) : inner_(inner), every_(every) {}
  std::optional<core::StereoFrame> next() override;
  const core::Camera& camera() const override { return inner_.camera(); }
  int size() const override { return -1; }
  bool live() const override { return inner_.live(); }
  int dropped() const { return dropped_; }

 private:
  core::FrameSource& inner_;
  int every_;
  int read_ = 0, dropped_ = 0;
};

}  // namespace sg::pipeline
