#pragma once
/// Ray caster for scenarios: left and right 8-bit images plus per-frame ground truth.
#include "sg/core/frame.hpp"
#include "sg/core/ground_truth.hpp"
#include "sg/core/source.hpp"
#include "sg/sim/scenario.hpp"

namespace sg::sim {

struct RenderedFrame {
  core::StereoFrame frame;  ///< left/right CV_8UC1, time_s = index / fps
  /// disparity, backward flow (empty for frame 0), danger, ids; with TruthMapSet::kDangerOnly
  /// danger and ids only
  core::TruthMaps maps;
  core::FrameTruth truth;
};

/// The truth maps Renderer::render produces: all of them, or only what a detection's scoring
/// needs (danger and ids; disparity and flow are left empty, which saves their per-pixel work).
enum class TruthMapSet { kAll, kDangerOnly };

/// Ground-truth collision test of one box at time t_s (DESIGN 4), relative to the moving camera
/// with constant relative velocity V = box_velocity(t_s) - ego_velocity (a box that accelerates
/// is extrapolated at its current velocity, as a TTC is defined): with Z_near the depth of the box's
/// nearest face, t_c = (Z_near - z_contact) / (-V_z) when V_z < 0; the box collides when
/// 0 < t_c <= horizon and at t_c its X extent overlaps [-half_width, half_width] and its Y extent
/// overlaps [y_top, y_bottom]. A box already at the contact depth (Z_near <= z_contact, Z_far >= 0)
/// that overlaps the envelope now collides with TTC 0. ttc_s is set only when colliding.
/// With a turning camera (camera_motion.rotates()) the test runs in the camera frame: the future
/// is stepped every 1 ms up to the horizon (box at its current velocity, camera on its path and
/// rotation), and the first instant where the box's bounds in that instant's camera frame reach
/// the contact depth (Z_near <= z_contact, Z_far >= 0) while overlapping the envelope's X and Y
/// extents is the contact; a camera turning in place thus never collides with what it does not
/// already touch.
core::ObstacleTruth box_collision(const Scenario& s, const Box& box, double t_s);

/// The frames of `s` up to and including the first at which an obstacle touches the platform
/// (box_collision colliding with TTC 0), else s.frames; at least 2.
int frames_to_first_contact(const Scenario& s);

/// Pure function of (scenario, frame index): rendering frame i never depends on other frames.
/// Pixel (x, y) looks along R(t) ((x - cx) / f, (y - cy) / f, 1) (R = camera_rotation); its gray
/// level is that ray's shade, or, where the surface it hits differs from a 4-neighbour's, the mean
/// of Scenario::edge_samples^2 rays over the pixel's area (the ground-truth maps stay those of
/// the centre ray). The left
/// camera sits at ego_velocity * t, the right one baseline_m further along the camera's X axis.
/// GT disparity = f B / Z with Z the depth in the camera frame; GT backward flow = the pixel of the
/// same surface point in the previous frame's camera (its pose and rotation then). Rows are rendered with
/// cv::parallel_for_; the output does not depend on the thread count.
class Renderer {
 public:
  /// Throws core::InputError when validate(scenario) finds problems.
  explicit Renderer(Scenario scenario);
  /// Images and ground truth of frame `index` (0 <= index < frames), t = index / fps. The
  /// images do not depend on `maps`.
  RenderedFrame render(int index, TruthMapSet maps = TruthMapSet::kAll) const;
  /// Only the FrameTruth of frame `index` (ray casting without shading; several times faster).
  core::FrameTruth truth(int index) const;
  const Scenario& scenario() const { return scenario_; }

 private:
  Scenario scenario_;
};

/// A FrameSource that renders a scenario on the fly; keeps the truth of the last frame.
class ScenarioSource : public core::FrameSource {
 public:
  explicit ScenarioSource(Scenario scenario);
  std::optional<core::StereoFrame> next() override;
  /// The frame's index and time stamp now, its rendering in PendingFrame::load (load_where_read:
  /// the rendering is parallel), so that a paced run skips a frame it drops without rendering it.
  /// last_truth() and last_maps() follow next() only.
  std::optional<core::PendingFrame> next_pending() override;
  const core::Camera& camera() const override;
  int size() const override;
  /// Ground truth of the frame last returned by next().
  const core::FrameTruth& last_truth() const { return last_.truth; }
  /// The scenario rendered.
  const Scenario& scenario() const { return renderer_.scenario(); }
  /// Truth maps of the frame last returned by next(): danger and ids only (TruthMapSet).
  const core::TruthMaps& last_maps() const { return last_.maps; }

 private:
  Renderer renderer_;
  int next_index_ = 0;
  RenderedFrame last_;
};

}  // namespace sg::sim
