// The truth log of real recordings: its parser on good and bad files, what is derived from it
// (closing speed, truth TTC, due, quiet, still) and the scores of hand-made detection sequences,
// all with answers worked out by hand.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "sg/core/error.hpp"
#include "sg/eval/truth_log.hpp"

namespace sg::eval {
namespace {

namespace fs = std::filesystem;

/// Expects parse_truth_log(text) to throw InputError whose message holds every needle.
void expect_error(const std::string& text, const std::vector<std::string>& needles,
                  const TruthLogOptions& options = {}) {
  try {
    (void)parse_truth_log(text, "log.csv", options);
    ADD_FAILURE() << "no error for:\n" << text;
  } catch (const core::InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    for (const std::string& n : needles)
      EXPECT_NE(what.find(n), std::string::npos) << "'" << n << "' not in: " << what;
  }
}

// ---------------------------------------------------------------------------------------------
// Parser

TEST(TruthLogParse, UniboLayoutWithBlankDistances) {
  const TruthLog log = parse_truth_log(
      "frame,t_s,phase,board_distance_m\n"
      "0,0.0000,creep,\n"
      "1,0.0667,Approach,1.082\n"
      "2,0.1333,retreat,0.732\n",
      "truth.csv");
  EXPECT_TRUE(log.has_frame);
  EXPECT_TRUE(log.has_time);
  EXPECT_TRUE(log.has_phase);
  EXPECT_EQ(log.distance_column, "board_distance_m");
  ASSERT_EQ(log.rows.size(), 3u);
  EXPECT_EQ(log.rows[0].line, 2);
  EXPECT_EQ(*log.rows[1].frame, 1);
  EXPECT_DOUBLE_EQ(*log.rows[1].t_s, 0.0667);
  EXPECT_FALSE(log.rows[0].distance_m);
  EXPECT_DOUBLE_EQ(*log.rows[1].distance_m, 1.082);
  EXPECT_EQ(log.rows[1].phase, "approach");  // lower case
}

TEST(TruthLogParse, TudelftLayoutIgnoresOtherColumns) {
  const TruthLog log = parse_truth_log(
      "frame,t_s,camera_x_m,camera_y_m,camera_z_m,yaw_deg,distance_m\n"
      "0,0.000,-2.521,0.968,-1.604,97.3,3.143\n"
      "1,0.141,-2.521,0.968,-1.604,abc,3.100\n",
      "truth.csv");
  EXPECT_FALSE(log.has_phase);
  EXPECT_EQ(log.distance_column, "distance_m");
  ASSERT_EQ(log.rows.size(), 2u);
  EXPECT_DOUBLE_EQ(*log.rows[1].distance_m, 3.1);
  EXPECT_TRUE(log.rows[1].phase.empty());
}

TEST(TruthLogParse, DistanceColumnChoice) {
  const std::string text = "t_s,board_distance_m,distance_m,range\n0,1,2,3\n";
  EXPECT_DOUBLE_EQ(*parse_truth_log(text, "x").rows[0].distance_m, 2.0);  // distance_m first
  TruthLogOptions options;
  options.distance_column = "range";
  const TruthLog log = parse_truth_log(text, "x", options);
  EXPECT_EQ(log.distance_column, "range");
  EXPECT_DOUBLE_EQ(*log.rows[0].distance_m, 3.0);
}

TEST(TruthLogParse, CommentsBlankLinesCrLfAndSpaces) {
  const TruthLog log = parse_truth_log(
      "# made by hand\r\n\r\n t_s , phase \r\n0.5, still \r\n\r\n# pause\n1.0,approach\n", "x");
  EXPECT_FALSE(log.has_frame);
  EXPECT_TRUE(log.distance_column.empty());
  ASSERT_EQ(log.rows.size(), 2u);
  EXPECT_EQ(log.rows[0].phase, "still");
  EXPECT_EQ(log.rows[0].line, 4);
  EXPECT_EQ(log.rows[1].line, 7);
  EXPECT_DOUBLE_EQ(*log.rows[1].t_s, 1.0);
}

TEST(TruthLogParse, FrameOnly) {
  const TruthLog log = parse_truth_log("frame,distance_m\n3,2.5\n7,\n", "x");
  EXPECT_TRUE(log.has_frame);
  EXPECT_FALSE(log.has_time);
  EXPECT_EQ(*log.rows[1].frame, 7);
  EXPECT_FALSE(log.rows[1].t_s);
}

TEST(TruthLogParse, MissingFile) {
  try {
    (void)read_truth_log("no/such/truth.csv");
    ADD_FAILURE() << "no error";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no/such/truth.csv"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos) << e.what();
  }
}

TEST(TruthLogParse, ReadsAFile) {
  const fs::path p = fs::path(::testing::TempDir()) / "sg_truth_log_read.csv";
  std::ofstream(p) << "frame,distance_m\n0,1.5\n";
  const TruthLog log = read_truth_log(p);
  EXPECT_EQ(log.name, p.string());
  EXPECT_DOUBLE_EQ(*log.rows[0].distance_m, 1.5);
  fs::remove(p);
}

TEST(TruthLogParse, EmptyFile) {
  expect_error("", {"log.csv", "empty"});
  expect_error(" \n\n# only a comment\n", {"log.csv", "empty"});
}

TEST(TruthLogParse, NoHeader) {
  expect_error("0,0.0,1.5\n1,0.1,1.4\n", {"log.csv line 1", "no header"});
}

TEST(TruthLogParse, NoFrameOrTimeColumn) {
  expect_error("time,distance_m\n0,1\n", {"log.csv line 1", "no 'frame' or 't_s' column"});
}

TEST(TruthLogParse, NeitherDistanceNorPhase) {
  expect_error("frame,t_s,speed\n0,0,1\n", {"log.csv line 1", "neither a distance column"});
}

TEST(TruthLogParse, NamedDistanceColumnMissing) {
  TruthLogOptions options;
  options.distance_column = "lidar_m";
  expect_error("frame,distance_m\n0,1\n", {"log.csv line 1", "'lidar_m'"}, options);
}

TEST(TruthLogParse, RepeatedColumn) {
  expect_error("frame,distance_m,frame\n0,1,0\n", {"line 1", "'frame' appears twice"});
}

TEST(TruthLogParse, HeaderWithoutRows) {
  expect_error("frame,distance_m\n\n", {"log.csv", "no data row"});
}

TEST(TruthLogParse, WrongCellCount) {
  expect_error("frame,distance_m\n0,1\n1\n", {"log.csv line 3", "1 cells", "has 2"});
  expect_error("frame,distance_m\n0,1,2\n", {"log.csv line 2", "3 cells"});
}

TEST(TruthLogParse, NonNumericValues) {
  expect_error("frame,distance_m\n0,1\nx,2\n", {"log.csv line 3, column 1 (frame)", "'x'"});
  expect_error("frame,distance_m\n1.5,2\n", {"line 2, column 1 (frame)", "'1.5'"});
  expect_error("frame,distance_m\n-1,2\n", {"line 2, column 1 (frame)", "'-1'"});
  expect_error("frame,distance_m\n,2\n", {"line 2, column 1 (frame)", "''"});
  expect_error("distance_m,t_s\n2,0.0\n2,zero\n", {"line 3, column 2 (t_s)", "'zero'"});
  expect_error("t_s,distance_m\n0,2\n0.1,2m\n", {"line 3, column 2 (distance_m)", "'2m'"});
  expect_error("t_s,distance_m\ninf,2\n", {"line 2, column 1 (t_s)"});
}

TEST(TruthLogParse, NonIncreasingFrameOrTime) {
  expect_error("frame,distance_m\n0,1\n2,1\n2,1\n",
               {"log.csv line 4, column 1 (frame)", "does not increase", "line 3"});
  expect_error("frame,distance_m\n5,1\n3,1\n", {"line 3, column 1 (frame)", "does not increase"});
  expect_error("t_s,distance_m\n0.1,1\n0.1,1\n", {"line 3, column 1 (t_s)", "does not increase"});
  expect_error("t_s,distance_m\n0.2,1\n0.1,1\n", {"line 3, column 1 (t_s)", "does not increase"});
}

TEST(TruthLogParse, BadDistances) {
  for (const std::string bad : {"nan", "NaN", "-0.1", "inf", "-inf", "1e999"}) {
    expect_error(
        "frame,t_s,board_distance_m\n0,0,1\n1,0.1," + bad + "\n",
        {"log.csv line 3, column 3 (board_distance_m)", "'" + bad + "'", "not a distance"});
  }
}

TEST(TruthLogParse, PhaseList) {
  EXPECT_EQ(parse_phase_list(" Creep, retreat ,,STILL"),
            (std::vector<std::string>{"creep", "retreat", "still"}));
  EXPECT_TRUE(parse_phase_list("").empty());
  EXPECT_EQ(default_quiet_phases(),
            (std::vector<std::string>{"still", "creep", "retreat", "quiet", "static", "stop"}));
}

// ---------------------------------------------------------------------------------------------
// Derived quantities

/// A log "t_s,distance_m" (or "frame,..." with `by_frame`) from (t, distance) with d < 0 = blank.
std::string distance_log(const std::vector<std::pair<double, double>>& rows) {
  std::ostringstream s;
  s.precision(17);
  s << "t_s,distance_m\n";
  for (const auto& [t, d] : rows) {
    s << t << ",";
    if (d >= 0) s << d;
    s << "\n";
  }
  return s.str();
}

TEST(TruthDerive, SlopeFit) {
  EXPECT_DOUBLE_EQ(*fit_slope({0, 1, 2, 3}, {5, 3, 1, -1}), -2.0);
  EXPECT_NEAR(*fit_slope({0, 1, 2}, {0, 2, 1}), 0.5, 1e-12);
  EXPECT_FALSE(fit_slope({1}, {1}));
  EXPECT_FALSE(fit_slope({2, 2, 2}, {1, 2, 3}));
}

TEST(TruthDerive, SteadyApproach) {
  // 10 Hz for 4 s, distance 3.025 - 0.5 t: closing 0.5 m/s everywhere (a line fits exactly, the
  // one-sided windows at the ends too), truth TTC (d - 0.5) / 0.5 = 5.05 - t, due from t = 2.1.
  std::vector<std::pair<double, double>> rows;
  for (int i = 0; i <= 40; ++i) rows.emplace_back(i * 0.1, 3.025 - 0.5 * i * 0.1);
  const std::vector<TruthFrame> f =
      derive_truth(parse_truth_log(distance_log(rows), "x"), TruthCriteria{}, 0.1);
  ASSERT_EQ(f.size(), 41u);
  int due = 0;
  for (int i = 0; i <= 40; ++i) {
    ASSERT_TRUE(f[i].closing_mps) << i;
    EXPECT_NEAR(*f[i].closing_mps, 0.5, 1e-9) << i;
    ASSERT_TRUE(f[i].ttc_s) << i;
    EXPECT_NEAR(*f[i].ttc_s, 5.05 - i * 0.1, 1e-9) << i;
    EXPECT_FALSE(f[i].quiet) << i;
    EXPECT_FALSE(f[i].still) << i;
    EXPECT_EQ(f[i].due, i >= 21) << i;
    due += f[i].due;
  }
  EXPECT_EQ(due, 20);
}

TEST(TruthDerive, ContactReachedIsTtcZeroAndDue) {
  // 2.0 - 0.5 t: the contact plane (0.5 m) at t = 3; beyond it TTC 0, still due.
  std::vector<std::pair<double, double>> rows;
  for (int i = 0; i <= 40; ++i) rows.emplace_back(i * 0.1, 2.0 - 0.5 * i * 0.1);
  const std::vector<TruthFrame> f =
      derive_truth(parse_truth_log(distance_log(rows), "x"), TruthCriteria{}, 0.1);
  EXPECT_NEAR(*f[5].ttc_s, 2.5, 1e-9);   // 1.75 m
  EXPECT_NEAR(*f[20].ttc_s, 1.0, 1e-9);  // 1.0 m
  EXPECT_DOUBLE_EQ(*f[35].ttc_s, 0.0);   // 0.25 m
  EXPECT_TRUE(f[35].due);
  EXPECT_TRUE(f[40].due);
}

TEST(TruthDerive, StillThenApproachThenRecede) {
  // 10 Hz: 2 s still at 3 m, 2 s approaching at 1 m/s, then 2 s receding at 0.5 m/s.
  std::vector<std::pair<double, double>> rows;
  for (int i = 0; i < 60; ++i) {
    const double t = i * 0.1;
    double d = 3.0;
    if (i > 20) d = 3.0 - (t - 2.0);
    if (i > 40) d = 1.0 + 0.5 * (t - 4.0);
    rows.emplace_back(t, d);
  }
  const std::vector<TruthFrame> f =
      derive_truth(parse_truth_log(distance_log(rows), "x"), TruthCriteria{}, 0.1);
  for (int i = 0; i <= 15; ++i) {  // windows wholly in the still part
    EXPECT_NEAR(*f[i].closing_mps, 0.0, 1e-9) << i;
    EXPECT_TRUE(f[i].quiet) << i;
    EXPECT_TRUE(f[i].still) << i;
    EXPECT_FALSE(f[i].due) << i;
    EXPECT_FALSE(f[i].ttc_s) << i;
  }
  for (int i = 25; i <= 35; ++i) {  // wholly approaching
    EXPECT_NEAR(*f[i].closing_mps, 1.0, 1e-9) << i;
    EXPECT_FALSE(f[i].quiet) << i;
    EXPECT_NEAR(*f[i].ttc_s, 3.0 - (i * 0.1 - 2.0) - 0.5, 1e-9) << i;
    EXPECT_TRUE(f[i].due) << i;  // TTC 2.0 .. 1.0
  }
  for (int i = 46; i < 55; ++i) {  // wholly receding: quiet, not still
    EXPECT_NEAR(*f[i].closing_mps, -0.5, 1e-9) << i;
    EXPECT_TRUE(f[i].quiet) << i;
    EXPECT_FALSE(f[i].still) << i;
    EXPECT_FALSE(f[i].due) << i;
  }
}

TEST(TruthDerive, TooFewKnownDistancesLeaveSpeedUnknown) {
  // 8 Hz (exact binary times), distance 3 - t. Known every 5th row, 0.625 s apart: a window of
  // +-0.5 s holds at most two of them.
  std::vector<std::pair<double, double>> rows;
  for (int i = 0; i < 40; ++i) rows.emplace_back(i * 0.125, i % 5 == 0 ? 3.0 - i * 0.125 : -1.0);
  const std::vector<TruthFrame> f =
      derive_truth(parse_truth_log(distance_log(rows), "x"), TruthCriteria{}, 0.125);
  for (const TruthFrame& x : f) {
    EXPECT_FALSE(x.closing_mps);
    EXPECT_FALSE(x.ttc_s);
    EXPECT_FALSE(x.quiet);  // without a phase: quiet needs a known speed
    EXPECT_FALSE(x.due);
  }
  // Known every 4th row (0.5 s apart): the window around a known row holds three (its ends
  // included), the window around the row after it two.
  rows.clear();
  for (int i = 0; i < 40; ++i) rows.emplace_back(i * 0.125, i % 4 == 0 ? 3.0 - i * 0.125 : -1.0);
  const std::vector<TruthFrame> g =
      derive_truth(parse_truth_log(distance_log(rows), "x"), TruthCriteria{}, 0.125);
  ASSERT_TRUE(g[8].closing_mps);
  EXPECT_NEAR(*g[8].closing_mps, 1.0, 1e-12);
  EXPECT_NEAR(*g[8].ttc_s, 1.5, 1e-12);  // 2 m
  EXPECT_TRUE(g[8].due);
  EXPECT_FALSE(g[9].closing_mps);
  EXPECT_FALSE(g[9].ttc_s);
}

TEST(TruthDerive, PhasesDecideQuietAndStill) {
  const TruthLog log = parse_truth_log(
      "frame,phase,distance_m\n"
      "0,still,2.0\n1,still,2.0\n2,creep,1.99\n3,approach,1.5\n4,approach,1.0\n5,retreat,1.2\n"
      "6,Stop,1.2\n7,,1.2\n",
      "x");
  TruthCriteria c;
  std::vector<TruthFrame> f = derive_truth(log, c, 0.5);
  EXPECT_DOUBLE_EQ(f[4].t_s, 2.0);  // frame * period without a t_s column
  const std::vector<bool> quiet = {true, true, true, false, false, true, true, false};
  const std::vector<bool> still = {true, true, false, false, false, false, false, false};
  for (std::size_t i = 0; i < f.size(); ++i) {
    EXPECT_EQ(f[i].quiet, quiet[i]) << i;
    EXPECT_EQ(f[i].still, still[i]) << i;
  }
  c.quiet_phases = parse_phase_list("retreat");
  f = derive_truth(log, c, 0.5);
  EXPECT_FALSE(f[0].quiet);
  EXPECT_FALSE(f[0].still);  // still counts only among quiet frames
  EXPECT_TRUE(f[5].quiet);
}

TEST(TruthDerive, DueWithinADistance) {
  const TruthLog log = parse_truth_log(
      "frame,phase,board_distance_m\n"
      "0,approach,\n1,approach,0.9\n2,approach,0.85\n3,approach,0.8\n4,retreat,0.8\n",
      "x");
  TruthCriteria c;
  c.due_within_m = 0.85;
  const std::vector<TruthFrame> f = derive_truth(log, c, 1.0 / 15);
  EXPECT_FALSE(f[0].due);  // unknown distance
  EXPECT_FALSE(f[1].due);
  EXPECT_TRUE(f[2].due);
  EXPECT_TRUE(f[3].due);
  EXPECT_FALSE(f[4].due);  // quiet
}

// ---------------------------------------------------------------------------------------------
// Scores

/// 8 Hz (exact binary times), 1 m/s (0.125 m a frame): frames 0-9 still at 3 m, 10-30
/// approaching (frame 29 at 0.5 m: the contact), 31-49 retreating.
std::string scenario_log(int rows = 50) {
  std::ostringstream s;
  s << "frame,t_s,phase,distance_m\n";
  for (int f = 0; f < rows; ++f) {
    double d = 3.0;
    const char* phase = "still";
    if (f >= 10 && f <= 30) d = 3.0 - 0.125 * (f - 9), phase = "approach";
    if (f > 30) d = 0.375 + 0.125 * (f - 30), phase = "retreat";
    s << f << "," << f * 0.125 << "," << phase << "," << d << "\n";
  }
  return s.str();
}

core::Detection detection(int frame, bool alarm, std::vector<double> distances = {}) {
  core::Detection d;
  d.frame = frame;
  d.time_s = frame * 0.125;
  d.signal = alarm;
  for (double m : distances) {
    core::Obstacle o;
    o.distance_m = m;
    d.obstacles.push_back(o);
  }
  return d;
}

double scenario_distance(int f) {
  if (f < 10) return 3.0;
  if (f <= 30) return 3.0 - 0.125 * (f - 9);
  return 0.375 + 0.125 * (f - 30);
}

TEST(TruthScore, RecallFalseAlarmsLeadAndDistanceError) {
  TruthCriteria c;
  c.due_within_m = 1.5;  // due: approach frames 21..30
  const TruthLog log = parse_truth_log(scenario_log(), "x");
  TruthScorer scorer(derive_truth(log, c, 0.125), c);
  for (int f = 0; f < 50; ++f) {
    const bool alarm = (f >= 23 && f <= 30) || f == 4 || f == 40;
    std::vector<double> obstacles;
    if (alarm && f != 40) {
      const double error = f == 4 ? 0.5 : f <= 26 ? 0.1 : 0.2;
      // The nearest obstacle counts; a farther one beside it must not.
      obstacles = {scenario_distance(f) * (1 + error) + 5.0, scenario_distance(f) * (1 + error)};
    }
    if (f == 12) obstacles = {10.0};  // no alarm: not scored for distance
    scorer.add(detection(f, alarm, obstacles));
  }
  const TruthReport r = scorer.report();
  EXPECT_EQ(r.frames, 50);
  EXPECT_EQ(r.scored_frames, 50);
  EXPECT_EQ(r.unscored_frames, 0);
  EXPECT_EQ(r.rows_past_last_frame, 0);
  EXPECT_EQ(r.alarm_frames, 10);
  EXPECT_EQ(r.due_frames, 10);
  EXPECT_EQ(r.due_alarm_frames, 8);
  EXPECT_DOUBLE_EQ(*r.recall(), 0.8);
  EXPECT_EQ(r.quiet_frames, 29);
  EXPECT_EQ(r.quiet_alarm_frames, 2);
  EXPECT_DOUBLE_EQ(*r.false_alarm_rate(), 2.0 / 29);
  EXPECT_EQ(r.still_frames, 10);
  EXPECT_EQ(r.still_alarm_frames, 1);
  ASSERT_EQ(r.contacts.size(), 1u);
  EXPECT_EQ(r.contacts[0].frame, 29);
  EXPECT_DOUBLE_EQ(r.contacts[0].t_s, 3.625);
  ASSERT_TRUE(r.contacts[0].lead_s);
  EXPECT_DOUBLE_EQ(*r.contacts[0].lead_s, 0.75);  // first alarm at frame 23 after still frame 9
  EXPECT_EQ(r.contacts[0].last_frames, 21);       // frames 9..29: t in [1.125, 3.625]
  EXPECT_EQ(r.contacts[0].last_alarm_frames, 7);  // 23..29
  EXPECT_DOUBLE_EQ(*r.contacts[0].recall_last(), 1.0 / 3);
  EXPECT_EQ(r.distance_frames, 9);                       // frame 40 has no obstacle
  EXPECT_NEAR(*r.distance_rel_error_median, 0.2, 1e-9);  // 0.1 x4, 0.2 x4, 0.5

  const nlohmann::json j = r.to_json();
  EXPECT_EQ(j["due_alarm_frames"], 8);
  EXPECT_EQ(j["contacts"][0]["frame"], 29);
  EXPECT_DOUBLE_EQ(j["contacts"][0]["lead_s"].get<double>(), 0.75);
  EXPECT_EQ(j["matched_by"], "frame");
  const std::string table = r.table();
  EXPECT_NE(table.find("lead 0.75 s"), std::string::npos) << table;
  EXPECT_NE(table.find("recall (due)      0.800"), std::string::npos) << table;
}

TEST(TruthScore, LeadIgnoresAlarmsBeforeTheLastQuietFrameAndBeyondTheHorizon) {
  TruthCriteria c;
  const TruthLog log = parse_truth_log(scenario_log(), "x");
  {
    // Alarms only on still frames: no lead, and nothing in the last 2.5 s after frame 9.
    TruthScorer scorer(derive_truth(log, c, 0.125), c);
    for (int f = 0; f < 50; ++f) scorer.add(detection(f, f >= 5 && f <= 9));
    const TruthReport r = scorer.report();
    ASSERT_EQ(r.contacts.size(), 1u);
    EXPECT_FALSE(r.contacts[0].lead_s);
    EXPECT_EQ(r.contacts[0].last_alarm_frames, 1);  // frame 9 is in [1.125, 3.625]
    EXPECT_NE(r.table().find("lead never"), std::string::npos);
  }
  {
    // Every frame alarms: the lead starts after the last quiet frame (9): 3.625 - 1.25.
    TruthScorer scorer(derive_truth(log, c, 0.125), c);
    for (int f = 0; f < 50; ++f) scorer.add(detection(f, true));
    const TruthReport r = scorer.report();
    EXPECT_DOUBLE_EQ(*r.contacts[0].lead_s, 2.375);
    EXPECT_DOUBLE_EQ(*r.contacts[0].recall_last(), 1.0);
  }
  {
    // Without phases (a log of distances only): quiet = not approaching. Frames 0-5 are (their
    // +-0.5 s windows lie in the still part), frame 6's window reaches frame 10 (0.067 m/s).
    std::string text = scenario_log();
    std::ostringstream only;
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line)) {
      const auto first = line.find(',');
      const auto second = line.find(',', first + 1);
      const auto third = line.find(',', second + 1);
      only << line.substr(0, second) << line.substr(third) << "\n";  // drop the phase
    }
    const TruthLog plain = parse_truth_log(only.str(), "x");
    ASSERT_FALSE(plain.has_phase);
    {
      TruthScorer scorer(derive_truth(plain, c, 0.125), c);
      for (int f = 0; f < 50; ++f) scorer.add(detection(f, f >= 3 && f <= 29));
      // The first alarm after the last quiet frame (5); horizon + 2 s reach back to t = -1.375.
      EXPECT_DOUBLE_EQ(*scorer.report().contacts[0].lead_s, 3.625 - 6 * 0.125);
    }
    // A 0.5 s horizon: alarms count from t = 3.625 - 2.5 = 1.125 (frame 9) on.
    c.horizon_s = 0.5;
    TruthScorer scorer(derive_truth(plain, c, 0.125), c);
    for (int f = 0; f < 50; ++f) scorer.add(detection(f, f >= 3 && f <= 29));
    EXPECT_DOUBLE_EQ(*scorer.report().contacts[0].lead_s, 2.5);
  }
}

