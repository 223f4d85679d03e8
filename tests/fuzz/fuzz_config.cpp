// libFuzzer target: the YAML config file (io::apply_config_file), then validation of what it
// set, as the CLI does.
#include "fuzz_input.hpp"
#include "sg/core/camera.hpp"
#include "sg/core/params.hpp"
#include "sg/io/config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = sg::fuzz::write_input(data, size, ".yaml");
  sg::fuzz::expect_only_input_errors([&] {
    sg::core::DetectorParams params;
    sg::io::RunSettings settings;
    sg::io::apply_config_file(path, params, settings);
    (void)sg::core::validate(params, sg::core::Camera{});
  });
  return 0;
}
