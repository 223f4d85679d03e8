#include "sg/pipeline/flow_evaluation.hpp"

#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "sg/core/error.hpp"
#include "sg/vision/flow.hpp"

namespace sg::pipeline {
namespace {

namespace fs = std::filesystem;

cv::Mat read_gray_image(const fs::path& path) {
  cv::Mat img = cv::imread(path.string(), cv::IMREAD_GRAYSCALE);
  if (img.empty()) throw core::InputError("image " + path.string() + " cannot be decoded");
  return img;
}

}  // namespace

std::vector<FlowEvalRow> evaluate_flow(const std::vector<io::FlowGtPair>& pairs,
                                       const std::vector<core::FlowMethod>& methods,
                                       const std::function<void(const FlowEvalRow&)>& on_row) {
  for (const io::FlowGtPair& pair : pairs)
    for (const fs::path& f : {pair.first, pair.second, pair.gt})
      if (!fs::is_regular_file(f)) throw core::InputError("file " + f.string() + " does not exist");
  std::vector<FlowEvalRow> rows;
  for (const io::FlowGtPair& pair : pairs) {
    const cv::Mat first = read_gray_image(pair.first), second = read_gray_image(pair.second);
    const cv::Mat gt = io::read_flo(pair.gt);
    if (first.size() != second.size() || first.size() != gt.size())
      throw core::InputError("pair " + pair.name + ": sizes differ (" + pair.first.string() + ", " +
                             pair.second.string() + ", " + pair.gt.string() + ")");
    for (core::FlowMethod m : methods) {
      core::FlowParams params;
      params.method = m;
      cv::Mat flow;
      vision::compute_flow(first, second, params, flow);
      FlowEvalRow row{pair.name, m, eval::flow_accuracy(flow, gt)};
      if (on_row) on_row(row);
      rows.push_back(std::move(row));
    }
  }
  return rows;
}

}  // namespace sg::pipeline
