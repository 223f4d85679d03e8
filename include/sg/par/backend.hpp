#pragma once
/// The runtime that executes the skeletons of sg::par (DESIGN.md section 1): a plain sequential
/// loop, the reference for correctness, or oneTBB. No TBB type appears in this layer's headers.
#include <functional>

namespace sg::par {

/// How a skeleton runs. Both backends call the user's callables with the same arguments in the
/// same per-stage order; only concurrency differs.
enum class Backend {
  kSequential,  ///< a plain loop on the caller's thread (the reference)
  kTbb,         ///< oneTBB: flow graph for farms, parallel_for for tiles
};

/// "sequential" / "tbb".
const char* to_string(Backend backend);

/// Number of threads oneTBB uses when none is given (the cores this process may use), >= 1.
int default_threads();

/// Runs `body` on the caller's thread inside a oneTBB task arena of `threads` threads (the caller
/// counts as one of them), so that every TBB algorithm started by `body`, including OpenCV's
/// parallel loops, uses at most that many threads. threads = 0 runs `body` in the current arena
/// (oneTBB's default, default_threads()). An exception thrown by `body` propagates to the caller.
/// Precondition: threads >= 0.
void run_in_arena(int threads, const std::function<void()>& body);

}  // namespace sg::par
