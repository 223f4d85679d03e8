#pragma once
/// Parameter validation: collects one "<section>.<field>=<value>: <rule>" line per broken rule
/// ("<field>=<value>: <rule>" without a section), the form every validate() of the project
/// reports (core::throw_if_invalid joins them).
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace sg::core {

class Checker {
 public:
  explicit Checker(std::vector<std::string>& out, std::string section = "")
      : out_(out), section_(std::move(section)) {}
  template <typename T>
  void require(bool ok, const std::string& field, const T& value, const char* rule) {
    if (ok) return;
    std::ostringstream s;
    if (!section_.empty()) s << section_ << ".";
    s << field << "=" << value << ": " << rule;
    out_.push_back(s.str());
  }

 private:
  std::vector<std::string>& out_;
  std::string section_;
};

}  // namespace sg::core
