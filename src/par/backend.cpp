#include "sg/par/backend.hpp"

#include <oneapi/tbb/global_control.h>
#include <oneapi/tbb/info.h>
#include <oneapi/tbb/task_arena.h>
#include <optional>

namespace sg::par {

const char* to_string(Backend backend) {
  switch (backend) {
    case Backend::kSequential:
      return "sequential";
    case Backend::kTbb:
      return "tbb";
  }
  return "?";
}

int default_threads() {
  const int n = tbb::info::default_concurrency();
  return n > 0 ? n : 1;
}

void run_in_arena(int threads, const std::function<void()>& body) {
  if (threads <= 0) {
    body();
    return;
  }
  // An arena larger than the machine (e.g. one extra thread for a stage that mostly sleeps) needs
  // the process-wide limit raised while it runs; TBB otherwise caps its workers at the cores.
  std::optional<tbb::global_control> allow;
  if (threads > default_threads()) {
    allow.emplace(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
  }
  tbb::task_arena arena(threads);
  arena.execute(body);  // runs `body` on this thread, joined to the arena
}

}  // namespace sg::par
