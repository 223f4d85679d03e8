#include "sg/core/detection.hpp"

namespace sg::core {

const char* to_string(Severity s) {
  switch (s) {
    case Severity::kNone: return "none";
    case Severity::kWarning: return "warning";
    case Severity::kDanger: return "danger";
  }
  return "?";
}

const char* to_string(Steering s) {
  switch (s) {
    case Steering::kStraight: return "straight";
    case Steering::kLeft: return "left";
    case Steering::kRight: return "right";
    case Steering::kStop: return "stop";
  }
  return "?";
}

}  // namespace sg::core
