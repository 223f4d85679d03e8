#pragma once
/// Row tiling, the data-parallel skeleton of DESIGN.md section 1 (FastFlow's parallel-for): a task
/// of H rows is split into T contiguous horizontal tiles computed independently. A tile of rows
/// [b, e) may read the rows its kernel needs around them (h rows above and below, clamped to
/// [0, H)) and writes only [b, e), so tiled output can equal untiled output bit for bit. Knows
/// nothing about images.
///
///   sg::par::parallel_for_tiles(rows, tiles, [&](int t, int begin, int end) {
///     kernel(input, output, sg::par::RowRange{begin, end});   // writes rows [begin, end) only
///   });
#include <functional>

#include "sg/par/backend.hpp"

namespace sg::par {

/// Half-open range of rows [begin, end). A plain struct so that this layer needs no OpenCV.
struct RowRange {
  int begin = 0;  ///< first row
  int end = 0;    ///< one past the last row
  /// Number of rows, >= 0 for a valid range.
  int size() const { return end - begin; }
  bool empty() const { return end <= begin; }
  bool operator==(const RowRange&) const = default;
};

/// Number of tiles actually used for `rows` rows: `tiles` clamped to [1, rows]; 0 when rows <= 0.
/// tiles < 1 counts as 1.
int tile_count(int rows, int tiles);

/// Rows of tile `t` (0 <= t < tile_count(rows, tiles)) when [0, rows) is split into
/// tile_count(rows, tiles) contiguous tiles whose sizes differ by at most one (the first
/// rows % count tiles get the extra row). Tiles are in order and partition [0, rows).
RowRange tile_rows(int rows, int tiles, int t);

/// Body of a tiled loop: (tile index, first row, one past the last row).
using TileBody = std::function<void(int tile, int begin, int end)>;

/// Calls `body(t, begin, end)` once for every tile t of tile_rows(rows, tiles, t); nothing when
/// rows <= 0. kSequential calls the tiles in order on the caller's thread; kTbb runs one task per
/// tile with tbb::parallel_for (simple_partitioner) in the current arena (see run_in_arena), so
/// tiles may run concurrently and `body` must only write tile-private data. Returns when all tiles
/// are done. An exception thrown by `body` is rethrown here (with kTbb, remaining tiles may be
/// skipped).
void parallel_for_tiles(int rows, int tiles, const TileBody& body,
                        Backend backend = Backend::kTbb);

}  // namespace sg::par
