#pragma once
/// Heap warm-up for a pipeline's first frames. Knows nothing about images.
#include <cstddef>

namespace sg::par {

/// Touches `bytes` of fresh heap memory, one write a page, in blocks of `block_bytes`, and frees
/// it again. Where the process keeps freed blocks on its heap (glibc with a high mmap and trim
/// threshold and one arena, as `stereoguard` sets them), the full-size maps a pipeline allocates
/// in its first frames then land on pages the kernel has already mapped instead of faulting each
/// one in: on a 2-core VM the first 20 Stereo-Flow frames at 640x480 took 30 ms instead of 20
/// until the history of past maps was full (perf: page faults). Elsewhere it only costs the
/// time of the writes. Returns the bytes touched.
std::size_t prefault_heap(std::size_t bytes, std::size_t block_bytes = std::size_t{16} << 20);

}  // namespace sg::par
