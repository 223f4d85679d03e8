#include "sg/core/camera.hpp"

#include <cmath>
#include <sstream>

namespace sg::core {
namespace {

template <typename T>
void require(std::vector<std::string>& out, bool ok, const char* field, T value, const char* rule) {
  if (ok) return;
  std::ostringstream s;
  s << "camera." << field << "=" << value << ": " << rule;
  out.push_back(s.str());
}

}  // namespace

std::vector<std::string> validate(const Camera& c) {
  std::vector<std::string> out;
  require(out, c.width > 0, "width", c.width, "must be positive");
  require(out, c.height > 0, "height", c.height, "must be positive");
  require(out, std::isfinite(c.focal_px) && c.focal_px > 0, "focal_px", c.focal_px,
          "must be a positive number");
  require(out, std::isfinite(c.baseline_m) && c.baseline_m > 0, "baseline_m", c.baseline_m,
          "must be a positive number");
  require(out, std::isfinite(c.cx), "cx", c.cx, "must be a number");
  require(out, std::isfinite(c.cy), "cy", c.cy, "must be a number");
  require(out, std::isfinite(c.fps) && c.fps > 0, "fps", c.fps, "must be a positive number");
  require(out, !(std::isfinite(c.fps) && c.fps > kMaxFps), "fps", c.fps, "is above any camera's frame rate (max 10000 Hz)");
  require(out, !(std::isfinite(c.focal_px) && c.focal_px > kMaxFocalPx), "focal_px", c.focal_px,
          "is above any real lens (max 1e5 px)");
  require(out, !(std::isfinite(c.baseline_m) && c.baseline_m > kMaxBaselineM), "baseline_m", c.baseline_m,
          "is above any real stereo rig (max 100 m)");
  return out;
}

}  // namespace sg::core
