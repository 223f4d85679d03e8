#include "sg/vision/labelling.hpp"

#include <algorithm>
#include <limits>

namespace sg::vision {

void label_stereo(const cv::Mat& disp, const std::vector<PastDisparity>& past,
                  const core::Camera& camera, const core::StereoLabelParams& p,
                  const core::Envelope& envelope, cv::Mat& danger, cv::Mat& ttc) {
  danger.create(disp.size(), CV_8U);
  ttc.create(disp.size(), CV_32F);
  const float kNaN = std::numeric_limits<float>::quiet_NaN();
  const double fb = camera.focal_px * camera.baseline_m;
  const double dt = camera.frame_period();
  const float min_delta = static_cast<float>(p.min_delta_d_px);
  const int n = static_cast<int>(past.size());
  const float max_growth = static_cast<float>(p.max_growth);

  std::vector<const float*> prev_rows(past.size());
  for (int y = 0; y < disp.rows; ++y) {
    const float* cur = disp.ptr<float>(y);
    for (int g = 0; g < n; ++g) prev_rows[g] = past[g].disp->ptr<float>(y);
    uchar* out_danger = danger.ptr<uchar>(y);
    float* out_ttc = ttc.ptr<float>(y);
    const double row_y = (y - camera.cy) / camera.focal_px;  // Y = row_y * Z

    for (int x = 0; x < disp.cols; ++x) {
      out_danger[x] = 0;
      out_ttc[x] = kNaN;
      const float d = cur[x];
      if (!(d > 0.0f)) continue;  // invalid, or at infinity
      const double z = fb / d;
      // Time until the point reaches the contact depth, from gap k:
      // t = (k*dt * D_{i-k} / (D_i - D_{i-k})) * (Z - z_contact) / Z. For a constant approach the
      // first factor is Z_i / v whatever k, so the longest flagging gap, which averages the most
      // matching noise away, gives the reported TTC.
      const double to_contact = std::max(0.0, (z - envelope.z_contact_m) / z);
      int best_gap = 0;
      double best = std::numeric_limits<double>::quiet_NaN();
      for (int g = 0; g < n; ++g) {
        const float dp = prev_rows[g][x];
        if (!(dp > 0.0f)) continue;
        const float delta = d - dp;
        if (!(delta >= min_delta)) continue;
        // A depth that more than halves within the gap is an object edge sweeping over the pixel,
        // not motion: a real approach that fast is caught by the smaller gaps.
        if (max_growth > 0.0f && d > max_growth * dp) continue;
        const double t = past[g].gap * dt * dp / delta * to_contact;
        if (t <= envelope.horizon_s && past[g].gap > best_gap) {
          best_gap = past[g].gap;
          best = t;
        }
      }
      if (best_gap == 0) continue;
      if (z > p.z_max_m) continue;
      if (p.use_envelope_band) {
        const double y_m = row_y * z;
        if (y_m < envelope.y_top_m || y_m > envelope.y_bottom_m) continue;
      }
      out_danger[x] = 255;
      out_ttc[x] = static_cast<float>(best);
    }
  }
}

}  // namespace sg::vision