TEST(TruthScore, FramesBeyondTheLogAndRowsBeyondTheFrames) {
  TruthCriteria c;
  const TruthLog log = parse_truth_log(scenario_log(40), "x");
  {
    TruthScorer scorer(derive_truth(log, c, 0.125), c);
    for (int f = 0; f < 46; ++f) scorer.add(detection(f, f == 44));
    const TruthReport r = scorer.report();
    EXPECT_EQ(r.frames, 46);
    EXPECT_EQ(r.scored_frames, 40);
    EXPECT_EQ(r.unscored_frames, 6);
    EXPECT_EQ(r.alarm_frames, 1);
    EXPECT_EQ(r.quiet_alarm_frames, 0);  // frame 44 is unscored
    EXPECT_NE(r.table().find("unscored frames   6"), std::string::npos) << r.table();
  }
  {
    TruthScorer scorer(derive_truth(log, c, 0.125), c);
    for (int f = 0; f < 25; ++f) scorer.add(detection(f, false));
    const TruthReport r = scorer.report();
    EXPECT_EQ(r.scored_frames, 25);
    EXPECT_EQ(r.rows_past_last_frame, 15);
    EXPECT_TRUE(r.contacts.empty());  // the contact (frame 29) is past the frames
  }
}

TEST(TruthScore, MatchesByNearestTimeWithoutAFrameColumn) {
  // Rows every 0.1 s from 0 to 1.0; frames every 0.1 s with a clock 0.03 s late, up to 1.3 s.
  std::vector<std::pair<double, double>> rows;
  for (int i = 0; i <= 10; ++i) rows.emplace_back(i * 0.1, 2.0);
  TruthCriteria c;
  TruthScorer scorer(derive_truth(parse_truth_log(distance_log(rows), "x"), c, 0.1), c);
  for (int i = 0; i <= 13; ++i) {
    core::Detection d = detection(i, true, {2.2});
    d.time_s = i * 0.1 + 0.03;
    scorer.add(d);
  }
  const TruthReport r = scorer.report();
  EXPECT_FALSE(r.matched_by_frame);
  EXPECT_EQ(r.scored_frames, 11);  // 1.03 is within 0.05 of the last row; 1.13 is not
  EXPECT_EQ(r.unscored_frames, 3);
  EXPECT_EQ(r.quiet_frames, 11);  // standing still
  EXPECT_EQ(r.still_alarm_frames, 11);
  EXPECT_NEAR(*r.distance_rel_error_median, 0.1, 1e-9);
}

TEST(TruthScore, NoDetectionsAndNoDueFrames) {
  TruthCriteria c;
  TruthScorer scorer(derive_truth(parse_truth_log("frame,phase\n0,approach\n", "x"), c, 0.1), c);
  const TruthReport r = scorer.report();
  EXPECT_EQ(r.frames, 0);
  EXPECT_FALSE(r.recall());
  EXPECT_FALSE(r.false_alarm_rate());
  EXPECT_FALSE(r.distance_rel_error_median);
  EXPECT_TRUE(r.to_json()["recall"].is_null());
}

}  // namespace
}  // namespace sg::eval
