#include "sg/par/jobs.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "sg/par/backend.hpp"

namespace sg::par {

void for_each_job(int count, int threads, const std::function<void(int)>& job,
                  const std::function<void()>& done) {
  if (count <= 0) return;
  const int n = std::min(count, threads > 0 ? threads : default_threads());
  std::atomic<int> next{0};
  std::atomic<bool> failed{false};
  std::mutex mutex;  // guards error and the calls of done
  std::exception_ptr error;
  const auto work = [&] {
    for (int i = next++; i < count && !failed; i = next++) {
      try {
        job(i);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(mutex);
        if (!error) error = std::current_exception();
        failed = true;
        return;
      }
      if (done) {
        const std::lock_guard<std::mutex> lock(mutex);
        done();
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < n; ++t) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace sg::par
