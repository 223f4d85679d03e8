#include "sg/vision/sceneflow_seg.hpp"

// GCC 12 sees Boost.Graph's optional edge iterators as maybe uninitialised once inlined here.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <boost/graph/adjacency_list.hpp>
#include <boost/graph/boykov_kolmogorov_max_flow.hpp>
#pragma GCC diagnostic pop
#include <cmath>
#include <limits>

#include "sg/core/checker.hpp"
#include "sg/core/error.hpp"
#include "sg/vision/scene_flow.hpp"

namespace sg::vision {
namespace {

using Traits = boost::adjacency_list_traits<boost::vecS, boost::vecS, boost::directedS>;
using Graph = boost::adjacency_list<
    boost::vecS, boost::vecS, boost::directedS,
    boost::property<boost::vertex_index_t, long,
                    boost::property<boost::vertex_color_t, boost::default_color_type,
                                    boost::property<boost::vertex_distance_t, long,
                                                    boost::property<boost::vertex_predecessor_t,
                                                                    Traits::edge_descriptor>>>>,
    boost::property<boost::edge_capacity_t, double,
                    boost::property<boost::edge_residual_capacity_t, double,
                                    boost::property<boost::edge_reverse_t,
                                                    Traits::edge_descriptor>>>>;

/// Adds a -> b with capacity `forward` and b -> a with `backward`, each the other's reverse.
void add_pair(Graph& g, long a, long b, double forward, double backward) {
  auto capacity = boost::get(boost::edge_capacity, g);
  auto reverse = boost::get(boost::edge_reverse, g);
  const Traits::edge_descriptor e = boost::add_edge(a, b, g).first;
  const Traits::edge_descriptor r = boost::add_edge(b, a, g).first;
  capacity[e] = forward;
  capacity[r] = backward;
  reverse[e] = r;
  reverse[r] = e;
}

double xi_at(const cv::Mat& xi, int y, int x, double xi_static) {
  const float v = xi.at<float>(y, x);
  return std::isfinite(v) ? v : xi_static;
}

/// The smoothness weight between two neighbours.
double weight(const cv::Mat& image, cv::Point a, cv::Point b, const SceneFlowSegParams& p) {
  const double contrast = std::abs(int{image.at<std::uint8_t>(a)} - int{image.at<std::uint8_t>(b)});
  return p.lambda / (contrast + p.contrast_a);
}

void check_segmentation_inputs(const cv::Mat& image, const cv::Mat& xi,
                               const SceneFlowSegParams& p) {
  core::throw_if_invalid(validate(p), "invalid parameters");
  if (image.type() != CV_8UC1 || xi.type() != CV_32FC1 || image.size() != xi.size() ||
      image.empty())
    throw core::InputError(
        "scene-flow segmentation: an 8-bit grey image and a CV_32F likelihood of one size");
}

}  // namespace

void motion_likelihood(const cv::Mat& disp_cur, const cv::Mat& disp_prev, const cv::Mat& flow,
                       const core::Camera& cam, const SceneFlowSegParams& p, cv::Mat& xi) {
  core::throw_if_invalid(validate(p), "invalid parameters");
  if (disp_cur.type() != CV_32FC1 || disp_prev.type() != CV_32FC1 || flow.type() != CV_32FC2 ||
      disp_prev.size() != disp_cur.size() || flow.size() != disp_cur.size() || disp_cur.empty())
    throw core::InputError(
        "scene-flow segmentation: two CV_32F disparities and a CV_32FC2 flow of one size");
  xi.create(disp_cur.size(), CV_32FC1);
  const cv::Vec4d var(p.sigma_disparity_px * p.sigma_disparity_px,
                      p.sigma_flow_px * p.sigma_flow_px, p.sigma_flow_px * p.sigma_flow_px,
                      p.sigma_change_px * p.sigma_change_px);
  for (int y = 0; y < disp_cur.rows; ++y) {
    const float* d = disp_cur.ptr<float>(y);
    const auto* f = flow.ptr<cv::Vec2f>(y);
    float* out = xi.ptr<float>(y);
    for (int x = 0; x < disp_cur.cols; ++x) {
      out[x] = std::numeric_limits<float>::quiet_NaN();
      const double d2 = d[x];
      if (!(d2 > 0.0) || !std::isfinite(f[x][0]) || !std::isfinite(f[x][1])) continue;
      const double qx = x + f[x][0], qy = y + f[x][1];
      float d1f;
      if (!sample_disparity_bilinear(disp_prev, static_cast<float>(qx), static_cast<float>(qy),
                                     d1f) ||
          !(d1f > 0.0f))
        continue;
      const double d1 = d1f;
      const cv::Vec3d now(cam.point(x, y, d2)), before(cam.point(qx, qy, d1));
      const cv::Vec3d M = now - before;
      // dP/dd = -P / d; dP/dx = (B / d, 0, 0); dP/dy = (0, B / d, 0). M = P(p, d1 + c) - P(q, d1).
      const cv::Vec3d dd1 = -now / d2 + before / d1, dc = -now / d2;
      const double lateral = -cam.baseline_m / d1;
      const cv::Matx<double, 3, 4> J(dd1[0], lateral, 0.0, dc[0],  //
                                     dd1[1], 0.0, lateral, dc[1],  //
                                     dd1[2], 0.0, 0.0, dc[2]);
      const cv::Matx33d sigma = J * cv::Matx44d::diag(var) * J.t();
      bool invertible = true;
      const cv::Matx33d inv = sigma.inv(cv::DECOMP_CHOLESKY, &invertible);
      if (!invertible) continue;
      out[x] = static_cast<float>(std::sqrt(std::max(0.0, M.dot(inv * M))));
    }
  }
}

double segmentation_energy(const cv::Mat& image, const cv::Mat& xi, const SceneFlowSegParams& p,
                           const cv::Mat& moving) {
  check_segmentation_inputs(image, xi, p);
  if (moving.type() != CV_8UC1 || moving.size() != image.size())
    throw core::InputError(
        "scene-flow segmentation: the labelling must be CV_8U of the image's size");
  double e = 0.0;
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) {
      const bool m = moving.at<std::uint8_t>(y, x) != 0;
      e += m ? -xi_at(xi, y, x, p.xi_static) : -p.xi_static;
      for (const cv::Point n : {cv::Point(x + 1, y), cv::Point(x, y + 1)}) {
        if (n.x >= image.cols || n.y >= image.rows) continue;
        if (m != (moving.at<std::uint8_t>(n) != 0)) e += weight(image, {x, y}, n, p);
      }
    }
  }
  return e;
}

