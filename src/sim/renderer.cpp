#include "sg/sim/renderer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "sg/core/error.hpp"
#include "sg/sim/motion_blur.hpp"
#include "sg/sim/texture.hpp"

namespace sg::sim {
namespace {

constexpr double kSkyGray = 200.0;       // rays that hit nothing
constexpr double kContrast = 160.0;      // gray levels per unit of texture_value (std about 40)
constexpr double kGroundStretchZ = 2.5;  // ground texture is stretched along Z (less blur far off)
constexpr double kMinHitDepth = 1e-6;    // m; hits closer than this are ignored
constexpr double kInf = std::numeric_limits<double>::infinity();

enum class Surface : std::uint8_t { kSky, kGround, kWall, kBox };

/// A box at the frame time, in world coordinates.
struct BoxNow {
  cv::Vec3d lo, hi, centre;
  cv::Vec3d shift_prev;  // centre one frame earlier minus centre now, m
  int id = 0;
  std::uint32_t seed = 0;
  int texture = 0;  // TextureKind as an index
  double albedo = 0.0;
};

/// A shadow caster at the frame time.
struct CasterNow {
  cv::Vec3d centre;
  double radius = 0.0, darkness = 0.0;
};

/// Everything the ray caster needs for one frame.
struct Scene {
  double f = 0, cx = 0, cy = 0, baseline = 0, dt = 0;
  cv::Vec3d eye;       // left camera at the frame time
  cv::Vec3d eye_prev;  // left camera one frame earlier
  cv::Matx33d rot = cv::Matx33d::eye();       // camera-to-world rotation at the frame time
  cv::Matx33d rot_prev = cv::Matx33d::eye();  // ... one frame earlier
  double ground_y = 0, wall_z = 0, wall_top_y = 0;
  std::uint32_t ground_seed = 0, wall_seed = 0;
  int ground_texture = 0, wall_texture = 0;  // TextureKind as an index
  double ground_albedo = 0, wall_albedo = 0;
  std::vector<BoxNow> boxes;
  cv::Vec3d to_light;  // unit
  std::vector<CasterNow> casters;
};

struct Hit {
  double depth = kInf;  // ray parameter of R (dx, dy, 1) = depth in the camera, m
  Surface surface = Surface::kSky;
  int box = -1;   // index into Scene::boxes
  int axis = 2;   // normal axis (world) of the face hit
  int side = 0;   // 0 = the face at the low coordinate, 1 = the high one
};

/// Base gray level of a surface, from its seed.
double albedo_of(std::uint32_t seed) { return 90.0 + static_cast<double>(hash_u32(seed) % 80U); }

Scene make_scene(const Scenario& s, int index) {
  Scene sc;
  const double t = index / s.camera.fps;
  sc.f = s.camera.focal_px;
  sc.cx = s.camera.cx;
  sc.cy = s.camera.cy;
  sc.baseline = s.camera.baseline_m;
  sc.dt = 1.0 / s.camera.fps;
  sc.eye = ego_position(s, t);
  sc.eye_prev = ego_position(s, t - sc.dt);
  sc.rot = camera_rotation(s.camera_motion, t);
  sc.rot_prev = camera_rotation(s.camera_motion, t - sc.dt);
  sc.ground_y = s.height_m;
  sc.wall_z = s.background_z_m;
  sc.wall_top_y = s.height_m - s.background_height_m;
  sc.ground_seed = s.ground_seed;
  sc.wall_seed = s.background_seed;
  sc.ground_texture = static_cast<int>(s.ground_texture);
  sc.wall_texture = static_cast<int>(s.background_texture);
  sc.ground_albedo = albedo_of(s.ground_seed);
  sc.wall_albedo = albedo_of(s.background_seed);
  for (const Box& b : s.obstacles) {
    BoxNow n;
    n.centre = box_position(b, t);
    n.lo = n.centre - b.size_m * 0.5;
    n.hi = n.centre + b.size_m * 0.5;
    n.shift_prev = box_position(b, t - sc.dt) - n.centre;
    n.id = b.id;
    n.seed = b.texture_seed;
    n.texture = static_cast<int>(b.texture);
    n.albedo = albedo_of(b.texture_seed);
    sc.boxes.push_back(n);
  }
  sc.to_light = cv::normalize(s.shadows.to_light);
  for (const ShadowCaster& c : s.shadows.casters)
    sc.casters.push_back({c.position_m + c.velocity_mps * t, c.radius_m, c.darkness});
  return sc;
}

double safe_component(double v) {
  constexpr double kTiny = 1e-12;
  return std::abs(v) < kTiny ? (v < 0 ? -kTiny : kTiny) : v;
}

/// Nearest surface along o + s * dir, s > 0 (dir = R (dx, dy, 1), world frame).
Hit cast(const Scene& sc, const cv::Vec3d& o, const cv::Vec3d& dir) {
  Hit hit;
  if (dir[1] > 0) {
    const double s = (sc.ground_y - o[1]) / dir[1];
    if (s > kMinHitDepth) {
      hit.depth = s;
      hit.surface = Surface::kGround;
      hit.axis = 1;
    }
  }
  if (dir[2] > 0) {
    const double s = (sc.wall_z - o[2]) / dir[2];
    if (s > kMinHitDepth && s < hit.depth && o[1] + s * dir[1] >= sc.wall_top_y) {
      hit.depth = s;
      hit.surface = Surface::kWall;
      hit.axis = 2;
    }
  }
  if (sc.boxes.empty()) return hit;
  const double inv[3] = {1.0 / safe_component(dir[0]), 1.0 / safe_component(dir[1]),
                         1.0 / safe_component(dir[2])};
  for (std::size_t i = 0; i < sc.boxes.size(); ++i) {
    const BoxNow& b = sc.boxes[i];
    double t_near = -kInf, t_far = kInf;
    int axis = 0, side = 0;
    for (int a = 0; a < 3; ++a) {
      double t1 = (b.lo[a] - o[a]) * inv[a];
      double t2 = (b.hi[a] - o[a]) * inv[a];
      int entry_side = 0;
      if (t1 > t2) {
        std::swap(t1, t2);
        entry_side = 1;
      }
      if (t1 > t_near) {
        t_near = t1;
        axis = a;
        side = entry_side;
      }
      t_far = std::min(t_far, t2);
    }
    if (t_near <= t_far && t_near > kMinHitDepth && t_near < hit.depth) {
      hit.depth = t_near;
      hit.surface = Surface::kBox;
      hit.box = static_cast<int>(i);
      hit.axis = axis;
      hit.side = side;
    }
  }
  return hit;
}

/// Size in texture units of the pixel footprint on a face with (world) normal `axis`, whose
/// texture runs along u_axis (1 unit a metre) and v_axis (v_scale m a unit), using ray
/// differentials of the direction dir = R (dx, dy, 1) at depth `depth`.
double footprint(const Scene& sc, int axis, double depth, const cv::Vec3d& dir, int u_axis,
                 int v_axis, double v_scale) {
  // d dir / d dx and d dir / d dy (R's first two columns) moved along the ray onto the face's
  // plane; only their components along the texture's axes count.
  const double inv = 1.0 / safe_component(dir[axis]);
  const double kx = sc.rot(axis, 0) * inv, ky = sc.rot(axis, 1) * inv;
  const double fu = std::max(std::abs(sc.rot(u_axis, 0) - dir[u_axis] * kx),
                             std::abs(sc.rot(u_axis, 1) - dir[u_axis] * ky));
  const double fv = std::max(std::abs(sc.rot(v_axis, 0) - dir[v_axis] * kx),
                             std::abs(sc.rot(v_axis, 1) - dir[v_axis] * ky)) /
                    v_scale;
  return depth / sc.f * std::max(fu, fv);
}

/// Share of the light reaching surface point p: 1 - darkness inside a caster's umbra, 1 outside
/// its penumbra (0.85..1.15 of its radius from the ray towards the light), smooth between.
double lit(const Scene& sc, const cv::Vec3d& p) {
  double light = 1.0;
  for (const CasterNow& c : sc.casters) {
    const cv::Vec3d w = c.centre - p;
    const double along = w.dot(sc.to_light);
    if (along <= 0.0) continue;  // the caster is not between p and the light
    const double dist = std::sqrt(std::max(0.0, w.dot(w) - along * along));
    const double inside = 1.0 - smoothstep01((dist / c.radius - 0.85) / 0.3);
    light *= 1.0 - c.darkness * inside;
  }
  return light;
}

/// What the gray level of a hit needs besides its texture's noise: light (base + kContrast
/// pattern_from_noise(kind, u, v, seed, footprint, noise)), or the sky's gray.
struct SurfacePoint {
  bool sky = true;
  int kind = 0;  // TextureKind as an index
  std::uint32_t seed = 0;
  double u = 0.0, v = 0.0;  // texture coordinates, m
  double footprint = 0.0;   // the pixel's footprint in texture units
  double base = 0.0;        // albedo (times the face's shade on a box)
  double light = 1.0;       // share of the light reaching the point (lit)
};

/// The surface point hit by the ray from o, with what shading it needs, into s (written in place:
/// a returned copy of the struct costs a store-forwarding stall per pixel).
void surface_point(const Scene& sc, const Hit& hit, const cv::Vec3d& o, const cv::Vec3d& dir,
                   SurfacePoint& s) {
  s.sky = hit.surface == Surface::kSky;
  if (s.sky) return;
  const cv::Vec3d p = o + dir * hit.depth;
  s.light = sc.casters.empty() ? 1.0 : lit(sc, p);
  if (hit.surface == Surface::kGround) {
    s.footprint = footprint(sc, 1, hit.depth, dir, 0, 2, kGroundStretchZ);
    s.kind = sc.ground_texture;
    s.seed = sc.ground_seed;
    s.u = p[0];
    s.v = p[2] / kGroundStretchZ;
    s.base = sc.ground_albedo;
    return;
  }
  if (hit.surface == Surface::kWall) {
    s.footprint = footprint(sc, 2, hit.depth, dir, 0, 1, 1.0);
    s.kind = sc.wall_texture;
    s.seed = sc.wall_seed;
    s.u = p[0];
    s.v = p[1];
    s.base = sc.wall_albedo;
    return;
  }
  const BoxNow& b = sc.boxes[static_cast<std::size_t>(hit.box)];
  const cv::Vec3d local = p - b.centre;
  // Texture axes of each face: X faces use (Z, Y), Y faces (X, Z), Z faces (X, Y).
  static constexpr int kU[3] = {2, 0, 0};
  static constexpr int kV[3] = {1, 2, 1};
  static constexpr double kFaceShade[3] = {0.8, 1.15, 1.0};
  const int u = kU[hit.axis], v = kV[hit.axis];
  s.footprint = footprint(sc, hit.axis, hit.depth, dir, u, v, 1.0);
  s.kind = b.texture;
  s.seed = hash_combine(b.seed, static_cast<std::uint32_t>(hit.axis * 2 + hit.side));
  s.u = local[u];
  s.v = local[v];
  s.base = b.albedo * kFaceShade[hit.axis];
}

/// Gray level (before noise and gain) of a surface point whose texture noise is `noise`.
double shade_point(const SurfacePoint& s, double noise) {
  if (s.sky) return kSkyGray;
  return s.light *
         (s.base + kContrast * pattern_from_noise(s.kind, s.u, s.v, s.seed, s.footprint, noise));
}

/// Identity of the surface a ray hit (sky, ground, wall, or one face of one box): where it
/// differs between neighbouring pixels, a silhouette or a fold runs between them.
std::int32_t surface_code(const Hit& hit) {
  if (hit.surface != Surface::kBox) return static_cast<std::int32_t>(hit.surface);
  return 4 + (hit.box * 3 + hit.axis) * 2 + hit.side;
}

/// Outputs of render_rows; null members are not produced.
struct RowTargets {
  cv::Mat* gray = nullptr;         // CV_8UC1
  const cv::Mat* noise = nullptr;  // CV_32F, may be null
  double gain = 1.0;
  int edge_samples = 1;          // Scenario::edge_samples
  cv::Mat* disparity = nullptr;  // CV_32F
  cv::Mat* flow = nullptr;       // CV_32FC2
  cv::Mat* ids = nullptr;        // CV_16U
  // Scratch of the gray image between the two passes: the centre ray's shade and surface.
  cv::Mat* shade = nullptr;  // CV_32F
  cv::Mat* code = nullptr;   // CV_32S
};

/// Surface points shaded together: the gray level (before noise and gain) of each, shade_point
/// with the textures of all at once (texture_values, equal to texture_value bit for bit).
struct ShadingBatch {
  std::vector<SurfacePoint> points;
  std::vector<double> shades;  // shade_all's output, one per point

