#pragma once
/// Helpers shared by the io tests: a scratch folder per test and error-message capture.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <unistd.h>

#include "sg/core/error.hpp"

namespace sg::io::testing_util {

/// A fresh folder under testing::TempDir(), removed when the test ends.
class ScratchDir {
 public:
  ScratchDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = std::filesystem::path(::testing::TempDir()) /
            ("sg_io_" + std::string(info->test_suite_name()) + "_" + info->name() + "_" +
             std::to_string(::getpid()));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

/// The message of the core::InputError thrown by `f`; a test failure when none is thrown.
template <typename F>
std::string input_error_of(F&& f) {
  try {
    f();
  } catch (const core::InputError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << "message not one line: " << message;
    return message;
  }
  ADD_FAILURE() << "expected core::InputError";
  return {};
}

}  // namespace sg::io::testing_util
