#pragma once
/// The per-pixel envelope test of pool_surface_motion (DESIGN 3.2), on one run of pixels of one
/// row that share a pooled surface velocity: a SIMD kernel (Google Highway, dispatched at run
/// time) and the scalar reference it must equal bit for bit. Both use the same double-precision
/// operations in the same order, and the kernel's file is compiled without contraction into
/// fused multiply-adds, so every lane rounds exactly as the scalar code does.
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>

#include "sg/core/camera.hpp"
#include "sg/core/params.hpp"

namespace sg::vision {

/// What the test of one frame shares across its surfaces.
struct SurfaceTest {
  double cx = 0.0, cy = 0.0, focal_px = 0.0;  ///< the camera's principal point and focal, px
  double fb = 0.0;                            ///< focal_px * baseline_m
  double span_s = 0.0;                        ///< the noise gate's span (the longest gap), s
  double min_delta_d_px = 0.0;                ///< the noise gate's disparity growth, px
  double v_min_mps = 0.0;                     ///< heads_into_envelope's approach speed
  double yaw_rate_rps = 0.0;  ///< the platform's turn (heads_into_envelope_turning), rad/s
  /// With a turn: cos and sin of the angle the surface's velocity is turned by before the test,
  /// -yaw_rate_rps span_s / 2 (the fit's slope is the velocity at the middle of its span).
  double turn_cos = 1.0, turn_sin = 0.0;
  core::Envelope envelope;
};

/// The test's constants for a frame (pool_surface_motion's arguments).
SurfaceTest make_surface_test(const core::Camera& cam, const core::Envelope& env,
                              const core::SceneFlowParams& p, double span_s,
                              double yaw_rate_rps = 0.0);

/// For x in [x0, x1) of row y, with disparities d[x] > 0 of one surface moving at V (m/s):
/// ttc[x] = the TTC of V (s, t_c keep) when the noise gate (with V) and
/// heads_into_envelope(P(x, y, d[x]), V keep) pass, NaN otherwise. keep in (0, 1]: the share of
/// V that the surface's doubt leaves (1: none). Only ttc[x0, x1) is written. With a yaw rate the
/// test is heads_into_envelope_turning, pixel by pixel (the reference's loop).
void test_surface_run(const SurfaceTest& k, const cv::Vec3d& V, double keep, int y, int x0, int x1,
                      const float* d, float* ttc);

/// test_surface_run with k.yaw_rate_rps != 0: V turned by (turn_cos, turn_sin), the same noise
/// gate as the reference, then heads_into_envelope_turning.
void test_surface_run_turning(const SurfaceTest& k, const cv::Vec3d& V, double keep, int y, int x0,
                              int x1, const float* d, float* ttc);

/// The same as test_surface_run without a turn, one pixel at a time: the reference the SIMD
/// kernel is tested against.
void test_surface_run_reference(const SurfaceTest& k, const cv::Vec3d& V, double keep, int y,
                                int x0, int x1, const float* d, float* ttc);

/// The SIMD target test_surface_run runs on this machine (e.g. "AVX3").
std::string surface_test_target();

}  // namespace sg::vision