  /// shades[i] = shade_point(points[i], texture_value of it) for every point.
  void shade_all() {
    const std::size_t m = points.size();
    u_.resize(m);
    v_.resize(m);
    footprint_.resize(m);
    seed_.resize(m);
    noise_.resize(m);
    shades.resize(m);
    int n = 0;
    for (const SurfacePoint& s : points) {
      if (s.sky) continue;
      u_[n] = s.u;
      v_[n] = s.v;
      footprint_[n] = s.footprint;
      seed_[n] = s.seed;
      ++n;
    }
    texture_values(u_.data(), v_.data(), seed_.data(), footprint_.data(), n, noise_.data());
    int k = 0;
    for (std::size_t i = 0; i < m; ++i)
      shades[i] = shade_point(points[i], points[i].sky ? 0.0 : noise_[k++]);
  }

 private:
  std::vector<double> u_, v_, footprint_, noise_;
  std::vector<std::uint32_t> seed_;
};

/// Renders rows [rows.start, rows.end) of the camera at `eye` with one ray through each pixel's
/// centre; for the gray image only its shade and surface (integrate_rows finishes it). Each pixel
/// depends only on its own ray, so any split into row ranges gives the same images.
void render_rows(const Scene& sc, const cv::Vec3d& eye, const cv::Vec3d& eye_prev,
                 const RowTargets& out, cv::Range rows, int width) {
  ShadingBatch shading;
  shading.points.resize(out.shade ? static_cast<std::size_t>(width) : 0);
  for (int y = rows.start; y < rows.end; ++y) {
    const double dy = (y - sc.cy) / sc.f;
    auto* shade_row = out.shade ? out.shade->ptr<float>(y) : nullptr;
    auto* code_row = out.code ? out.code->ptr<std::int32_t>(y) : nullptr;
    auto* disp = out.disparity ? out.disparity->ptr<float>(y) : nullptr;
    auto* flow = out.flow ? out.flow->ptr<cv::Vec2f>(y) : nullptr;
    auto* ids = out.ids ? out.ids->ptr<std::uint16_t>(y) : nullptr;
    for (int x = 0; x < width; ++x) {
      const double dx = (x - sc.cx) / sc.f;
      const cv::Vec3d dir = sc.rot * cv::Vec3d(dx, dy, 1.0);
      const Hit hit = cast(sc, eye, dir);
      if (shade_row) {
        surface_point(sc, hit, eye, dir, shading.points[static_cast<std::size_t>(x)]);
        code_row[x] = surface_code(hit);
      }
      const bool is_box = hit.surface == Surface::kBox;
      if (ids) ids[x] = is_box ? static_cast<std::uint16_t>(sc.boxes[hit.box].id) : 0;
      if (disp) {
        disp[x] = hit.surface == Surface::kSky
                      ? 0.0f
                      : static_cast<float>(sc.f * sc.baseline / hit.depth);
      }
      if (flow) {
        cv::Vec2f q(0.0f, 0.0f);
        if (hit.surface == Surface::kSky) {
          // At infinity only the rotation moves the sky: the same direction a frame earlier.
          const cv::Vec3d rel = sc.rot_prev.t() * dir;
          if (rel[2] > kMinHitDepth) {
            q[0] = static_cast<float>(sc.cx + sc.f * rel[0] / rel[2] - x);
            q[1] = static_cast<float>(sc.cy + sc.f * rel[1] / rel[2] - y);
          }
        } else {
          // The same surface point one frame earlier, seen from the camera one frame earlier.
          cv::Vec3d p = eye + dir * hit.depth;
          if (is_box) p += sc.boxes[hit.box].shift_prev;
          const cv::Vec3d rel = sc.rot_prev.t() * (p - eye_prev);
          if (rel[2] > kMinHitDepth) {
            q[0] = static_cast<float>(sc.cx + sc.f * rel[0] / rel[2] - x);
            q[1] = static_cast<float>(sc.cy + sc.f * rel[1] / rel[2] - y);
          }
        }
        flow[x] = q;
      }
    }
    if (shade_row) {
      shading.shade_all();
      for (int x = 0; x < width; ++x)
        shade_row[x] = static_cast<float>(shading.shades[static_cast<std::size_t>(x)]);
    }
  }
}

/// The gray rows [rows.start, rows.end) from render_rows' shades, as a pixel integrates light:
/// where the centre ray's surface differs from a 4-neighbour's, the pixel's shade is the mean of
/// edge_samples^2 rays on a regular grid over its area; elsewhere the centre ray's. Then gain and
/// noise.
void integrate_rows(const Scene& sc, const cv::Vec3d& eye, const RowTargets& out,
                    cv::Range rows) {
  const cv::Mat& code = *out.code;
  const int n = out.edge_samples, w = code.cols, h = code.rows;
  ShadingBatch samples;      // the rays of the row's edge pixels, n^2 each, in pixel order
  std::vector<char> edge(static_cast<std::size_t>(w));
  for (int y = rows.start; y < rows.end; ++y) {
    const auto* c = code.ptr<std::int32_t>(y);
    const auto* above = y > 0 ? code.ptr<std::int32_t>(y - 1) : c;
    const auto* below = y + 1 < h ? code.ptr<std::int32_t>(y + 1) : c;
    const auto* shade_row = out.shade->ptr<float>(y);
    const auto* noise = out.noise ? out.noise->ptr<float>(y) : nullptr;
    auto* gray = out.gray->ptr<std::uint8_t>(y);
    samples.points.clear();
    for (int x = 0; x < w; ++x) {
      edge[x] = n > 1 && ((x > 0 && c[x - 1] != c[x]) || (x + 1 < w && c[x + 1] != c[x]) ||
                          above[x] != c[x] || below[x] != c[x]);
      if (!edge[x]) continue;
      for (int j = 0; j < n; ++j) {
        const double dy = (y - 0.5 + (j + 0.5) / n - sc.cy) / sc.f;
        for (int i = 0; i < n; ++i) {
          const double dx = (x - 0.5 + (i + 0.5) / n - sc.cx) / sc.f;
          const cv::Vec3d dir = sc.rot * cv::Vec3d(dx, dy, 1.0);
          surface_point(sc, cast(sc, eye, dir), eye, dir, samples.points.emplace_back());
        }
      }
    }
    samples.shade_all();
    const double* sample = samples.shades.data();
    for (int x = 0; x < w; ++x) {
      double value = shade_row[x];
      if (edge[x]) {
        double sum = 0.0;
        for (int k = 0; k < n * n; ++k) sum += *sample++;
        value = sum / (n * n);
      }
      value *= out.gain;
      if (noise) value += noise[x];
      gray[x] = cv::saturate_cast<std::uint8_t>(value);
    }
  }
}

/// Renders the camera at `eye` (one frame earlier at `eye_prev`, for the flow).
void render_parallel(const Scene& sc, const cv::Vec3d& eye, const cv::Vec3d& eye_prev,
                     RowTargets out, int width, int height) {
  cv::Mat shade, code;
  if (out.gray) {
    shade.create(height, width, CV_32FC1);
    code.create(height, width, CV_32SC1);
    out.shade = &shade;
    out.code = &code;
  }
  cv::parallel_for_(cv::Range(0, height),
                    [&](const cv::Range& r) { render_rows(sc, eye, eye_prev, out, r, width); });
  if (out.gray)
    cv::parallel_for_(cv::Range(0, height),
                      [&](const cv::Range& r) { integrate_rows(sc, eye, out, r); });
}

/// Per-obstacle truth from the ids map; fills danger when given.
core::FrameTruth frame_truth(const Scenario& s, int index, const cv::Mat& ids, cv::Mat* danger) {
  core::FrameTruth truth;
  truth.frame = index;
  const double t = index / s.camera.fps;
  int max_id = 0;
  for (const Box& b : s.obstacles) max_id = std::max(max_id, b.id);
  std::vector<int> count(static_cast<std::size_t>(max_id) + 1, 0);
  for (int y = 0; y < ids.rows; ++y) {
    const auto* row = ids.ptr<std::uint16_t>(y);
    for (int x = 0; x < ids.cols; ++x)
      if (row[x] != 0) ++count[row[x]];
  }
  std::vector<std::uint8_t> lut(count.size(), 0);
  for (const Box& b : s.obstacles) {
    core::ObstacleTruth o = box_collision(s, b, t);
    o.pixels = count[static_cast<std::size_t>(b.id)];
    if (o.colliding) {
      lut[static_cast<std::size_t>(b.id)] = 255;
      if (o.pixels >= s.min_area_px && o.pixels > 0) truth.alarm = true;
    }
    truth.obstacles.push_back(o);
  }
  if (danger) {
    danger->create(ids.size(), CV_8UC1);
    for (int y = 0; y < ids.rows; ++y) {
      const auto* row = ids.ptr<std::uint16_t>(y);
      auto* out = danger->ptr<std::uint8_t>(y);
      for (int x = 0; x < ids.cols; ++x) out[x] = lut[row[x]];
    }
  }
  return truth;
}

void check_index(const Scenario& s, int index) {
  if (index < 0 || index >= s.frames)
    throw std::out_of_range("frame " + std::to_string(index) + " outside scenario '" + s.name +
                            "' (0.." + std::to_string(s.frames - 1) + ")");
}

/// Exposure gain at time t_s: that of the last step started, else 1.
double exposure_gain(const ImageEffects& fx, double t_s) {
  double gain = 1.0;
  for (const ExposureStep& step : fx.exposure_steps)
    if (step.from_s <= t_s) gain = step.gain;
  return gain;
}

/// Applies Scenario::effects to one rendered pair (see ImageEffects for the order).
void apply_effects(const ImageEffects& fx, double t_s, cv::Mat& left, cv::Mat& right) {
  const double gain = exposure_gain(fx, t_s);
  if (gain != 1.0 || fx.vignetting != 0.0) {
    cv::Mat factor(left.size(), CV_32FC1);
    const double cx = 0.5 * (left.cols - 1), cy = 0.5 * (left.rows - 1);
    const double corner2 = cx * cx + cy * cy;
    for (int y = 0; y < factor.rows; ++y) {
      auto* row = factor.ptr<float>(y);
      for (int x = 0; x < factor.cols; ++x) {
        const double r2 = ((x - cx) * (x - cx) + (y - cy) * (y - cy)) / corner2;
        row[x] = static_cast<float>(gain * (1.0 - fx.vignetting * r2));
      }
    }
    for (cv::Mat* image : {&left, &right}) {
      cv::Mat value;
      image->convertTo(value, CV_32FC1);
      cv::multiply(value, factor, value);
      value.convertTo(*image, CV_8UC1);  // rounds and saturates
    }
  }
  if (fx.right_shift_y_px != 0.0) {
    const cv::Matx23d shift(1, 0, 0, 0, 1, fx.right_shift_y_px);
    cv::Mat moved;
    cv::warpAffine(right, moved, shift, right.size(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
    right = moved;
  }
  if (fx.jpeg_quality > 0) {
    const std::vector<int> quality = {cv::IMWRITE_JPEG_QUALITY, fx.jpeg_quality};
    for (cv::Mat* image : {&left, &right}) {
      std::vector<std::uint8_t> bytes;
      cv::imencode(".jpg", *image, bytes, quality);
      *image = cv::imdecode(bytes, cv::IMREAD_GRAYSCALE);
    }
  }
}

}  // namespace

namespace {

/// Whether `box` (at its time-t_s velocity) touches the envelope tau seconds after t_s, seen from
/// the camera on its path at its current speed and rotated as then (ego accelerations are not
/// foreseen, as the box's are not): its bounds in that instant's camera frame reach the contact
/// depth (Z_near <= z_contact, Z_far >= 0) while overlapping the envelope's X and Y extents.
bool touches_rotated(const Scenario& s, const Box& box, double t_s, double tau) {
  const core::Envelope& e = s.envelope;
  const cv::Matx33d to_camera = camera_rotation(s.camera_motion, t_s + tau).t();
  const cv::Vec3d eye = ego_coasting_position(s, t_s, tau);
  const cv::Vec3d c = box_position(box, t_s) + box_velocity(box, t_s) * tau;
  const cv::Vec3d half = box.size_m * 0.5;
  cv::Vec3d lo(kInf, kInf, kInf), hi(-kInf, -kInf, -kInf);
  for (int k = 0; k < 8; ++k) {
    const cv::Vec3d corner(c[0] + ((k & 1) ? half[0] : -half[0]),
                           c[1] + ((k & 2) ? half[1] : -half[1]),
                           c[2] + ((k & 4) ? half[2] : -half[2]));
    const cv::Vec3d q = to_camera * (corner - eye);
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], q[a]);
      hi[a] = std::max(hi[a], q[a]);
    }
  }
  return lo[2] <= e.z_contact_m && hi[2] >= 0.0 && hi[0] >= -e.half_width_m &&
         lo[0] <= e.half_width_m && hi[1] >= e.y_top_m && lo[1] <= e.y_bottom_m;
}

/// box_collision for a rotating camera: steps the future and checks the box's bounds in the
/// camera frame of each instant (touches_rotated).
core::ObstacleTruth turning_collision(const Scenario& s, const Box& box, double t_s) {
  constexpr double kStep = 1e-3;  // s
  core::ObstacleTruth o;
  o.id = box.id;
  const double horizon = s.envelope.horizon_s;
  const int steps = static_cast<int>(std::ceil(horizon / kStep));
  for (int i = 0; i <= steps; ++i) {
    const double tau = std::min(i * kStep, horizon);
    if (touches_rotated(s, box, t_s, tau)) {
      o.colliding = true;
      o.ttc_s = tau;
      return o;
    }
  }
  return o;
}

/// Whether `box` touches the platform at t_s: box_collision's verdict "colliding, TTC 0", without
/// stepping the future.
bool touches(const Scenario& s, const Box& box, double t_s) {
  if (s.camera_motion.rotates()) return touches_rotated(s, box, t_s, 0.0);
  const core::ObstacleTruth o = box_collision(s, box, t_s);
  return o.colliding && o.ttc_s && *o.ttc_s <= 0.0;
}

}  // namespace

