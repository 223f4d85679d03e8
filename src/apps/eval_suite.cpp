#include "eval_suite.hpp"

#include <iostream>
#include <limits>
#include <memory>
#include <opencv2/imgcodecs.hpp>

#include "outputs.hpp"
#include "sg/core/error.hpp"
#include "sg/io/progress.hpp"
#include "sg/pipeline/random_suite.hpp"

namespace sg::apps {

void eval_suite_main(const SuiteEvalArgs& args) {
  if (args.suite != "random")
    throw core::InputError("suite=" + args.suite + ": the only suite is 'random'");
  if (!args.count) throw core::InputError("--suite random needs --count N");
  if (!args.seed) throw core::InputError("--suite random needs --seed S (the first scene's seed)");
  if (*args.seed < 0 || *args.seed > std::numeric_limits<std::uint32_t>::max())
    throw core::InputError("seed=" + std::to_string(*args.seed) + ": must be in 0..4294967295");
  pipeline::RandomSuiteOptions options;
  options.count = *args.count;
  options.first_seed = static_cast<std::uint32_t>(*args.seed);
  if (!args.max_size.empty()) options.max_size = parse_size(args.max_size, "max-size", "320x240");
  options.max_frames = args.max_frames;
  options.jobs = args.jobs;
  options.detector = args.detector;
  core::throw_if_invalid(pipeline::validate(options), "eval --suite random");
  std::unique_ptr<io::ProgressBar> progress;
  if (!args.quiet && io::stderr_is_terminal())
    progress = std::make_unique<io::ProgressBar>(std::cerr, options.count,
                                                 std::chrono::milliseconds(100), "scenes");
  const pipeline::RandomSuiteResult result = pipeline::run_random_suite(options, [&] {
    if (progress) progress->tick();
  });
  if (progress) progress->finish();
  std::cout << "eval --suite random, seeds " << options.first_seed << ".."
            << options.first_seed + static_cast<std::uint32_t>(options.count - 1) << "\n"
            << result.table();
  if (!args.plot.empty()) {
    const cv::Mat image = pipeline::plot_random_suite(result);
    bool written = false;
    try {
      written = cv::imwrite(args.plot, image);
    } catch (const cv::Exception&) {
      written = false;
    }
    if (!written) throw core::InputError(args.plot + ": cannot write the plot (a .png path?)");
    std::cout << "plot " << args.plot << "\n";
  }
  if (!args.json.empty()) write_json_output(args.json, result.to_json());
}

}  // namespace sg::apps
