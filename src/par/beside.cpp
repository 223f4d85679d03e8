#include "sg/par/beside.hpp"

#include <atomic>
#include <exception>
#include <thread>

namespace sg::par {

void run_beside(const std::function<void()>& work, const std::function<void()>& pump) {
  std::atomic<bool> done{false};
  std::exception_ptr failure;
  std::thread worker([&] {
    try {
      work();
    } catch (...) {
      failure = std::current_exception();
    }
    done.store(true, std::memory_order_release);
  });
  std::exception_ptr pump_failure;
  while (!done.load(std::memory_order_acquire)) {
    try {
      pump();
    } catch (...) {
      pump_failure = std::current_exception();
      break;
    }
  }
  worker.join();
  if (failure) std::rethrow_exception(failure);
  if (pump_failure) std::rethrow_exception(pump_failure);
}

}  // namespace sg::par
