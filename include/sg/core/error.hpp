#pragma once
/// Errors a user can cause (bad input, bad parameters). The CLI turns them into one line on stderr
/// and exit status 2; anything else escaping is a bug.
#include <stdexcept>
#include <string>
#include <vector>

namespace sg::core {

/// A problem with the user's input: a missing file, a size mismatch, a bad calibration, an invalid
/// parameter. `what()` is one line naming the problem.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Throws InputError joining `problems` with "; " when it is not empty. `context` prefixes the
/// message (e.g. "invalid parameters").
void throw_if_invalid(const std::vector<std::string>& problems, const std::string& context);

}  // namespace sg::core