core::ObstacleTruth box_collision(const Scenario& s, const Box& box, double t_s) {
  if (s.camera_motion.rotates()) return turning_collision(s, box, t_s);
  core::ObstacleTruth o;
  o.id = box.id;
  const core::Envelope& e = s.envelope;
  const cv::Vec3d rel = box_position(box, t_s) - ego_position(s, t_s);
  const cv::Vec3d v = box_velocity(box, t_s) - ego_velocity(s, t_s);
  const cv::Vec3d half = box.size_m * 0.5;
  const auto overlaps_at = [&](double dt) {
    const cv::Vec3d c = rel + v * dt;
    return c[0] + half[0] >= -e.half_width_m && c[0] - half[0] <= e.half_width_m &&
           c[1] + half[1] >= e.y_top_m && c[1] - half[1] <= e.y_bottom_m;
  };
  const double z_near = rel[2] - half[2];
  const double z_far = rel[2] + half[2];
  if (z_near <= e.z_contact_m) {
    // Already at the contact depth: colliding only if it is in the envelope now.
    if (z_far >= 0.0 && overlaps_at(0.0)) {
      o.colliding = true;
      o.ttc_s = 0.0;
    }
    return o;
  }
  if (v[2] >= 0.0) return o;
  const double t_c = (z_near - e.z_contact_m) / (-v[2]);
  if (t_c <= e.horizon_s && overlaps_at(t_c)) {
    o.colliding = true;
    o.ttc_s = t_c;
  }
  return o;
}