void segment_moving(const cv::Mat& image, const cv::Mat& xi, const SceneFlowSegParams& p,
                    cv::Mat& moving, double* energy) {
  check_segmentation_inputs(image, xi, p);
  const int w = image.cols, h = image.rows;
  const long n = static_cast<long>(w) * h, source = n, sink = n + 1;
  Graph g(static_cast<size_t>(n + 2));
  // The source side is "moving": cutting s -> p (p static) costs p's static term, cutting
  // p -> t (p moving) its moving term, each less their minimum, which E adds as a constant.
  double constant = 0.0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const long v = static_cast<long>(y) * w + x;
      const double cost_moving = -xi_at(xi, y, x, p.xi_static), cost_static = -p.xi_static;
      const double m = std::min(cost_moving, cost_static);
      constant += m;
      add_pair(g, source, v, cost_static - m, 0.0);
      add_pair(g, v, sink, cost_moving - m, 0.0);
      if (x + 1 < w) {
        const double c = weight(image, {x, y}, {x + 1, y}, p);
        add_pair(g, v, v + 1, c, c);
      }
      if (y + 1 < h) {
        const double c = weight(image, {x, y}, {x, y + 1}, p);
        add_pair(g, v, v + w, c, c);
      }
    }
  }
  const double flow = boost::boykov_kolmogorov_max_flow(g, source, sink);
  // After the flow the source's search tree (black) is the source side of a minimum cut.
  auto color = boost::get(boost::vertex_color, g);
  moving.create(image.size(), CV_8UC1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      moving.at<std::uint8_t>(y, x) =
          color[static_cast<long>(y) * w + x] == boost::black_color ? 255 : 0;
  if (energy) *energy = flow + constant;
}

}  // namespace sg::vision
