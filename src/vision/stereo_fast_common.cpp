#include "stereo_fast_common.hpp"

#include <algorithm>

#include "sg/vision/stereo_fast.hpp"

namespace sg::vision {

namespace fast_detail {
namespace {
int clamp_index(int i, int n) { return std::clamp(i, 0, n - 1); }
}  // namespace

void prefilter_rows(const cv::Mat& img, int cap, int r0, int r1, cv::Mat& out) {
  // Borders as StereoBM's prefilter: rows reflected without repeating the edge (row -1 = row 1),
  // first and last columns set to cap (no gradient), and an odd height's last row too.
  const int width = img.cols, height = img.rows;
  out.create(r1 - r0, width, CV_8U);
  auto reflect = [height](int y) {
    if (height == 1) return 0;
    return y < 0 ? -y : (y >= height ? 2 * height - 2 - y : y);
  };
  for (int y = r0; y < r1; ++y) {
    const std::uint8_t* a = img.ptr<std::uint8_t>(reflect(y - 1));
    const std::uint8_t* b = img.ptr<std::uint8_t>(y);
    const std::uint8_t* c = img.ptr<std::uint8_t>(reflect(y + 1));
    std::uint8_t* o = out.ptr<std::uint8_t>(y - r0);
    if (height % 2 == 1 && y == height - 1 && height > 1) {
      // StereoBM filters rows in pairs and leaves an odd height's last row flat (= cap).
      std::fill(o, o + width, static_cast<std::uint8_t>(cap));
      continue;
    }
    o[0] = static_cast<std::uint8_t>(cap);
    for (int x = 1; x + 1 < width; ++x) {
      const int v = (a[x + 1] - a[x - 1]) + 2 * (b[x + 1] - b[x - 1]) + (c[x + 1] - c[x - 1]);
      o[x] = static_cast<std::uint8_t>(std::clamp(v, -cap, cap) + cap);
    }
    o[width - 1] = static_cast<std::uint8_t>(cap);
  }
}

void census_rows(const cv::Mat& img, int r0, int r1, cv::Mat& out) {
  const int width = img.cols, height = img.rows, r = kCensusRadius;
  out.create(r1 - r0, width, CV_32S);
  // Rows padded by r on each side so that the inner loop has no branches.
  std::vector<std::uint8_t> pad(static_cast<size_t>(2 * r + 1) * (width + 2 * r));
  const int pw = width + 2 * r;
  for (int y = r0; y < r1; ++y) {
    for (int k = -r; k <= r; ++k) {
      const std::uint8_t* src = img.ptr<std::uint8_t>(clamp_index(y + k, height));
      std::uint8_t* dst = pad.data() + static_cast<size_t>(k + r) * pw;
      for (int x = -r; x < width + r; ++x) dst[x + r] = src[clamp_index(x, width)];
    }
    std::uint32_t* o = reinterpret_cast<std::uint32_t*>(out.ptr<std::int32_t>(y - r0));
    const std::uint8_t* centre = pad.data() + static_cast<size_t>(r) * pw + r;
    for (int x = 0; x < width; ++x) o[x] = 0;
    for (int dy = -r; dy <= r; ++dy) {
      for (int dx = -r; dx <= r; ++dx) {
        if (dy == 0 && dx == 0) continue;
        const std::uint8_t* nb = pad.data() + static_cast<size_t>(dy + r) * pw + r + dx;
        for (int x = 0; x < width; ++x)
          o[x] = (o[x] << 1) | static_cast<std::uint32_t>(nb[x] < centre[x]);
      }
    }
  }
}

void store_disparity16(const cv::Mat& rows16, int y0, cv::Mat& disp) {
  for (int i = 0; i < rows16.rows; ++i) {
    const std::int16_t* src = rows16.ptr<std::int16_t>(i);
    float* dst = disp.ptr<float>(y0 + i);
    for (int x = 0; x < rows16.cols; ++x)
      dst[x] = src[x] == kInvalid16 ? -1.0f : static_cast<float>(src[x]) / 16.0f;
  }
}

}  // namespace fast_detail
}  // namespace sg::vision
