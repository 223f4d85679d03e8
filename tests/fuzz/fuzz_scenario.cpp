// libFuzzer target: scenario files, YAML or JSON (sim::load_scenario_file).
#include "fuzz_input.hpp"
#include "sg/sim/scenario.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = sg::fuzz::write_input(data, size, ".yaml");
  sg::fuzz::expect_only_input_errors([&] { (void)sg::sim::load_scenario_file(path.string()); });
  return 0;
}
