#include "sg/core/source.hpp"

#include <memory>

namespace sg::core {

std::optional<PendingFrame> FrameSource::next_pending() {
  std::optional<StereoFrame> frame = next();
  if (!frame) return std::nullopt;
  PendingFrame pending;
  pending.index = frame->index;
  pending.time_s = frame->time_s;
  // std::function needs a copyable callable; the Mats inside share their pixels anyway.
  auto decoded = std::make_shared<StereoFrame>(std::move(*frame));
  pending.load = [decoded] { return *decoded; };
  return pending;
}

}  // namespace sg::core
