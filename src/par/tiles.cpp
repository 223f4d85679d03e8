#include "sg/par/tiles.hpp"

#include <algorithm>
#include <atomic>

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/partitioner.h>

namespace sg::par {

int tile_count(int rows, int tiles) {
  if (rows <= 0) return 0;
  return std::clamp(tiles, 1, rows);
}

RowRange tile_rows(int rows, int tiles, int t) {
  const int count = tile_count(rows, tiles);
  if (count == 0 || t < 0 || t >= count) return {};
  const int base = rows / count;
  const int extra = rows % count;  // the first `extra` tiles get one more row
  const int begin = t * base + std::min(t, extra);
  return {begin, begin + base + (t < extra ? 1 : 0)};
}

void parallel_for_tiles(int rows, int tiles, const TileBody& body, Backend backend) {
  const int count = tile_count(rows, tiles);
  if (count == 0) return;
  if (backend == Backend::kSequential || count == 1) {
    for (int t = 0; t < count; ++t) {
      const RowRange r = tile_rows(rows, count, t);
      body(t, r.begin, r.end);
    }
    return;
  }
  // The release/acquire pairs duplicate the ordering TBB provides when it spawns and joins the
  // tile tasks; they make it visible to ThreadSanitizer, which cannot see inside the
  // uninstrumented libtbb. Each side writes its own atomic, so no edge links two tiles: TSan still
  // reports two tiles touching the same memory.
  std::atomic<int> started{0};
  std::atomic<int> finished{0};
  started.store(1, std::memory_order_release);
  tbb::parallel_for(
      tbb::blocked_range<int>(0, count, 1),
      [&](const tbb::blocked_range<int>& range) {
        (void)started.load(std::memory_order_acquire);
        for (int t = range.begin(); t != range.end(); ++t) {
          const RowRange r = tile_rows(rows, count, t);
          body(t, r.begin, r.end);
        }
        finished.fetch_add(1, std::memory_order_release);
      },
      tbb::simple_partitioner());
  (void)finished.load(std::memory_order_acquire);
}

}  // namespace sg::par
