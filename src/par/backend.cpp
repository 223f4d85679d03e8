#include "sg/par/backend.hpp"

#include <oneapi/tbb/info.h>
#include <oneapi/tbb/task_arena.h>

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

std::optional<Backend> parse_backend(std::string_view text) {
  if (text == "sequential") return Backend::kSequential;
  if (text == "tbb") return Backend::kTbb;
  return std::nullopt;
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
  tbb::task_arena arena(threads);
  arena.execute(body);  // runs `body` on this thread, joined to the arena
}

}  // namespace sg::par
