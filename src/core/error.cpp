#include "sg/core/error.hpp"

namespace sg::core {

void throw_if_invalid(const std::vector<std::string>& problems, const std::string& context) {
  if (problems.empty()) return;
  std::string message = context + ": ";
  for (size_t i = 0; i < problems.size(); ++i) {
    if (i > 0) message += "; ";
    message += problems[i];
  }
  throw InputError(message);
}

}  // namespace sg::core
