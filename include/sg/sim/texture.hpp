#pragma once
/// Procedural surface texture of the simulator: band-limited multi-octave value noise, a pure
/// function of surface coordinates in metres, so textures stay fixed to the objects.
/// texture_value is the reference; texture_values evaluates many points at once with SIMD and
/// equals it bit for bit.
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace sg::sim {

/// Integer hash (lowbias32 style); good enough to decorrelate lattice points and seeds.
inline std::uint32_t hash_u32(std::uint32_t h) {
  h ^= h >> 16;
  h *= 0x7feb352dU;
  h ^= h >> 15;
  h *= 0x846ca68bU;
  h ^= h >> 16;
  return h;
}

/// Hash of several words.
inline std::uint32_t hash_combine(std::uint32_t a, std::uint32_t b) {
  return hash_u32(a ^ (b + 0x9e3779b9U + (a << 6) + (a >> 2)));
}

constexpr std::uint32_t kLatticeBits = 8;
constexpr std::uint32_t kLatticeMask = (1U << kLatticeBits) - 1;

/// A fixed 256 x 256 table of values uniform in [-1, 1): the lattice of every octave of every
/// texture, read at a per-(seed, octave) offset (cheaper than hashing every lattice point).
inline const float* random_lattice() {
  static const std::vector<float> kTable = [] {
    std::vector<float> t(std::size_t{1} << (2 * kLatticeBits));
    for (std::uint32_t i = 0; i < t.size(); ++i)
      t[i] = static_cast<float>(hash_u32(i * 0x8da6b343U + 0x5bd1e995U) >> 8) *
                 (2.0f / 16777216.0f) -
             1.0f;
    return t;
  }();
  return kTable.data();
}

struct TextureParams {
  double finest_cell_m = 0.003;  ///< lattice spacing of the finest octave, m
  int octaves = 12;              ///< octave k has lattice spacing finest_cell_m * 2^k
  double fade_in_px = 2.0;       ///< an octave is absent below this many pixels per cell ...
  double full_in_px = 4.0;       ///< ... and at full weight above this (anti-aliasing)
  double fade_out_px = 32.0;     ///< coarse octaves fade out above this many pixels per cell ...
  double gone_px = 64.0;         ///< ... and are absent above this (keeps the cost bounded)
};

/// Texture value in about [-1, 1] (standard deviation about 0.25) at surface point (u, v) in
/// metres, prefiltered for a pixel footprint of `footprint_m` metres: octaves whose cells are
/// smaller than fade_in_px pixels are left out, so far textures blur instead of aliasing.
inline double texture_value(double u, double v, std::uint32_t seed, double footprint_m,
                            const TextureParams& p = TextureParams{}) {
  const auto smooth = [](double a) { return a * a * (3.0 - 2.0 * a); };
  const float* lattice = random_lattice();
  double sum = 0.0;
  double cell = p.finest_cell_m;
  double inv_cell = 1.0 / p.finest_cell_m;
  const double inv_footprint = 1.0 / footprint_m;
  for (int k = 0; k < p.octaves; ++k, cell *= 2.0, inv_cell *= 0.5) {
    const double r = cell * inv_footprint;  // pixels per cell
    if (r <= p.fade_in_px) continue;
    if (r >= p.gone_px) break;
    double w = 1.0;
    if (r < p.full_in_px) w = smooth((r - p.fade_in_px) / (p.full_in_px - p.fade_in_px));
    if (r > p.fade_out_px) w *= 1.0 - smooth((r - p.fade_out_px) / (p.gone_px - p.fade_out_px));
    // Each (seed, octave) reads the shared random lattice at its own offset.
    const std::uint32_t s = hash_u32(seed + static_cast<std::uint32_t>(k) * 0x9e3779b9U);
    const double x = u * inv_cell, y = v * inv_cell;
    // Floor without a library call (std::floor is not inlined without SSE4.1).
    std::int64_t jx = static_cast<std::int64_t>(x), jy = static_cast<std::int64_t>(y);
    jx -= x < static_cast<double>(jx);
    jy -= y < static_cast<double>(jy);
    const auto a = static_cast<float>(smooth(x - static_cast<double>(jx)));
    const auto b = static_cast<float>(smooth(y - static_cast<double>(jy)));
    const std::uint32_t ix = static_cast<std::uint32_t>(jx) + s;
    const std::uint32_t iy = static_cast<std::uint32_t>(jy) + (s >> 16);
    const std::uint32_t r0 = (iy & kLatticeMask) << kLatticeBits;
    const std::uint32_t r1 = ((iy + 1) & kLatticeMask) << kLatticeBits;
    const std::uint32_t c0 = ix & kLatticeMask, c1 = (ix + 1) & kLatticeMask;
    const float n00 = lattice[r0 | c0], n10 = lattice[r0 | c1];
    const float n01 = lattice[r1 | c0], n11 = lattice[r1 | c1];
    const float top = n00 + a * (n10 - n00), bottom = n01 + a * (n11 - n01);
    sum += w * (top + b * (bottom - top));
  }
  // About five octaves are active; their sum has a standard deviation near 0.4 * sqrt(5).
  return sum * (1.0 / 3.6);
}

inline double smoothstep01(double a) {
  a = a < 0.0 ? 0.0 : (a > 1.0 ? 1.0 : a);
  return a * a * (3.0 - 2.0 * a);
}

/// A square wave of `period` m in [-1, 1] at coordinate a, prefiltered for a pixel footprint of
/// `footprint_m`: a sine steepened until its edges span one footprint, fading to its mean (0) as
/// the footprint nears half a period.
inline double soft_square(double a, double period, double footprint_m) {
  constexpr double kTwoPi = 6.283185307179586;
  const double slope = kTwoPi * footprint_m / period;  // the sine's change over one footprint
  double v = std::sin(kTwoPi * a / period) / (slope > 1e-9 ? slope : 1e-9);
  v = v > 1.0 ? 1.0 : (v < -1.0 ? -1.0 : v);
  return v * (1.0 - smoothstep01((footprint_m / period - 0.2) / 0.3));
}

/// texture_value(u[i], v[i], seed[i], footprint_m[i]) with the default TextureParams into out[i]
/// for i in [0, n), bit for bit: a SIMD kernel (Google Highway, dispatched at run time) doing the
/// reference's operations lane by lane in the same order, its file compiled without fused
/// multiply-adds. Octaves a lane leaves out leave its sum untouched, as the reference's loop does.
void texture_values(const double* u, const double* v, const std::uint32_t* seed,
                    const double* footprint_m, int n, double* out);

/// The SIMD target texture_values runs on this machine (e.g. "AVX3").
std::string texture_target();

/// Surface value in about [-1, 1] of a TextureKind (sg/sim/scenario.hpp; passed as its index so
/// that this header stays free of the scenario): 0 noise, 1 low, 2 tiles, 3 stripes, 4 clutter.
/// Sizes (tile side, stripe period and angle, glyph height) follow from the seed. `noise` is
/// texture_value(u, v, seed, footprint_m), taken as an argument so that the noise of many points
/// can be computed at once (texture_values).
inline double pattern_from_noise(int kind, double u, double v, std::uint32_t seed,
                                 double footprint_m, double noise) {
  if (kind == 0) return noise;
  if (kind == 1) return 0.125 * noise;
  const std::uint32_t h = hash_u32(seed ^ 0x51ed270bU);
  const double r1 = (h & 0xffffU) / 65535.0, r2 = (h >> 16) / 65535.0;
  if (kind == 2) {  // tiles: a checkerboard of 0.15..0.6 m squares
    const double side = 0.15 + 0.45 * r1;
    return 0.6 * soft_square(u, 2.0 * side, footprint_m) * soft_square(v, 2.0 * side, footprint_m) +
           0.15 * noise;
  }
  if (kind == 3) {  // stripes: period 0.05..0.3 m at an angle 0..180 deg
    const double period = 0.05 + 0.25 * r1, angle = 3.141592653589793 * r2;
    return 0.6 * soft_square(u * std::cos(angle) + v * std::sin(angle), period, footprint_m) +
           0.15 * noise;
  }
  // clutter: lines of glyphs of 3 x 5 marks, glyph height 0.03..0.1 m, a line every 1.6 heights
  const double glyph_h = 0.03 + 0.07 * r1, glyph_w = 0.6 * glyph_h, line = 1.6 * glyph_h;
  const double mark = glyph_h / 5.0;
  const double weight = 1.0 - smoothstep01(footprint_m / mark - 0.5);
  constexpr double kMean = 0.2;  // the mean of paper and ink, where the marks fade out
  if (weight <= 0.0) return kMean + 0.15 * noise;
  const double cu = std::floor(u / glyph_w), cv = std::floor(v / line);
  const double fu = u / glyph_w - cu, fv = (v / line - cv) * 1.6;  // fv in glyph heights
  double value = 0.4;                                               // paper
  if (fv < 1.0) {
    const std::uint32_t g = hash_combine(
        hash_combine(seed, static_cast<std::uint32_t>(static_cast<std::int64_t>(cu))),
        static_cast<std::uint32_t>(static_cast<std::int64_t>(cv)));
    const int col = static_cast<int>(fu * 4.0), row = static_cast<int>(fv * 5.0);
    // Columns 0..2 carry marks, column 3 is the gap between glyphs; one glyph in six is a space.
    if (col < 3 && g % 6U != 0U && ((g >> (1 + row * 3 + col)) & 1U)) value = -0.6;  // ink
  }
  return kMean + weight * (value - kMean) + 0.15 * noise;
}

}  // namespace sg::sim
