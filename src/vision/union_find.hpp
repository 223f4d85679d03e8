#pragma once
// The union-find of the run-based labellings (segment_motion.cpp, components.cpp) and of the
// relative-size feature clusters (relative_size.cpp). Internal header.
#include <algorithm>
#include <vector>

namespace sg::vision::detail {

/// Union-find root with path halving.
inline int find_root(std::vector<int>& parent, int i) {
  while (parent[static_cast<size_t>(i)] != i) {
    parent[static_cast<size_t>(i)] = parent[static_cast<size_t>(parent[static_cast<size_t>(i)])];
    i = parent[static_cast<size_t>(i)];
  }
  return i;
}

/// Joins the sets of a and b under the smaller root.
inline void unite_roots(std::vector<int>& parent, int a, int b) {
  a = find_root(parent, a);
  b = find_root(parent, b);
  if (a != b) parent[static_cast<size_t>(std::max(a, b))] = std::min(a, b);
}

}  // namespace sg::vision::detail
