// Flow accuracy on real data (Middlebury RubberWhale, three FlyingChairs pairs). CTest label "data":
// skips when SG_SHARED_DIR/data is absent. Prints the EPE table; asserts loose sanity bounds only.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "sg/eval/flow_metrics.hpp"
#include "sg/io/gt_formats.hpp"
#include "sg/vision/flow.hpp"

namespace sg::vision {
namespace {

namespace fs = std::filesystem;

struct Pair {
  std::string name;
  fs::path frame1, frame2, gt;  ///< gt = forward flow frame1 -> frame2
};

std::vector<Pair> pairs() {
  const fs::path data = fs::path(SG_SHARED_DIR) / "data";
  std::vector<Pair> out;
  const fs::path rw = data / "middlebury_flow" / "RubberWhale";
  out.push_back({"RubberWhale", rw / "RubberWhale1.png", rw / "RubberWhale2.png",
                 rw / "RubberWhale.flo"});
  const fs::path fc = data / "flyingchairs_examples";
  for (const char* id : {"0000000", "0000001", "0000002"})
    out.push_back({std::string("chairs-") + id, fc / (std::string(id) + "-img0.ppm"),
                   fc / (std::string(id) + "-img1.ppm"), fc / (std::string(id) + "-gt.flo")});
  return out;
}

TEST(FlowData, EndPointErrorOnMiddleburyAndFlyingChairs) {
  const auto all = pairs();
  for (const auto& p : all)
    if (!fs::exists(p.frame1) || !fs::exists(p.frame2) || !fs::exists(p.gt))
      GTEST_SKIP() << "dataset file missing: " << p.gt.parent_path();
  std::printf("%-16s %-14s %8s %8s\n", "pair", "method", "EPE px", "bad3 %");
  for (const auto& pair : all) {
    const cv::Mat f1 = cv::imread(pair.frame1.string(), cv::IMREAD_GRAYSCALE);
    const cv::Mat f2 = cv::imread(pair.frame2.string(), cv::IMREAD_GRAYSCALE);
    const cv::Mat gt = io::read_flo(pair.gt);
    ASSERT_EQ(f1.size(), gt.size()) << pair.name;
    const eval::FlowAccuracy zero = eval::flow_accuracy(cv::Mat::zeros(gt.size(), CV_32FC2), gt);
    std::printf("%-16s %-14s %8.3f %8.2f\n", pair.name.c_str(), "zero-flow", zero.epe,
                zero.bad3_percent);
    ASSERT_GT(zero.valid_pixels, gt.total() / 2) << pair.name;
    for (FlowMethod m : {FlowMethod::kDisUltrafast, FlowMethod::kDisFast, FlowMethod::kDisMedium,
                         FlowMethod::kFarneback}) {
      FlowParams params;
      params.method = m;
      cv::Mat flow;
      // The GT is forward (1 -> 2); our flow is backward (current -> previous), so frame 1 plays
      // "current" and frame 2 "previous".
      compute_flow(f1, f2, params, flow);
      const eval::FlowAccuracy a = eval::flow_accuracy(flow, gt);
      std::printf("%-16s %-14s %8.3f %8.2f\n", pair.name.c_str(), to_string(m), a.epe,
                  a.bad3_percent);
      // Loose bounds. FlyingChairs has large motions (up to ~75 px) that DIS and Farneback often
      // miss (chairs-0000000 ends above the zero-flow EPE); a sign error roughly doubles the EPE.
      EXPECT_LT(a.epe, 1.6 * zero.epe) << pair.name << " " << to_string(m);
      if (pair.name == "RubberWhale" || pair.name == "chairs-0000001") {
        EXPECT_LT(a.epe, 0.7 * zero.epe) << pair.name << " " << to_string(m);
      }
      if (pair.name == "RubberWhale" && m == FlowMethod::kDisMedium) {
        EXPECT_LT(a.epe, 1.5);
      }
    }
  }
  std::fflush(stdout);
}

}  // namespace
}  // namespace sg::vision
