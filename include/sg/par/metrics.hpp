#pragma once
/// Timing helpers for the pipeline metrics of DESIGN.md section 1 (latency percentiles, service
/// time, busy time). Know nothing about images.
#include <chrono>
#include <cstddef>
#include <vector>

namespace sg::par {

/// The monotonic clock every stage stamps times with.
using Clock = std::chrono::steady_clock;
using TimePoint = Clock::time_point;

/// Now, on the monotonic clock.
inline TimePoint now() { return Clock::now(); }

/// Milliseconds from `from` to `to` (negative if `to` is earlier), as a double.
inline double elapsed_ms(TimePoint from, TimePoint to) {
  return std::chrono::duration<double, std::milli>(to - from).count();
}

/// Milliseconds since `from`.
inline double elapsed_ms(TimePoint from) { return elapsed_ms(from, now()); }

/// Measures an interval: started on construction or restart().
class Stopwatch {
 public:
  Stopwatch() : start_(now()) {}
  /// Starts again from now.
  void restart() { start_ = now(); }
  /// Milliseconds since the start.
  double elapsed_ms() const { return sg::par::elapsed_ms(start_); }

 private:
  TimePoint start_;
};

/// CPU time of the calling thread, ms (CLOCK_THREAD_CPUTIME_ID): unlike wall time it does not
/// grow while the thread waits for a core, so a stage's cost can be read on a loaded machine.
/// Work the thread hands to other threads (nested parallel loops) is not counted.
double thread_cpu_ms();

/// Measures the calling thread's CPU time from construction; read it on the same thread.
class CpuStopwatch {
 public:
  CpuStopwatch() : start_(thread_cpu_ms()) {}
  /// CPU milliseconds this thread spent since the start.
  double elapsed_ms() const { return thread_cpu_ms() - start_; }

 private:
  double start_;
};

/// Latency samples in milliseconds with nearest-rank percentiles. Not thread-safe: fill it from one
/// stage (e.g. the collector) or guard it.
class LatencyStats {
 public:
  /// Adds one sample, ms.
  void add(double ms);
  /// Removes all samples.
  void clear();
  /// Number of samples.
  std::size_t count() const { return samples_.size(); }
  bool empty() const { return samples_.empty(); }
  /// Nearest-rank percentile, ms: the smallest sample such that at least p% of the samples are <=
  /// it, i.e. sorted[ceil(p / 100 * n) - 1] (p <= 0 gives the minimum, p >= 100 the maximum).
  /// 0 when there are no samples.
  double percentile(double p) const;
  double p50() const { return percentile(50.0); }  ///< median, ms
  double p95() const { return percentile(95.0); }  ///< ms
  double p99() const { return percentile(99.0); }  ///< ms
  double min() const;                              ///< ms, 0 when empty
  double max() const;                              ///< ms, 0 when empty
  double mean() const;                             ///< ms, 0 when empty
  double sum() const;                              ///< ms, 0 when empty
  /// The samples in the order they were added, ms.
  const std::vector<double>& samples() const { return samples_; }

 private:
  std::vector<double> samples_;
  mutable std::vector<double> sorted_;  // cache, rebuilt when a sample was added
  mutable bool sorted_valid_ = true;
};

}  // namespace sg::par
