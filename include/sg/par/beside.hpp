#pragma once
/// Work on a thread of its own while the caller's thread keeps a loop of its own going (a window
/// toolkit must run on the thread that created it), and a one-slot mailbox between the two.
#include <functional>
#include <mutex>
#include <optional>
#include <utility>

namespace sg::par {

/// Runs `work` on a new thread and calls `pump` on the caller's thread, again and again, until
/// `work` has returned (`pump` should block briefly, e.g. waiting for a window event, or the loop
/// spins). Returns after the thread is joined; an exception thrown by `work` is rethrown here, one
/// thrown by `pump` after `work` has returned (`pump` must make `work` end when it fails, e.g. by
/// a stop request it reads, or the caller waits for `work` to finish on its own).
void run_beside(const std::function<void()>& work, const std::function<void()>& pump);

/// The newest value put, taken at most once: a producer that must never wait puts every value, a
/// consumer that may fall behind takes the latest and misses the ones in between.
template <class T>
class Latest {
 public:
  void put(T value) {
    std::lock_guard<std::mutex> lock(mutex_);
    value_ = std::move(value);
  }
  /// The value put since the last take, if any.
  std::optional<T> take() {
    std::lock_guard<std::mutex> lock(mutex_);
    std::optional<T> out = std::move(value_);
    value_.reset();
    return out;
  }

 private:
  std::mutex mutex_;
  std::optional<T> value_;
};

}  // namespace sg::par