int frames_to_first_contact(const Scenario& s) {
  for (int i = 0; i < s.frames; ++i)
    for (const Box& b : s.obstacles) {
      if (touches(s, b, i / s.camera.fps)) return std::max(2, i + 1);
    }
  return s.frames;
}

Renderer::Renderer(Scenario scenario) : scenario_(std::move(scenario)) {
  core::throw_if_invalid(validate(scenario_), "invalid scenario '" + scenario_.name + "'");
}

RenderedFrame Renderer::render(int index, TruthMapSet maps) const {
  check_index(scenario_, index);
  const Scenario& s = scenario_;
  const int w = s.camera.width, h = s.camera.height;
  const Scene sc = make_scene(s, index);
  const bool all_maps = maps == TruthMapSet::kAll;

  RenderedFrame r;
  r.frame.index = index;
  r.frame.time_s = index / s.camera.fps;
  r.frame.left.create(h, w, CV_8UC1);
  r.frame.right.create(h, w, CV_8UC1);
  if (all_maps) r.maps.disparity.create(h, w, CV_32FC1);
  r.maps.ids.create(h, w, CV_16UC1);
  if (index > 0 && all_maps) r.maps.flow.create(h, w, CV_32FC2);
  // Motion blur needs each camera's own image motion, frame 0's too.
  const bool blur = s.effects.exposure_time_s > 0.0;
  cv::Mat left_flow = r.maps.flow, right_flow;
  if (blur) {
    if (left_flow.empty()) left_flow.create(h, w, CV_32FC2);
    right_flow.create(h, w, CV_32FC2);
  }

  // Noise is drawn serially from one generator per (seed, frame, side): thread-count independent.
  cv::Mat noise[2];
  if (s.noise_sigma > 0) {
    for (int side = 0; side < 2; ++side) {
      const std::uint32_t key = hash_combine(hash_combine(s.noise_seed, static_cast<std::uint32_t>(index)),
                                             static_cast<std::uint32_t>(side));
      cv::RNG rng((static_cast<std::uint64_t>(key) << 32) | hash_u32(key + 1U));
      noise[side].create(h, w, CV_32FC1);
      rng.fill(noise[side], cv::RNG::NORMAL, 0.0, s.noise_sigma);
    }
  }

  RowTargets left;
  left.gray = &r.frame.left;
  left.noise = noise[0].empty() || blur ? nullptr : &noise[0];
  left.edge_samples = s.edge_samples;
  left.disparity = all_maps ? &r.maps.disparity : nullptr;
  left.flow = left_flow.empty() ? nullptr : &left_flow;
  left.ids = &r.maps.ids;
  render_parallel(sc, sc.eye, sc.eye_prev, left, w, h);

  RowTargets right;
  right.gray = &r.frame.right;
  right.noise = noise[1].empty() || blur ? nullptr : &noise[1];
  right.gain = s.right_gain;
  right.edge_samples = s.edge_samples;
  right.flow = blur ? &right_flow : nullptr;
  const cv::Vec3d baseline(s.camera.baseline_m, 0, 0);
  render_parallel(sc, sc.eye + sc.rot * baseline, sc.eye_prev + sc.rot_prev * baseline, right, w,
                  h);
  if (blur) {
    const double share = s.effects.exposure_time_s * s.camera.fps;
    motion_blur(r.frame.left, left_flow, share, noise[0]);
    motion_blur(r.frame.right, right_flow, share, noise[1]);
  }

  if (s.effects.any()) apply_effects(s.effects, r.frame.time_s, r.frame.left, r.frame.right);
  r.truth = frame_truth(s, index, r.maps.ids, &r.maps.danger);
  return r;
}

