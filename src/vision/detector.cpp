#include "sg/vision/detector.hpp"

#include <algorithm>

#include "sg/core/error.hpp"
#include "sg/vision/labelling.hpp"
#include "sg/vision/stereo_bm.hpp"

namespace sg::vision {

Detector::Detector(const core::DetectorParams& params, const core::Camera& camera)
    : params_(params), camera_(camera), hysteresis_(params.signal) {
  if (params_.mode == core::Mode::kStereoFlow)
    throw core::InputError("stereo-flow mode is not implemented yet");
}

core::Detection Detector::process(const core::StereoFrame& frame, const FrameMaps& maps) {
  const cv::Mat& disp = maps.disparity;
  if (disp.empty() || disp.type() != CV_32FC1)
    throw core::InputError("detector: the disparity map must be a non-empty CV_32F image");
  if (!past_.empty() && past_.front().size() != disp.size())
    throw core::InputError("detector: the disparity map changed size within a stream");

  std::vector<PastDisparity> past;
  for (int k : params_.stereo.gaps)
    if (k <= static_cast<int>(past_.size()))
      past.push_back({k, &past_[static_cast<size_t>(k - 1)]});

  core::Detection det;
  det.frame = frame.index;
  det.time_s = frame.time_s;
  cv::Mat ttc;
  label_stereo(disp, past, camera_, params_.stereo, params_.envelope, det.danger, ttc);
  det.obstacles = extract_obstacles(det.danger, disp, ttc, camera_, params_.signal);
  det.regions = hysteresis_.update(count_region_pixels(det.danger, params_.signal.region_columns));
  det.signal = std::any_of(det.regions.begin(), det.regions.end(),
                           [](const core::RegionSignal& r) { return r.fired; });
  det.severity = severity_of(det.signal, det.obstacles, params_.signal);
  det.steering = steering_hint(det.regions);

  const int max_gap = *std::max_element(params_.stereo.gaps.begin(), params_.stereo.gaps.end());
  past_.push_front(disp.clone());
  while (static_cast<int>(past_.size()) > max_gap) past_.pop_back();
  return det;
}

void compute_disparity(const core::StereoFrame& frame, const core::DetectorParams& params,
                       cv::Mat& disp) {
  if (frame.left.empty() || frame.left.type() != CV_8UC1 || frame.right.type() != CV_8UC1 ||
      frame.left.size() != frame.right.size())
    throw core::InputError("frame " + std::to_string(frame.index) +
                           ": left and right must be 8-bit gray images of the same size");
  match_bm(frame.left, frame.right, params.bm, disp);
}

}  // namespace sg::vision
