#include "sg/vision/components.hpp"

#include <cstdint>

#include "sg/core/error.hpp"
#include "mask_scan.hpp"
#include "union_find.hpp"

namespace sg::vision {

using detail::next_clear;
using detail::next_set;

int connected_runs(const cv::Mat& mask, std::vector<ComponentRun>& runs,
                   std::vector<ComponentStats>& stats) {
  if (mask.type() != CV_8UC1) throw core::InputError("components: the mask must be CV_8U");
  runs.clear();
  std::vector<int> parent;
  size_t above_begin = 0, above_end = 0;  // the previous row's runs
  for (int y = 0; y < mask.rows; ++y) {
    const std::uint8_t* m = mask.ptr<std::uint8_t>(y);
    const size_t row_begin = runs.size();
    size_t above = above_begin;
    for (int x = next_set(m, 0, mask.cols); x < mask.cols; x = next_set(m, x, mask.cols)) {
      const int x1 = next_clear(m, x, mask.cols);
      const int node = static_cast<int>(runs.size());
      runs.push_back({y, x, x1, 0});
      parent.push_back(node);
      // Runs above touch [x, x1) 8-connectedly when they overlap [x - 1, x1 + 1).
      while (above < above_end && runs[above].x1 < x) ++above;
      for (size_t a = above; a < above_end && runs[a].x0 <= x1; ++a)
        detail::unite_roots(parent, node, static_cast<int>(a));
      x = x1;
    }
    above_begin = row_begin;
    above_end = runs.size();
  }
  // A set's root is its smallest run, the component's first in raster order: numbered when met.
  stats.assign(1, ComponentStats{});
  for (size_t r = 0; r < runs.size(); ++r) {
    ComponentRun& run = runs[r];
    const int root = detail::find_root(parent, static_cast<int>(r));
    const cv::Rect box(run.x0, run.y, run.x1 - run.x0, 1);
    if (root == static_cast<int>(r)) {
      run.label = static_cast<int>(stats.size());
      stats.push_back({box, 0});
    } else {
      run.label = runs[static_cast<size_t>(root)].label;
      stats[static_cast<size_t>(run.label)].bbox |= box;
    }
    stats[static_cast<size_t>(run.label)].area += run.x1 - run.x0;
  }
  return static_cast<int>(stats.size());
}

}  // namespace sg::vision
