// libFuzzer target: a real recording's truth log (eval::read_truth_log), and what eval derives
// from and scores against it.
#include "fuzz_input.hpp"
#include "sg/eval/truth_log.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto csv = sg::fuzz::write_input(data, size, ".csv");
  sg::fuzz::expect_only_input_errors([&] {
    const sg::eval::TruthLog log = sg::eval::read_truth_log(csv);
    const sg::eval::TruthCriteria criteria;
    sg::eval::TruthScorer scorer(sg::eval::derive_truth(log, criteria, 1.0 / 15), criteria);
    for (int i = 0; i < 8; ++i) {
      sg::core::Detection d;
      d.frame = i;
      d.time_s = i / 15.0;
      d.signal = i % 3 == 0;
      scorer.add(d);
    }
    (void)scorer.report().table();
  });
  return 0;
}