core::FrameTruth Renderer::truth(int index) const {
  check_index(scenario_, index);
  const Scene sc = make_scene(scenario_, index);
  cv::Mat ids(scenario_.camera.height, scenario_.camera.width, CV_16UC1);
  RowTargets out;
  out.ids = &ids;
  render_parallel(sc, sc.eye, sc.eye_prev, out, ids.cols, ids.rows);
  return frame_truth(scenario_, index, ids, nullptr);
}

ScenarioSource::ScenarioSource(Scenario scenario) : renderer_(std::move(scenario)) {}

std::optional<core::StereoFrame> ScenarioSource::next() {
  if (next_index_ >= renderer_.scenario().frames) return std::nullopt;
  last_ = renderer_.render(next_index_++, TruthMapSet::kDangerOnly);
  return last_.frame;
}

std::optional<core::PendingFrame> ScenarioSource::next_pending() {
  if (next_index_ >= renderer_.scenario().frames) return std::nullopt;
  const int index = next_index_++;
  core::PendingFrame pending;
  pending.index = index;
  pending.time_s = index / renderer_.scenario().camera.fps;  // as render() stamps it
  const Renderer* renderer = &renderer_;
  pending.load = [renderer, index] {
    return renderer->render(index, TruthMapSet::kDangerOnly).frame;
  };
  pending.load_where_read = true;
  return pending;
}

const core::Camera& ScenarioSource::camera() const { return renderer_.scenario().camera; }

int ScenarioSource::size() const { return renderer_.scenario().frames; }

}  // namespace sg::sim
