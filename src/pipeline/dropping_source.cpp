#include "sg/pipeline/dropping_source.hpp"

namespace sg::pipeline {

std::optional<core::StereoFrame> DroppingSource::next() {
  std::optional<core::StereoFrame> frame = inner_.next();
  if (frame && every_ > 1 && ++read_ % every_ == 0) {
    ++dropped_;
    frame = inner_.next();
    ++read_;
  }
  return frame;
}

}  // namespace sg::pipeline
