#include "sg/par/metrics.hpp"

#include <time.h>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace sg::par {

double thread_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}

void LatencyStats::add(double ms) {
  samples_.push_back(ms);
  sorted_valid_ = false;
}

void LatencyStats::clear() {
  samples_.clear();
  sorted_.clear();
  sorted_valid_ = true;
}

double LatencyStats::percentile(double p) const {
  if (samples_.empty()) return 0.0;
  if (!sorted_valid_) {
    sorted_ = samples_;
    std::sort(sorted_.begin(), sorted_.end());
    sorted_valid_ = true;
  }
  const auto n = static_cast<double>(sorted_.size());
  // p * n first: exact for integer p, so e.g. p95 of 20 samples is rank 19, not 20.
  const double rank = std::ceil(std::clamp(p, 0.0, 100.0) * n / 100.0);  // 1-based
  const auto index = static_cast<std::size_t>(std::max(rank, 1.0)) - 1;
  return sorted_[std::min(index, sorted_.size() - 1)];
}

double LatencyStats::min() const {
  return samples_.empty() ? 0.0 : *std::min_element(samples_.begin(), samples_.end());
}

double LatencyStats::max() const {
  return samples_.empty() ? 0.0 : *std::max_element(samples_.begin(), samples_.end());
}

double LatencyStats::sum() const { return std::accumulate(samples_.begin(), samples_.end(), 0.0); }

double LatencyStats::mean() const {
  return samples_.empty() ? 0.0 : sum() / static_cast<double>(samples_.size());
}

}  // namespace sg::par
