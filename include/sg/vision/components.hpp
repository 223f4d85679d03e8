#pragma once
/// Connected components by row runs (DESIGN 3.3, the clean-up's blobs): a union-find over each
/// row's runs of set pixels, not over every pixel, so that a blob covering half the image costs
/// about as little as its outline.
#include <opencv2/core.hpp>
#include <vector>

namespace sg::vision {

/// Pixels [x0, x1) of row y, all set, of component `label`.
struct ComponentRun {
  int y = 0, x0 = 0, x1 = 0;
  int label = 0;
};

/// A component's bounding box and pixel count.
struct ComponentStats {
  cv::Rect bbox;
  int area = 0;
};

/// The 8-connected components of the nonzero pixels of `mask` (CV_8U): `runs` = every maximal run
/// of set pixels of a row, in raster order, each with its component's label; labels 1..count-1
/// are numbered in the raster order of the components' first pixels (cv::connectedComponents
/// numbers them in the order of its block scan). stats[label] for label >= 1 (stats[0] is empty).
/// Returns count (1 when nothing is set).
int connected_runs(const cv::Mat& mask, std::vector<ComponentRun>& runs,
                   std::vector<ComponentStats>& stats);

}  // namespace sg::vision
