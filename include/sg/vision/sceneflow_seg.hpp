#pragma once
/// Scene-flow segmentation (thesis 3.2.2, DESIGN 3.4, after the thesis' [34] and [35]): how
/// unlikely each pixel's 3D motion is for a static world, then a two-label graph cut into moving
/// and static pixels.
///
/// Motion likelihood. A pixel p = (x, y) of frame i came from q = p + B(p) of frame i - 1 (the
/// backward flow B = (u, v)), where its disparity was d1 = D_{i-1}(q); now it is d2 = D_i(p), so
/// the disparity change is c = d2 - d1. Its scene flow M = P(x, y, d2) - P(x + u, y + v, d1) (3D
/// points of core::Camera) has the covariance Sigma = J diag(s_d^2, s_u^2, s_v^2, s_c^2) J^T, J the
/// Jacobian of M in (d1, u, v, c). For a static scene and a still camera M ~ N(0, Sigma), so the
/// Mahalanobis length xi = sqrt(M^T Sigma^-1 M) is large for what moves (xi^2 is chi-square with 3
/// degrees of freedom: xi^2 > 7.81 in 5 % of static pixels).
///
/// Graph cut. The labelling L (1 = moving) minimises
///   E(L) = sum_p [ -L(p) xi(p) - (1 - L(p)) xi_static ]
///        + lambda sum over 4-neighbours {p, p'} of |L(p) - L(p')| / (|I(p) - I(p')| + a),
/// an s-t minimum cut solved by Boost.Graph's Boykov-Kolmogorov max-flow.
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "sg/core/camera.hpp"
#include "sg/core/surveyed_params.hpp"

namespace sg::vision {

using SceneFlowSegParams = core::SceneFlowSegParams;

using core::validate;

/// xi per pixel (CV_32F); NaN where a disparity is invalid or q leaves the image (d1 is sampled
/// bilinearly, invalid when a neighbour is). Throws core::InputError on a type or size mismatch.
void motion_likelihood(const cv::Mat& disp_cur, const cv::Mat& disp_prev, const cv::Mat& flow,
                       const core::Camera& cam, const SceneFlowSegParams& p, cv::Mat& xi);

/// The labelling that minimises E (header) over an 8-bit grey image `image` and xi (CV_32F of its
/// size; NaN counts as xi_static, no evidence): CV_8U, 255 = moving. Also returns E of it in
/// `energy` when not null.
void segment_moving(const cv::Mat& image, const cv::Mat& xi, const SceneFlowSegParams& p,
                    cv::Mat& moving, double* energy = nullptr);

/// E (header) of a labelling (CV_8U, nonzero = moving): the reference the cut is tested against.
double segmentation_energy(const cv::Mat& image, const cv::Mat& xi, const SceneFlowSegParams& p,
                           const cv::Mat& moving);

}  // namespace sg::vision
