#pragma once
/// Helpers shared by the libFuzzer targets: every parser of user input reads a file, so each
/// target writes the fuzzer's bytes to a file and calls the parser on it.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

#include "sg/core/error.hpp"

namespace sg::fuzz {

/// Writes `size` bytes to a file of this process (in /dev/shm or the temp directory) ending in
/// `suffix` (e.g. ".yaml", ".flo": some readers choose the format by extension) and returns its
/// path. The same path is reused by every call with the same suffix.
std::filesystem::path write_input(const std::uint8_t* data, std::size_t size,
                                  const std::string& suffix);

/// Writes `size` bytes to `name` (a relative path, folders created) inside a folder of this
/// process and returns the file's path: for readers that take a folder or look for files next to
/// the one they read. The same folder is reused by every call.
std::filesystem::path write_named_input(const std::uint8_t* data, std::size_t size,
                                        const std::filesystem::path& name);

/// Runs `parse`; core::InputError is the expected answer to a bad file and is swallowed. Any
/// other exception escapes to libFuzzer and counts as a finding: the CLI would report it as an
/// internal error (exit status 1) instead of a clear message about the file.
template <typename Parse>
void expect_only_input_errors(Parse&& parse) {
  try {
    parse();
  } catch (const core::InputError&) {
  }
}

}  // namespace sg::fuzz
