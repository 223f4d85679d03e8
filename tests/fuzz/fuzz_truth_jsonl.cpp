// libFuzzer target: one line of a stereo folder's gt/frames.jsonl (io::parse_truth_line).
#include <string>

#include "fuzz_input.hpp"
#include "sg/io/stereo_folder.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string line(reinterpret_cast<const char*>(data), size);
  sg::fuzz::expect_only_input_errors([&] { (void)sg::io::parse_truth_line(line, "fuzz:1"); });
  return 0;
}
