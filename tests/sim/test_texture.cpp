// The simulator's texture: the SIMD kernel (texture_values) against its scalar reference
// (texture_value), on every SIMD target this machine runs.
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <opencv2/core.hpp>
#include <vector>

#include "sg/sim/texture.hpp"

namespace sg::sim {
namespace {

struct Points {
  std::vector<double> u, v, footprint;
  std::vector<std::uint32_t> seed;
};

/// Points of surfaces near and far: coordinates over +-80 m (a few up to +-5 km), footprints from
/// 10 um to 3 m (every octave from all present to all absent), neighbours of very different
/// footprints (silhouettes), and footprints of 0 (no octave) and equal neighbours.
Points random_points(int count, std::uint64_t rng_seed) {
  cv::RNG rng(rng_seed);
  Points p;
  for (int i = 0; i < count; ++i) {
    const double span = rng.uniform(0, 20) == 0 ? 5000.0 : 80.0;
    p.u.push_back(rng.uniform(-span, span));
    p.v.push_back(rng.uniform(-span, span));
    double fp = std::exp(rng.uniform(std::log(1e-5), std::log(3.0)));
    if (rng.uniform(0, 50) == 0) fp = 0.0;
    if (i > 0 && rng.uniform(0, 3) == 0) fp = p.footprint.back();
    p.footprint.push_back(fp);
    p.seed.push_back(rng.uniform(0, 8) == 0 ? p.seed.empty() ? 7U : p.seed.back()
                                            : static_cast<std::uint32_t>(rng.next()));
  }
  return p;
}

std::vector<std::uint64_t> bits(const std::vector<double>& v) {
  std::vector<std::uint64_t> out(v.size());
  std::memcpy(out.data(), v.data(), v.size() * sizeof(double));
  return out;
}

TEST(Texture, EveryTargetEqualsTheScalarReferenceBitForBit) {
  // An odd count, so that the scalar tail runs too.
  const Points p = random_points(20003, 5);
  const int n = static_cast<int>(p.u.size());
  std::vector<double> slow(p.u.size());
  int textured = 0, faded = 0;
  const TextureParams params;
  for (int i = 0; i < n; ++i) {
    slow[i] = texture_value(p.u[i], p.v[i], p.seed[i], p.footprint[i]);
    textured += slow[i] != 0.0;
    // Some octave between fading in and fading out: a weight other than 0 and 1.
    for (double cell = params.finest_cell_m; cell < 100.0; cell *= 2.0) {
      const double r = cell / p.footprint[i];
      if ((r > params.fade_in_px && r < params.full_in_px) ||
          (r > params.fade_out_px && r < params.gone_px)) {
        ++faded;
        break;
      }
    }
  }
  // Most points are textured and many lie in an octave's fade, so a kernel that drops an octave,
  // a weight or the mask fails.
  EXPECT_GT(textured, n * 3 / 4);
  EXPECT_GT(faded, n / 2);
  for (int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    ASSERT_EQ(texture_target(), hwy::TargetName(target));
    std::vector<double> fast(p.u.size() + 1, -7.0);
    texture_values(p.u.data(), p.v.data(), p.seed.data(), p.footprint.data(), n, fast.data());
    EXPECT_EQ(fast.back(), -7.0) << "wrote past n on " << texture_target();
    fast.pop_back();
    const std::vector<std::uint64_t> a = bits(fast), b = bits(slow);
    for (int i = 0; i < n; ++i)
      ASSERT_EQ(a[i], b[i]) << texture_target() << ": point " << i << " (" << p.u[i] << ", "
                            << p.v[i] << ") seed " << p.seed[i] << " footprint "
                            << p.footprint[i] << ": " << fast[i] << " against " << slow[i];
  }
  hwy::SetSupportedTargetsForTest(0);
}

TEST(Texture, NoPointsAndFewerPointsThanALane) {
  const Points p = random_points(3, 9);
  std::vector<double> out(3, -7.0);
  texture_values(p.u.data(), p.v.data(), p.seed.data(), p.footprint.data(), 0, out.data());
  EXPECT_EQ(out[0], -7.0);
  texture_values(p.u.data(), p.v.data(), p.seed.data(), p.footprint.data(), 3, out.data());
  for (int i = 0; i < 3; ++i)
    EXPECT_EQ(out[i], texture_value(p.u[i], p.v[i], p.seed[i], p.footprint[i])) << i;
}

}  // namespace
}  // namespace sg::sim
