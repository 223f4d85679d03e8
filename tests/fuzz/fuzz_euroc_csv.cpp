// libFuzzer target: EuRoC camN/data.csv (io::read_euroc_csv: timestamp_ns,file name).
#include "fuzz_input.hpp"
#include "sg/io/sources.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto csv = sg::fuzz::write_named_input(data, size, "cam0/data.csv");
  sg::fuzz::expect_only_input_errors([&] { (void)sg::io::read_euroc_csv(csv.parent_path()); });
  return 0;
}
