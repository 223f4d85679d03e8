#include "sg/core/source.hpp"

#include <gtest/gtest.h>

namespace sg::core {
namespace {

/// Three 4x2 frames whose pixels hold their index.
class CountingSource : public FrameSource {
 public:
  std::optional<StereoFrame> next() override {
    if (next_ == 3) return std::nullopt;
    StereoFrame f;
    f.index = next_;
    f.time_s = next_ * 0.5;
    f.left = cv::Mat(2, 4, CV_8UC1, cv::Scalar(next_));
    f.right = cv::Mat(2, 4, CV_8UC1, cv::Scalar(10 + next_));
    ++next_;
    return f;
  }
  const Camera& camera() const override { return camera_; }

 private:
  Camera camera_;
  int next_ = 0;
};

TEST(FrameSource, DefaultNextPendingKeepsOrderStampsAndPixels) {
  CountingSource source;
  std::vector<PendingFrame> pending;
  while (auto p = source.next_pending()) pending.push_back(std::move(*p));
  ASSERT_EQ(pending.size(), 3u);
  // Loaded out of order, as a farm may do: each load still yields its own frame.
  for (int i : {2, 0, 1}) {
    const StereoFrame f = pending[i].load();
    EXPECT_EQ(pending[i].index, i);
    EXPECT_DOUBLE_EQ(pending[i].time_s, i * 0.5);
    EXPECT_EQ(f.index, i);
    EXPECT_EQ(f.left.at<uchar>(1, 3), i);
    EXPECT_EQ(f.right.at<uchar>(0, 0), 10 + i);
  }
}

}  // namespace
}  // namespace sg::core
