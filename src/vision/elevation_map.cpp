#include "sg/vision/elevation_map.hpp"

#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <random>

#include "sg/core/checker.hpp"
#include "sg/core/error.hpp"

namespace sg::vision {
namespace {

/// The road model's terms at (X, Z): the row of the linear system for (a2, a1, b2, b1, c).
cv::Matx<double, 1, 5> terms(const cv::Point3d& P) {
  return {P.x * P.x, P.x, P.z * P.z, P.z, 1.0};
}

/// Least-squares road through `pts` (at least 5); false when degenerate.
bool solve_road(const std::vector<cv::Point3d>& pts, RoadModel& road) {
  cv::Mat A(static_cast<int>(pts.size()), 5, CV_64F), b(static_cast<int>(pts.size()), 1, CV_64F);
  for (int i = 0; i < A.rows; ++i) {
    const cv::Matx<double, 1, 5> t = terms(pts[static_cast<size_t>(i)]);
    for (int j = 0; j < 5; ++j) A.at<double>(i, j) = t(0, j);
    b.at<double>(i) = pts[static_cast<size_t>(i)].y;
  }
  cv::Mat x;
  if (!cv::solve(A, b, x, cv::DECOMP_SVD | cv::DECOMP_NORMAL) || !cv::checkRange(x)) return false;
  // A singular sample (points on one line of Z, say) solves to a model that is not unique.
  cv::Mat w;
  cv::SVD::compute(A.t() * A, w, cv::SVD::NO_UV);
  if (w.at<double>(4) <= 1e-12 * w.at<double>(0)) return false;
  road.a2 = x.at<double>(0), road.a1 = x.at<double>(1), road.b2 = x.at<double>(2);
  road.b1 = x.at<double>(3), road.c = x.at<double>(4);
  return true;
}

/// Calls f(P) for every sampled pixel with a valid disparity, with its 3D point.
template <class F>
void for_each_point(const cv::Mat& disp, const core::Camera& cam, int step, F&& f) {
  for (int y = 0; y < disp.rows; y += step) {
    const float* row = disp.ptr<float>(y);
    for (int x = 0; x < disp.cols; x += step)
      if (row[x] > 0.0f) f(cam.point(x, y, row[x]));
  }
}

void check_disparity(const cv::Mat& disp) {
  if (disp.type() != CV_32FC1 || disp.empty())
    throw core::InputError("elevation map: the disparity must be a non-empty CV_32F map");
}

}  // namespace

RoadModel fit_road(const cv::Mat& disp, const core::Camera& cam, const ElevationParams& p) {
  check_disparity(disp);
  core::throw_if_invalid(validate(p), "invalid parameters");
  std::vector<cv::Point3d> pts;
  for_each_point(disp, cam, p.sample_step_px, [&](const cv::Point3d& P) {
    if (P.z >= p.fit_z_min_m && P.z <= p.fit_z_max_m && P.y >= p.fit_y_min_m) pts.push_back(P);
  });
  RoadModel best;
  if (static_cast<int>(pts.size()) < std::max(5, p.min_inliers)) return best;
  auto inliers_of = [&](const RoadModel& m, std::vector<cv::Point3d>* keep) {
    int n = 0;
    for (const cv::Point3d& P : pts) {
      if (std::abs(P.y - m.y(P.x, P.z)) > p.tolerance_m) continue;
      ++n;
      if (keep) keep->push_back(P);
    }
    return n;
  };
  std::mt19937_64 rng(p.seed);
  std::uniform_int_distribution<size_t> pick(0, pts.size() - 1);
  std::vector<cv::Point3d> sample(5);
  for (int it = 0; it < p.iterations; ++it) {
    for (cv::Point3d& s : sample) s = pts[pick(rng)];
    RoadModel m;
    if (!solve_road(sample, m)) continue;
    m.inliers = inliers_of(m, nullptr);
    if (m.inliers > best.inliers) best = m;
  }
  if (best.inliers < p.min_inliers) return RoadModel{};
  std::vector<cv::Point3d> in;
  inliers_of(best, &in);
  // The least-squares refit of the inliers, unless it is degenerate or keeps too few of them.
  best.found = true;
  RoadModel refit;
  if (!solve_road(in, refit)) return best;
  refit.inliers = inliers_of(refit, nullptr);
  refit.found = true;
  return refit.inliers >= p.min_inliers ? refit : best;
}

bool ElevationMap::locate(double X, double Z, int& row, int& col) const {
  if (!(Z > 0.0) || !std::isfinite(X)) return false;
  row = static_cast<int>(std::ceil(Z / cell_m)) - 1;
  col = static_cast<int>(std::floor((X + half_width_m) / cell_m));
  return row >= 0 && row < count.rows && col >= 0 && col < count.cols;
}

ElevationMap build_elevation_map(const cv::Mat& disp, const core::Camera& cam,
                                 const RoadModel& road, const ElevationParams& p) {
  check_disparity(disp);
  core::throw_if_invalid(validate(p), "invalid parameters");
  if (!road.found) throw core::InputError("elevation map: no road model to build the map on");
  ElevationMap map;
  map.cell_m = p.cell_m;
  map.half_width_m = p.half_width_m;
  const int rows = static_cast<int>(std::ceil(p.z_max_m / p.cell_m));
  const int cols = static_cast<int>(std::ceil(2.0 * p.half_width_m / p.cell_m));
  map.count = cv::Mat::zeros(rows, cols, CV_32SC1);
  cv::Mat height_sum = cv::Mat::zeros(rows, cols, CV_64FC1);
  for_each_point(disp, cam, p.sample_step_px, [&](const cv::Point3d& P) {
    int r, c;
    if (!map.locate(P.x, P.z, r, c)) return;
    ++map.count.at<int>(r, c);
    height_sum.at<double>(r, c) += road.y(P.x, P.z) - P.y;
  });
  // Erd: the image area of the cell laid on the road, clipped to the image, in samples.
  map.expected.create(rows, cols, CV_32FC1);
  const std::vector<cv::Point2f> image = {
      {0.0f, 0.0f},
      {static_cast<float>(disp.cols), 0.0f},
      {static_cast<float>(disp.cols), static_cast<float>(disp.rows)},
      {0.0f, static_cast<float>(disp.rows)}};
  const double per_sample = static_cast<double>(p.sample_step_px) * p.sample_step_px;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const double x0 = -p.half_width_m + c * p.cell_m, z0 = r * p.cell_m;
      std::vector<cv::Point2f> quad;
      bool visible = true;
      for (const cv::Point2d& corner :
           {cv::Point2d(x0, z0), cv::Point2d(x0 + p.cell_m, z0),
            cv::Point2d(x0 + p.cell_m, z0 + p.cell_m), cv::Point2d(x0, z0 + p.cell_m)}) {
        // The nearest row of cells starts at the camera: its corners at Z = 0 are moved in front.
        const double Z = std::max(corner.y, 0.05);
        const cv::Point3d P(corner.x, road.y(corner.x, Z), Z);
        const cv::Point2d q = cam.project(P);
        if (!std::isfinite(q.x) || !std::isfinite(q.y) || std::abs(q.x) > 1e6 ||
            std::abs(q.y) > 1e6)
          visible = false;
        quad.emplace_back(static_cast<float>(q.x), static_cast<float>(q.y));
      }
      double area = 0.0;
      if (visible) {
        std::vector<cv::Point2f> hull, clipped;
        cv::convexHull(quad, hull);
        area = cv::intersectConvexConvex(hull, image, clipped, true);
      }
      map.expected.at<float>(r, c) = static_cast<float>(std::max(0.0, area) / per_sample);
    }
  }
  map.height.create(rows, cols, CV_32FC1);
  map.cell.create(rows, cols, CV_8UC1);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const int n = map.count.at<int>(r, c);
      auto& cell = map.cell.at<std::uint8_t>(r, c);
      if (n == 0) {
        map.height.at<float>(r, c) = std::numeric_limits<float>::quiet_NaN();
        cell = static_cast<std::uint8_t>(Cell::kEmpty);
        continue;
      }
      const double h = height_sum.at<double>(r, c) / n;
      map.height.at<float>(r, c) = static_cast<float>(h);
      if (n < p.min_points) {
        cell = static_cast<std::uint8_t>(Cell::kEmpty);
        continue;
      }
      // A cell the road would leave (nearly) empty but that holds min_points is dense too.
      const double road_points = std::max<double>(map.expected.at<float>(r, c), 1.0);
      const bool dense = n >= p.density_ratio * road_points;
      Cell k = Cell::kRoad;
      if (h > p.height_min_m || dense) {
        k = Cell::kObstacle;
      } else if (h > p.tolerance_m) {
        k = Cell::kSmallObstacle;
      }
      cell = static_cast<std::uint8_t>(k);
    }
  }
  return map;
}

void mark_elevation_obstacles(const cv::Mat& disp, const core::Camera& cam, const RoadModel& road,
                              const ElevationMap& map, const ElevationParams& p, cv::Mat& mask) {
  check_disparity(disp);
  mask.create(disp.size(), CV_8UC1);
  for (int y = 0; y < disp.rows; ++y) {
    const float* d = disp.ptr<float>(y);
    std::uint8_t* m = mask.ptr<std::uint8_t>(y);
    for (int x = 0; x < disp.cols; ++x) {
      m[x] = 0;
      if (!(d[x] > 0.0f)) continue;
      const cv::Point3d P = cam.point(x, y, d[x]);
      int r, c;
      if (!map.locate(P.x, P.z, r, c)) continue;
      if (map.cell.at<std::uint8_t>(r, c) != static_cast<std::uint8_t>(Cell::kObstacle)) continue;
      if (road.y(P.x, P.z) - P.y > p.tolerance_m) m[x] = 255;
    }
  }
}

}  // namespace sg::vision
