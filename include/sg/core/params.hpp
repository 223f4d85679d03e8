#pragma once
/// Detector parameters: plain aggregates with defaults, units in the comments. Validate once at the
/// boundary (CLI, config file, library entry) with validate(); kernels assume valid input.
#include <cstdint>
#include <string>
#include <vector>

#include "sg/core/camera.hpp"
#include "sg/core/surveyed_params.hpp"

namespace sg::core {

/// The detector (DESIGN 3.4): ours, Stereo (depth decreases, DESIGN 3.1) and Stereo-Flow (the 3D
/// motion heads into the envelope, DESIGN 3.2), and the five the thesis surveys in chapter 3
/// (vision/surveyed.hpp). `--mode` and `--detector` name the same choice.
enum class Mode {
  kStereo,
  kStereoFlow,
  kMotionParallax,  ///< monocular: blobs of the flow that expand (thesis 3.1.1)
  kRelativeSize,    ///< monocular: clusters of features that grow (thesis 3.1.2)
  kElevationMap,    ///< obstacles standing on a fitted road, nearer than a distance (3.2.1)
  kSceneFlowSeg,    ///< moving blobs of a graph cut whose scene flow enters the envelope (3.2.2)
  kLongSeq,         ///< the LongSeq matcher's points nearer than a distance (thesis 3.2.3)
};
/// "stereo", "stereo-flow", "motion-parallax", "relative-size", "elevation-map",
/// "sceneflow-seg", "longseq".
const char* to_string(Mode m);
/// Parses the names of to_string; throws InputError naming them otherwise.
Mode parse_mode(const std::string& text);
/// Every detector, in the order of the enum.
std::vector<Mode> all_modes();

/// What a detector needs computed for a frame besides its left image, so that the pipeline
/// computes only that.
struct Needs {
  bool disparity = true;  ///< stereo matching (SM)
  bool flow = false;      ///< the backward flow to the previous frame's left image (OF)
  /// The labelling reads the left image itself (relative-size: this frame's and an earlier one's;
  /// sceneflow-seg: this frame's, for the cut's contrast weights).
  bool left_image = false;
};
Needs needs(Mode m);
/// One of the five detectors the thesis surveys (vision/surveyed.hpp), not Stereo or Stereo-Flow.
bool is_surveyed(Mode m);

/// Stereo matcher (DESIGN 2.1): OpenCV StereoBM, OpenCV StereoSGBM, our own SIMD matcher, or
/// LongSeq (thesis 3.2.3, vision/longseq.hpp: the longest run of good matches over one row).
enum class Matcher { kBm, kSgbm, kFast, kLongSeq };
/// "bm" / "sgbm" / "fast" / "longseq".
const char* to_string(Matcher m);
/// Parses "bm" / "sgbm" / "fast" / "longseq"; throws InputError otherwise.
Matcher parse_matcher(const std::string& text);
/// Matching cost of the `fast` matcher: SAD on the x-Sobel prefiltered image (as StereoBM), or
/// the Hamming distance of 5x5 census signatures (robust to exposure differences).
enum class MatchCost { kSad, kCensus };
/// "sad" / "census".
const char* to_string(MatchCost c);
/// Parses "sad" / "census"; throws InputError otherwise.
MatchCost parse_match_cost(const std::string& text);

/// Stereo matching settings (DESIGN 2.1); the names follow OpenCV StereoBM, whose meaning the
/// `fast` matcher keeps. `sgbm` uses the range, block size, uniqueness, speckle and lr fields.
struct BmParams {
  /// fast (default: StereoBM's results at several times its speed), bm, sgbm or longseq
  Matcher matcher = Matcher::kFast;
  MatchCost cost = MatchCost::kSad; ///< cost of the fast matcher (bm/sgbm ignore it)
  int min_disparity = 0;        ///< px
  int num_disparities = 64;     ///< px, positive multiple of 16
  int block_size = 11;          ///< px, odd, 5..255 (at 640 px wide; core::adapt_to_camera)
  int prefilter_cap = 31;       ///< 1..63
  int texture_threshold = 10;   ///< >= 0; low-texture blocks become invalid
  int uniqueness_ratio = 15;    ///< percent, >= 0
  int speckle_window = 100;     ///< px, 0 disables the speckle filter
  int speckle_range = 2;        ///< px (scaled by 16 internally), >= 0
  /// px, left-right check tolerance; -1 disables. A pixel whose right-to-left match lands more
  /// than this away is occluded or mismatched (repetitive texture, shadows, the edge of the
  /// range): on the shared robot recording the chessboard's period read 0.53 m for a box 0.85 m
  /// away, and the simulated ego-pass raised 3 false alarm frames, none with the check.
  int lr_max_diff = 1;
  /// Match the left band too (vision/left_band.hpp): the columns the full range cannot search,
  /// strip by strip with the range that fits (bm, sgbm and fast; longseq ignores it). Off leaves
  /// them unmatched: with a wide baseline or a near contact that is a third to half of the image
  /// (docs/decisions/left-band.md).
  bool left_band = true;
  /// Fill the holes of a bm or fast map from the half-size pair (vision/coarse_fill.hpp): a
  /// surface with too little texture for the sensor's noise keeps only its outline at full size
  /// and is matched at half size. Only holes more than half a block from a matched pixel, and
  /// only images at least 320 px wide. Why off for now: docs/decisions/coarse-fill.md.
  bool coarse_fill = false;
  /// Drop matches whose block repeats along its row within the disparity range
  /// (vision/periodic.hpp): shifted by a whole period the block matches itself better than this
  /// share of its cost shifted by one pixel, about what the true match loses to a sub-pixel
  /// offset. [0, 1); 0 disables. Why 0.3: docs/decisions/periodic-texture.md.
  double periodic_ratio = 0.3;
  // LongSeq (matcher longseq): its window is one row of block_size pixels (<= 63), its disparities
  // 0 .. num_disparities - 1 (min_disparity 0).
  double longseq_cost_max = 6.0;  ///< a good match: mean absolute difference <= this, grey levels
  double longseq_best_max = 3.0;  ///< a pixel whose best match costs more is unmatched, grey levels
  bool longseq_both_ways = true;  ///< also match right to left, keep the smaller disparity
};

/// The space the platform occupies, in camera coordinates (DESIGN 3.2). Defaults: a small robot.
struct Envelope {
  double half_width_m = 0.5;  ///< |X| <= half_width_m
  double y_top_m = -1.0;      ///< top of the envelope (y down), m
  double y_bottom_m = 1.0;    ///< bottom of the envelope, m; the ground lies below
  double z_contact_m = 0.5;   ///< depth at which a point touches the platform, m
  double horizon_s = 3.0;     ///< warn about contacts within this time, s
};

/// Stereo-mode pixel labelling (DESIGN 3.1): depth decreases.
struct StereoLabelParams {
  /// Frame gaps k compared: D_i against D_{i-k}. k = 1 is the thesis; larger k catch slow
  /// (far) approaches whose per-frame disparity change is below the matcher's noise. At 30 fps
  /// gap 15 spans 0.5 s: a point with TTC <= 3 s at Z m changes by >= f*B*0.5/(3 Z) px over it
  /// (1 px at 10 m for f*B = 60), so min_delta_d_px = 1 still sees it (simulated head-on:
  /// recall 1.0, lead 2.98 s; static and receding scenes: no alarm frame).
  std::vector<int> gaps = {1, 5, 15};
  double z_max_m = 12.0;        ///< ignore points farther than this, m
  /// D_i - D_{i-k} must reach this, px. Well above BM's sub-pixel noise (0.1-0.3 px): with 0.5 the
  /// simulated receding box raised alarms.
  double min_delta_d_px = 1.0;
  /// D_i <= max_growth * D_{i-k}, else the gap is ignored for that pixel: a depth that more than
  /// halves within the gap is an object edge sweeping over the pixel, not motion (an approach that
  /// fast is caught by the smaller gaps). 0 disables; otherwise > 1.
  double max_growth = 2.0;
  /// Skip points outside the envelope's vertical band (ground, overhead): y_top <= Y <= y_bottom.
  bool use_envelope_band = true;
};

/// From dangerous pixels to signals (DESIGN 3.3).
struct SignalParams {
  int open_size = 3;             ///< morphological opening kernel, px (odd; 1 disables)
  int min_area_px = 150;         ///< blobs smaller than this are dropped, px
  int region_columns = 3;        ///< left / centre / right
  int region_min_px = 150;       ///< a region is dangerous in a frame above this many px
  int on_k = 2;                  ///< region turns on after on_k of the last on_n frames were dangerous
  int on_n = 3;
  int off_m = 3;                 ///< ... and off after off_m clear frames
  double ttc_danger_s = 1.5;     ///< severity danger when min TTC <= this, s
  double ttc_warning_s = 3.0;    ///< severity warning when min TTC <= this, s
  /// Obstacle tracking (vision/tracking.hpp): blobs of consecutive frames whose boxes overlap by
  /// at least this fraction of the smaller box are one obstacle, (0, 1].
  double track_min_overlap = 0.3;
  /// An obstacle's TTC, distance and closing speed come from a straight-line fit of its distance
  /// over the last ttc_fit_window_s seconds (> 0) once it has ttc_fit_min_frames frames (>= 2)
  /// spanning at least ttc_fit_min_span_s seconds (>= 0, <= the window) in it; before that the
  /// blob's median per-pixel TTC stands. A slope fitted over a few frames is noisier than the
  /// per-pixel TTCs, which compare with frames up to the longest gap back (20 frames, 0.67 s):
  /// on ego-wall a 4-frame fit read 3.5 s for a true 2.9 s.
  double ttc_fit_window_s = 1.0;
  int ttc_fit_min_frames = 4;
  double ttc_fit_min_span_s = 0.5;
  /// An obstacle whose fitted distance has come under the matcher's near limit (f B / (number of
  /// disparities - 1)) cannot be measured any more: its blob shows a wrong, aliased disparity or
  /// vanishes, a few frames before contact. With this on, such a track's distance and TTC are
  /// extrapolated from its fit, and a track whose blob vanished there is kept (an obstacle marked
  /// predicted, its last box dangerous) until its predicted contact.
  bool coast_near_range = true;
  /// Severity rises at once but falls only after this many consecutive frames asked for less
  /// (>= 1), so that it does not flicker between warning and danger.
  int severity_off_frames = 5;
  /// A blob raises an alarm only once its track has been seen this many frames in a row with a
  /// distance that holds together with its motion (core::Obstacle::seen_frames; >= 1, 1 = at
  /// once): a mismatch lasts a frame, or reads a fixed wrong depth while the flow says it moves.
  /// A track that coasts on its prediction counts as seen.
  int confirm_frames = 2;
};

/// Dense optical flow method (DESIGN 2.2): OpenCV DISOpticalFlow presets or Farneback.
enum class FlowMethod { kDisUltrafast, kDisFast, kDisMedium, kFarneback };

/// "dis-ultrafast" / "dis-fast" / "dis-medium" / "farneback".
const char* to_string(FlowMethod m);
/// Parses the names of to_string(); throws InputError naming the text otherwise.
FlowMethod parse_flow_method(const std::string& text);

/// Optical-flow settings (vision/flow.hpp).
struct FlowParams {
  FlowMethod method = FlowMethod::kDisUltrafast;
  /// Rows of context a tile reads above and below its own rows (compute_flow_rows), px. DIS and
  /// Farneback work on pyramids, so a tile differs from the whole image near its cut anyway.
  int tile_halo_px = 48;
  // Farneback only (cv::calcOpticalFlowFarneback); OpenCV's sample values.
  double fb_pyr_scale = 0.5;  ///< pyramid scale between levels, in (0, 1)
  int fb_levels = 3;          ///< pyramid levels, >= 1
  int fb_win_size = 15;       ///< averaging window, px, >= 3
  int fb_iterations = 3;      ///< iterations per level, >= 1
  int fb_poly_n = 5;          ///< polynomial expansion neighbourhood, 5 or 7
  double fb_poly_sigma = 1.2;  ///< Gaussian sigma of the expansion, > 0 (1.1 for n=5, 1.5 for 7)
};

/// Ground-plane fit (vision/scene_flow.hpp fit_ground_plane) for the optional ground exclusion.
struct GroundParams {
  double lower_fraction = 0.4;  ///< fit on the bottom fraction of the image rows, (0, 1]
  int sample_step_px = 4;       ///< sample every n-th row and column, >= 1
  int iterations = 200;         ///< RANSAC iterations, >= 1
  double tolerance_m = 0.05;    ///< inlier distance to the plane, m
  double z_max_m = 12.0;        ///< ignore points farther than this, m
  int min_inliers = 200;        ///< fewer inliers: no plane found
  std::uint64_t seed = 12345;   ///< fixed RANSAC seed (reproducible)
  /// With pool_surface_motion, no surface joins the ground's side (mark_ground_side) with what is
  /// off it, so that an object standing on the ground keeps its own motion.
  bool split_surfaces = true;
  /// A pixel whose disparity exceeds the plane's at that pixel by at most this, px (>= 0), is on
  /// the ground's side. About the matcher's error on a textured road, so that the road's
  /// mismatched patches stay with the road.
  double side_margin_px = 1.0;
};

/// Stereo-Flow pixel labelling (DESIGN 3.2): the 3D motion heads into the envelope.
struct SceneFlowParams {
  /// Frame gaps k compared by label_stereo_flow_window: P_i against P_{i-k} along the chained
  /// flow. k = 1 is the thesis; larger k see slow (far) approaches whose per-frame disparity
  /// change is below the matcher's noise. Gaps beyond the history given are skipped. With
  /// longest_gap_decides, {1, 4, 10, 20} gave on the simulated scenes: head-on recall 0.98 with
  /// a 2.98 s lead and no early alarm; crossing, receding, static, ego-pass: no alarm frame.
  /// The chains cost about 20 ms a frame at VGA when the whole image is a candidate.
  std::vector<int> gaps = {1, 4, 10, 20};
  /// Approach speed the point must reach, -V_z >= v_min, m/s: a floor under the noise of a
  /// still scene's velocities, below walking pace. 0.3 missed a small robot's 0.2-0.35 m/s
  /// approach to a box (shared recording: recall 0.73 against 1.00 with 0.1).
  double v_min_mps = 0.1;
  /// Ignore points farther than this, m. Larger than Stereo mode's: the long gaps measure far
  /// motion well enough (simulated head-on at 6 m/s: caught 2.9 s ahead instead of 1.9 s at 12 m).
  double z_max_m = 20.0;
  /// The disparity must have grown by this much over the gap, D_i(p) - D_{i-k}(q) >= this, px:
  /// a noise gate, as in Stereo mode; 0 disables it.
  double min_delta_d_px = 0.5;
  /// Until the velocity fit's chain reaches the longest gap (the first frames of a stream), the
  /// envelope test uses the slowest approach along the measured path that this many standard
  /// errors of the surface's velocity could hide, V (1 - sigma_V / -V_z), >= 0. The standard
  /// error is the scatter of the surface's mean residuals about its fitted line
  /// (pool_surface_motion, slope_doubt), widened as Student's t; none is trusted before three
  /// samples. Why from the data, not an assumed error: docs/decisions/startup-doubt.md.
  /// 0 trusts the first frames fully.
  double startup_doubt_se = 2.0;
  /// Velocities faster than this are mismatches and are ignored, m/s.
  double max_speed_mps = 40.0;
  /// With fit_velocity, a chain with a sample whose disparity departs from the line fitted
  /// through its other samples by more than chain_outlier_px (px) and more than
  /// chain_outlier_fraction of its own disparity crossed a mismatch: its velocity is unknown. A
  /// repetitive texture matched one period off in some frames (a checkerboard 2.6 m away read at
  /// 1.6 m in some frames, 20 px against 32) or a flow that slid onto another surface steps by
  /// whole pixels; the matcher's noise stays under the pixel bound, a smooth change of speed
  /// under the fraction. chain_outlier_px 0 disables; the fraction is >= 0.
  double chain_outlier_px = 2.0;
  double chain_outlier_fraction = 0.25;
  /// The past disparity D_{i-k}(q) is unknown when the neighbours its bilinear sample uses differ
  /// by more than this, px: at a depth edge the mix of object and background would look like a
  /// fast approach. Infinity disables the check.
  double max_disparity_step_px = 1.0;
  /// Pixels within edge_margin_px of a depth edge of D_i, or whose source q is that near one in
  /// D_{i-k}, are not dangerous: the largest and smallest valid disparities of the (2 r + 1)^2
  /// window differ by more than edge_step_px. Block matching fattens foreground over the
  /// background by about half a block, and flow bleeds over edges, so such pixels pair an object's
  /// disparity now with the background's before: a false fast approach. 0 disables. px.
  int edge_margin_px = 8;
  /// The step that makes a depth edge for edge_margin_px, px. An object 8 m before a wall 40 m
  /// away steps by 6 px; a level ground changes by B/h px per row (0.1 at the default camera), so
  /// with 1.0 it is masked too; the slanted side faces of boxes, which block matching gets wrong,
  /// are masked with 1.0 but not 2.0 (simulated ego-pass: no alarm instead of 0.16 false alarms).
  double edge_step_px = 1.0;
  /// Give back thin near structures (poles, posts, bars) that the edge margin would remove
  /// whole: pixels of a run of similar disparity at most 2 edge_margin_px + 1 long between
  /// farther surfaces, with nothing nearer within the margin (vision/edge_margin.hpp), are
  /// not depth-edge pixels. Without it a 6 cm pole is missed until 2 m away (simulated thin-pole).
  bool keep_thin_structures = true;
  /// Pool the velocity over each surface before the envelope test (vision/segment_motion.hpp):
  /// the points of a rigid object share one velocity, and its per-pixel estimates scatter by
  /// about 10 % at 7 m, which tested pixel by pixel raises early alarms on large objects and
  /// late ones on small far objects. Surfaces are the connected pixels of continuous disparity
  /// (steps of at most edge_step_px) in the band; each takes the interquartile mean of the
  /// velocities its candidates know.
  bool pool_surface_motion = true;
  /// With pool_surface_motion, a surface also continues down a column past a stretch of at most
  /// this many metres (at its depth, 0..5) where the matcher read something else, and resumes at
  /// a disparity within edge_step_px, so that the pieces of a thin pole the block window broke
  /// apart pool as one. Why 0.3: docs/decisions/surface-bridge.md. 0 joins only neighbours.
  double surface_bridge_m = 0.3;
  /// With pool_surface_motion, candidates nearer than chain_stride_z_m (m, > 0) are followed back
  /// along the flow chain only on every chain_stride-th row and column (1..8; 1 = all of them),
  /// the stride doubled at every factor sqrt(2) nearer, columns first, up to 16 (ChainStrides).
  /// Their surfaces' velocities are pooled and tested at every pixel anyway, so the labelling
  /// costs about as much near as far. Why 2 from 8 m: docs/decisions/chain-stride.md.
  int chain_stride = 2;
  double chain_stride_z_m = 8.0;
  /// Grow each dangerous blob back over the depth-edge margin (pixels of similar disparity next
  /// to it, up to edge_margin_px rounds) before the clean-up's min_area, so that the margin
  /// cannot shrink a far object below min_area. Why off: docs/decisions/grow-into-edges.md.
  bool grow_into_edges = false;
  /// Remove the camera's own rotation before the envelope test: the rotation between frames is
  /// estimated from the background flow (with disparity known, rotation flow is
  /// depth-independent; vision/ego_motion.hpp) and P_{i-k} is turned into frame i's orientation.
  /// Needed when the platform turns or sways while it moves: on exact maps, driving at 3 m/s
  /// while turning at 10 deg/s makes boxes beside the path look as if they cut in (compensated:
  /// none); a hand-carried or walking camera sways. Why on: docs/decisions/compensate-rotation.md.
  bool compensate_rotation = true;
  /// With compensate_rotation: the envelope test follows the platform's turn (the yaw rate of
  /// that rotation estimate over the longest gap): a point is dangerous when it meets the contact
  /// plane on the arc the platform drives, not on the straight line ahead
  /// (vision::heads_into_envelope_turning). That holds for a platform that drives where it
  /// heads, as a car does (on in the car preset); a camera that pans or a platform that crabs
  /// while it moves straight needs the straight line (off: the default, robot and walker).
  bool predict_turn = false;
  /// How the gaps combine per pixel. true: the longest gap that gives the pixel a velocity decides
  /// alone (its verdict, TTC and velocity), the temporal integration of DESIGN 3.2: a longer gap
  /// divides the disparity noise by its length, and the shorter gaps only speak where the chain
  /// of the longer ones is lost (the point left the image, or an invalid disparity) or the history
  /// is short. false: a pixel is dangerous when any gap flags it (TTC: the smallest).
  bool longest_gap_decides = true;
  /// The velocity of a pixel is the weighted least-squares slope of its 3D position over every
  /// frame of its chain up to the longest gap (positions weighted by 1 / var(Z), i.e. by d^4),
  /// instead of the difference between now and the longest gap's frame alone
  /// (longest_gap_decides and the gaps below the longest are then not used). The error of a far
  /// surface's disparity is largely common to all its pixels and changes from frame to frame
  /// (simulated head-on-fast, a box 20 m away: -0.22 to +0.07 px against a growth of 0.6 px over
  /// 20 frames), so pooling over pixels cannot remove it, while averaging over frames does.
  bool fit_velocity = true;
  /// The point must lie in the envelope's vertical band now too (y_top <= Y_i <= y_bottom), as in
  /// Stereo mode: ground and overhead points then cannot enter the envelope through noise in V_y.
  bool use_envelope_band = true;
  /// Clear dangerous pixels on or below a fitted ground plane: the ground is never an obstacle,
  /// yet an envelope that reaches below the camera's height (a robot preset 1.0 m deep on a
  /// camera 0.5 m high), a tilt, or flow lost on a fast road make it read as approaching. Its
  /// plane also splits the surfaces of pool_surface_motion (GroundParams::split_surfaces).
  bool exclude_ground = true;
  GroundParams ground;  ///< the fit used by exclude_ground
};

/// Everything the detector needs.
struct DetectorParams {
  Mode mode = Mode::kStereo;
  BmParams bm;
  Envelope envelope;
  StereoLabelParams stereo;
  SignalParams signal;
  FlowParams flow;            ///< Stereo-Flow mode only
  SceneFlowParams scene_flow;  ///< Stereo-Flow mode only
  // The surveyed detectors' own settings (core/surveyed_params.hpp).
  MotionParallaxParams motion_parallax;  ///< motion-parallax
  RelativeSizeParams relative_size;      ///< relative-size
  ElevationParams elevation;             ///< elevation-map
  SceneFlowSegParams sceneflow_seg;      ///< sceneflow-seg
  ProximityParams proximity;             ///< elevation-map and longseq
};

/// Sets p.mode to m; the longseq detector also selects the LongSeq matcher.
void select_detector(DetectorParams& p, Mode m);

/// Every violation as "<section>.<field>=<value>: <rule>"; empty when valid.
std::vector<std::string> validate(const BmParams& p);
std::vector<std::string> validate(const Envelope& p);
std::vector<std::string> validate(const StereoLabelParams& p);
std::vector<std::string> validate(const SignalParams& p);
/// "flow.<field>=<value>: <rule>".
std::vector<std::string> validate(const FlowParams& p);
/// "ground.<field>=<value>: <rule>".
std::vector<std::string> validate(const GroundParams& p);
/// "scene_flow.<field>=<value>: <rule>" (and ground.* when exclude_ground).
std::vector<std::string> validate(const SceneFlowParams& p);
/// All of the above (and core/surveyed_params.hpp's) plus the rules between sections (the
/// longseq detector matches with longseq; the alarm distance lies beyond the contact depth) and
/// checks against the image size (num_disparities < width, etc.).
std::vector<std::string> validate(const DetectorParams& p, const Camera& camera);

}  // namespace sg::core
