#include "eval_stereo.hpp"

#include <cstdio>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/core/utility.hpp>
#include <sstream>

#include "outputs.hpp"
#include "sg/core/error.hpp"
#include "sg/pipeline/stereo_evaluation.hpp"

namespace sg::apps {
namespace {

nlohmann::json to_json(const std::string& pair, const std::string& matcher, int nd, int block,
                       const eval::StereoScores& s, double ms) {
  return {{"pair", pair},
          {"matcher", matcher},
          {"num_disparities", nd},
          {"block_size", block},
          {"bad1", s.bad1},
          {"bad2", s.bad2},
          {"bad4", s.bad4},
          {"dense_bad1", s.dense_bad1},
          {"dense_bad2", s.dense_bad2},
          {"dense_bad4", s.dense_bad4},
          {"mae", s.mae},
          {"density", s.density},
          {"ms", ms}};
}

void print_row(const std::string& pair, const std::string& matcher, int nd,
               const eval::StereoScores& s, double ms) {
  std::printf("%-12s %-12s %4d %7.2f %7.2f %7.2f %7.3f %7.1f %8.2f %8.1f\n", pair.c_str(),
              matcher.c_str(), nd, s.bad1, s.bad2, s.bad4, s.mae, 100.0 * s.density, s.dense_bad2,
              ms);
}

}  // namespace

void eval_stereo_main(const StereoEvalArgs& args) {
  std::vector<io::StereoGtPair> pairs;
  if (!args.dir.empty()) {
    if (!args.left.empty() || !args.right.empty() || !args.gt.empty())
      throw core::InputError("--stereo takes --dir DIR or --left/--right/--gt, not both");
    pairs = io::find_stereo_gt_pairs(args.dir, args.gt_scale);
  } else {
    if (args.left.empty() || args.right.empty() || args.gt.empty())
      throw core::InputError("--stereo needs --dir DIR or all of --left, --right and --gt");
    pairs.push_back({std::filesystem::path(args.left).stem().string(), args.left, args.right,
                     args.gt, args.gt_scale});
  }
  if (args.gt_scale < 0) throw core::InputError("gt_scale: must be >= 0 (0 = from datasets.xml)");
  std::vector<pipeline::StereoMatcherEntry> matchers;
  std::stringstream list(args.matchers);
  for (std::string item; std::getline(list, item, ',');)
    matchers.push_back(pipeline::parse_matcher_entry(item, args.base));
  if (matchers.empty()) throw core::InputError("matchers: give at least one");

  // One OpenCV thread: times comparable between matchers and with DESIGN 8's kernel figures.
  const int threads = cv::getNumThreads();
  cv::setNumThreads(1);
  std::printf(
      "stereo eval: %zu pair(s), block %d, range %s; bad-k: %% of matched GT pixels off "
      "by > k px; dense bad-2: %% of GT pixels (missing = bad); ms: one thread\n",
      pairs.size(), args.base.block_size,
      args.auto_range ? "per pair from GT" : std::to_string(args.base.num_disparities).c_str());
  std::printf("%-12s %-12s %4s %7s %7s %7s %7s %7s %8s %8s\n", "pair", "matcher", "nd", "bad1",
              "bad2", "bad4", "mae", "dens%", "d-bad2", "ms");
  std::map<std::string, std::pair<eval::StereoScores, double>> sums;
  nlohmann::json rows = nlohmann::json::array();
  const auto result = pipeline::evaluate_stereo(
      pairs, matchers, args.auto_range, [&](const pipeline::StereoEvalRow& r) {
        print_row(r.pair, r.matcher, r.num_disparities, r.scores, r.ms);
        std::fflush(stdout);
        rows.push_back(to_json(r.pair, r.matcher, r.num_disparities, r.block_size, r.scores, r.ms));
      });
  cv::setNumThreads(threads);
  nlohmann::json means = nlohmann::json::array();
  for (const auto& m : matchers) {
    eval::StereoScores mean;
    double ms = 0;
    int n = 0;
    for (const auto& r : result) {
      if (r.matcher != m.label) continue;
      ++n;
      mean.bad1 += r.scores.bad1;
      mean.bad2 += r.scores.bad2;
      mean.bad4 += r.scores.bad4;
      mean.dense_bad1 += r.scores.dense_bad1;
      mean.dense_bad2 += r.scores.dense_bad2;
      mean.dense_bad4 += r.scores.dense_bad4;
      mean.mae += r.scores.mae;
      mean.density += r.scores.density;
      ms += r.ms;
    }
    for (double* v : {&mean.bad1, &mean.bad2, &mean.bad4, &mean.dense_bad1, &mean.dense_bad2,
                      &mean.dense_bad4, &mean.mae, &mean.density, &ms})
      *v /= n;
    print_row("mean", m.label, 0, mean, ms);
    means.push_back(to_json("mean", m.label, 0, m.params.block_size, mean, ms));
  }
  if (!args.json.empty())
    write_json_output(args.json, nlohmann::json{{"stereo", rows}, {"mean", means}}, 13);
}

}  // namespace sg::apps
