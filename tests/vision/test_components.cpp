#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "sg/vision/components.hpp"

namespace sg::vision {
namespace {

/// Random masks: blobs of rectangles and ellipses at several densities, single pixels,
/// diagonal chains and widths that are not a multiple of 8.
cv::Mat random_mask(cv::Size size, int shapes, double speckle, std::uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat m(size, CV_8UC1, cv::Scalar(0));
  for (int i = 0; i < shapes; ++i) {
    const cv::Point c(rng.uniform(0, size.width), rng.uniform(0, size.height));
    const cv::Size axes(rng.uniform(1, std::max(2, size.width / 3)),
                        rng.uniform(1, std::max(2, size.height / 3)));
    if (rng.uniform(0, 2) == 0)
      cv::ellipse(m, c, axes, rng.uniform(0.0, 180.0), 0, 360, cv::Scalar(255), cv::FILLED);
    else
      cv::rectangle(m, cv::Rect(c, axes), cv::Scalar(255), cv::FILLED);
  }
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x)
      if (rng.uniform(0.0, 1.0) < speckle) m.at<std::uint8_t>(y, x) ^= 255;
  // A diagonal chain: connected only through corners.
  for (int k = 0; k < std::min(size.width, size.height) / 2; ++k)
    m.at<std::uint8_t>(k, size.width - 1 - k) = 255;
  return m;
}

/// Expects connected_runs to give OpenCV's 8-connected components, numbered in the raster order
/// of their first pixels, with OpenCV's areas and boxes, and runs that tile the mask.
void expect_same_as_opencv(const cv::Mat& mask, const std::string& what) {
  std::vector<ComponentRun> runs;
  std::vector<ComponentStats> stats;
  const int count = connected_runs(mask, runs, stats);
  cv::Mat cv_labels, cv_stats, centroids;
  const int cv_count =
      cv::connectedComponentsWithStats(mask, cv_labels, cv_stats, centroids, 8, CV_32S);
  ASSERT_EQ(count, cv_count) << what;
  ASSERT_EQ(static_cast<int>(stats.size()), count) << what;
  cv::Mat labels(mask.size(), CV_32SC1, cv::Scalar(0));
  for (size_t r = 0; r < runs.size(); ++r) {
    const ComponentRun& run = runs[r];
    if (r > 0) {  // raster order, maximal, disjoint
      const ComponentRun& before = runs[r - 1];
      ASSERT_TRUE(before.y < run.y || (before.y == run.y && before.x1 < run.x0)) << what;
    }
    ASSERT_TRUE(run.label >= 1 && run.label < count) << what;
    for (int x = run.x0; x < run.x1; ++x) labels.at<int>(run.y, x) = run.label;
  }
  // Every set pixel is in a run, and our labels map one to one onto OpenCV's.
  std::map<int, int> ours_to_cv, cv_to_ours;
  int next_new = 1;
  for (int y = 0; y < mask.rows; ++y)
    for (int x = 0; x < mask.cols; ++x) {
      const int ours = labels.at<int>(y, x), theirs = cv_labels.at<int>(y, x);
      ASSERT_EQ(ours == 0, mask.at<std::uint8_t>(y, x) == 0) << what << " at " << x << "," << y;
      if (ours == 0) continue;
      if (!ours_to_cv.count(ours)) {
        ASSERT_EQ(ours, next_new++)
            << what << ": not numbered in raster order at " << x << "," << y;
        ours_to_cv[ours] = theirs;
      }
      if (!cv_to_ours.count(theirs)) cv_to_ours[theirs] = ours;
      ASSERT_EQ(ours_to_cv[ours], theirs) << what << " at " << x << "," << y;
      ASSERT_EQ(cv_to_ours[theirs], ours) << what << " at " << x << "," << y;
    }
  for (const auto& [ours, theirs] : ours_to_cv) {
    const ComponentStats& s = stats[static_cast<size_t>(ours)];
    EXPECT_EQ(s.area, cv_stats.at<int>(theirs, cv::CC_STAT_AREA)) << what << " label " << ours;
    EXPECT_EQ(s.bbox, cv::Rect(cv_stats.at<int>(theirs, cv::CC_STAT_LEFT),
                               cv_stats.at<int>(theirs, cv::CC_STAT_TOP),
                               cv_stats.at<int>(theirs, cv::CC_STAT_WIDTH),
                               cv_stats.at<int>(theirs, cv::CC_STAT_HEIGHT)))
        << what << " label " << ours;
  }
}

TEST(ConnectedRuns, EqualOpenCvsEightConnectedComponents) {
  int seed = 0;
  for (const cv::Size size : {cv::Size(640, 480), cv::Size(37, 23), cv::Size(1, 9), cv::Size(9, 1)})
    for (int shapes : {0, 3, 25})
      for (double speckle : {0.0, 0.02, 0.5}) {
        const cv::Mat mask = random_mask(size, shapes, speckle, static_cast<std::uint64_t>(++seed));
        expect_same_as_opencv(mask, "mask " + std::to_string(seed));
      }
}

TEST(ConnectedRuns, HandlesFullEmptyAndRoiMasks) {
  expect_same_as_opencv(cv::Mat(48, 70, CV_8UC1, cv::Scalar(255)), "full");
  expect_same_as_opencv(cv::Mat(48, 70, CV_8UC1, cv::Scalar(0)), "empty");
  // A region of interest: rows are not contiguous, and values other than 255 count as set.
  cv::Mat big = random_mask(cv::Size(200, 100), 12, 0.05, 77);
  big.setTo(1, big == 255);
  expect_same_as_opencv(big(cv::Rect(13, 7, 101, 61)), "roi");
  std::vector<ComponentRun> runs;
  std::vector<ComponentStats> stats;
  EXPECT_THROW(connected_runs(cv::Mat(4, 4, CV_32FC1, cv::Scalar(1)), runs, stats),
               std::exception);
}

}  // namespace
}  // namespace sg::vision
