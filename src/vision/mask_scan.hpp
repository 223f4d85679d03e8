#pragma once
// Scans of a CV_8U mask row eight bytes at a time, for the run-based labellings
// (components.cpp, segment_motion.cpp). Internal header.
#include <cstdint>
#include <cstring>

namespace sg::vision::detail {

constexpr std::uint64_t kLowBits = 0x0101010101010101ULL;
constexpr std::uint64_t kHighBits = 0x8080808080808080ULL;

inline std::uint64_t load8(const std::uint8_t* p) {
  std::uint64_t v = 0;
  std::memcpy(&v, p, sizeof v);
  return v;
}

/// The first pixel from x on with m[x] != 0, or cols; eight clear bytes at a time.
inline int next_set(const std::uint8_t* m, int x, int cols) {
  while (x + 8 <= cols && load8(m + x) == 0) x += 8;
  while (x < cols && m[x] == 0) ++x;
  return x;
}

/// The first pixel from x on with m[x] == 0, or cols; eight set bytes at a time (no zero byte in v:
/// (v - 0x01..01) & ~v & 0x80..80 is 0).
inline int next_clear(const std::uint8_t* m, int x, int cols) {
  while (x + 8 <= cols) {
    const std::uint64_t v = load8(m + x);
    if (((v - kLowBits) & ~v & kHighBits) != 0) break;
    x += 8;
  }
  while (x < cols && m[x] != 0) ++x;
  return x;
}

}  // namespace sg::vision::detail
