#include <gtest/gtest.h>

#include <vector>

#include "sg/pipeline/bench.hpp"

namespace sg::pipeline {
namespace {

BenchRow row(const char* kind, int workers, double fps, double p99) {
  BenchRow r;
  r.kind = kind;
  r.workers = workers;
  r.fps = fps;
  r.latency_p99_ms = p99;
  return r;
}

TEST(BestForPacing, TakesTheLowestTailAmongTheFastest) {
  // W 3 is fastest by noise but doubles the tail: W 2 is what a user paces a camera with.
  const std::vector<BenchRow> rows = {row("opencv-mt", 1, 300, 5),  row("pipeline", 1, 70, 19),
                                      row("pipeline", 2, 105.9, 33), row("pipeline", 3, 106.5, 60),
                                      row("paced", 2, 200, 1)};
  EXPECT_EQ(best_for_pacing(rows), 2u);
  // Beyond the 5 % of noise, throughput wins.
  const std::vector<BenchRow> clear = {row("pipeline", 2, 100, 33), row("pipeline", 3, 106, 60)};
  EXPECT_EQ(best_for_pacing(clear), 1u);
  EXPECT_EQ(best_for_pacing({row("baseline", 1, 50, 20)}), 1u);  // no pipeline row
  EXPECT_EQ(best_for_pacing({}), 0u);
}

}  // namespace
}  // namespace sg::pipeline
