#include "sg/eval/truth_log.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <system_error>

#include "sg/core/error.hpp"

namespace sg::eval {
namespace {

std::string trim(std::string_view s) {
  const auto not_space = [](unsigned char c) { return !std::isspace(c); };
  const auto first = std::find_if(s.begin(), s.end(), not_space);
  const auto last = std::find_if(s.rbegin(), s.rend(), not_space).base();
  return first < last ? std::string(first, last) : std::string();
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::vector<std::string> split_cells(const std::string& line) {
  std::vector<std::string> cells;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    cells.push_back(trim(std::string_view(line).substr(start, comma - start)));
    if (comma == std::string::npos) return cells;
    start = comma + 1;
  }
}

/// Text for a message: at most 40 characters, printable.
std::string shown(const std::string& cell) {
  std::string s = cell.substr(0, 40);
  for (char& c : s)
    if (!std::isprint(static_cast<unsigned char>(c))) c = '?';
  return "'" + s + (cell.size() > 40 ? "...'" : "'");
}

std::optional<double> to_double(const std::string& cell) {
  double v = 0.0;
  const char* end = cell.data() + cell.size();
  const auto r = std::from_chars(cell.data(), end, v);
  if (r.ec != std::errc() || r.ptr != end) return std::nullopt;
  return v;
}

std::optional<int> to_int(const std::string& cell) {
  int v = 0;
  const char* end = cell.data() + cell.size();
  const auto r = std::from_chars(cell.data(), end, v);
  if (r.ec != std::errc() || r.ptr != end) return std::nullopt;
  return v;
}

/// Where a problem is: "<name> line L, column C (<column>)".
struct Where {
  const std::string& name;
  int line;
  std::string at(std::size_t column, const std::string& header) const {
    return name + " line " + std::to_string(line) + ", column " + std::to_string(column + 1) +
           " (" + header + ")";
  }
};

std::optional<double> median(std::vector<double> v) {
  if (v.empty()) return std::nullopt;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  if (v.size() % 2 == 1) return *mid;
  const double upper = *mid;
  return (*std::max_element(v.begin(), mid) + upper) / 2.0;
}

std::optional<double> ratio(int num, int den) {
  if (den == 0) return std::nullopt;
  return static_cast<double>(num) / den;
}

nlohmann::json optional_json(const std::optional<double>& v) {
  return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
}

}  // namespace

TruthLog parse_truth_log(const std::string& text, const std::string& name,
                         const TruthLogOptions& options) {
  TruthLog log;
  log.name = name;
  std::istringstream in(text);
  std::string line;
  int line_no = 0;
  std::vector<std::string> header;
  int header_line = 0;
  constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  std::size_t frame_col = kNone, time_col = kNone, distance_col = kNone, phase_col = kNone;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string content = trim(line);
    if (content.empty() || content[0] == '#') continue;
    std::vector<std::string> cells = split_cells(content);
    if (header.empty()) {
      header_line = line_no;
      for (std::size_t c = 0; c < cells.size(); ++c) {
        if (!cells[c].empty() && to_double(cells[c])) {
          throw core::InputError(name + " line " + std::to_string(line_no) + ": no header row (" +
                                 shown(cells[c]) +
                                 " is a number; the first line names the columns, e.g. "
                                 "frame,t_s,distance_m,phase)");
        }
        for (std::size_t earlier = 0; earlier < c; ++earlier) {
          if (!cells[c].empty() && cells[c] == cells[earlier]) {
            throw core::InputError(name + " line " + std::to_string(line_no) + ": column '" +
                                   cells[c] + "' appears twice (columns " +
                                   std::to_string(earlier + 1) + " and " + std::to_string(c + 1) +
                                   ")");
          }
        }
      }
      header = cells;
      const auto find = [&header](const std::string& column) {
        const auto it = std::find(header.begin(), header.end(), column);
        return it == header.end() ? kNone : static_cast<std::size_t>(it - header.begin());
      };
      frame_col = find("frame");
      time_col = find("t_s");
      phase_col = find("phase");
      if (!options.distance_column.empty()) {
        distance_col = find(options.distance_column);
        if (distance_col == kNone) {
          throw core::InputError(name + " line " + std::to_string(line_no) + ": no column '" +
                                 options.distance_column + "' (the distance column asked for)");
        }
      } else {
        distance_col = find("distance_m");
        if (distance_col == kNone) distance_col = find("board_distance_m");
      }
      if (frame_col == kNone && time_col == kNone) {
        throw core::InputError(name + " line " + std::to_string(line_no) +
                               ": no 'frame' or 't_s' column in the header (" + shown(content) +
                               "); one of them places each row in time");
      }
      if (distance_col == kNone && phase_col == kNone) {
        throw core::InputError(name + " line " + std::to_string(line_no) +
                               ": neither a distance column (distance_m, board_distance_m, or "
                               "--distance-column NAME) nor a 'phase' column: nothing to score");
      }
      log.has_frame = frame_col != kNone;
      log.has_time = time_col != kNone;
      log.has_phase = phase_col != kNone;
      if (distance_col != kNone) log.distance_column = header[distance_col];
      continue;
    }
    const Where where{name, line_no};
    if (cells.size() != header.size()) {
      throw core::InputError(name + " line " + std::to_string(line_no) + ": " +
                             std::to_string(cells.size()) + " cells, the header (line " +
                             std::to_string(header_line) + ") has " +
                             std::to_string(header.size()));
    }
    TruthRow row;
    row.line = line_no;
    if (frame_col != kNone) {
      const std::string& cell = cells[frame_col];
      const std::optional<int> frame = to_int(cell);
      if (!frame || *frame < 0) {
        throw core::InputError(where.at(frame_col, "frame") + ": " + shown(cell) +
                               " is not a frame number (an integer >= 0)");
      }
      if (!log.rows.empty() && *frame <= *log.rows.back().frame) {
        throw core::InputError(where.at(frame_col, "frame") + ": frame " + std::to_string(*frame) +
                               " does not increase (line " + std::to_string(log.rows.back().line) +
                               " has frame " + std::to_string(*log.rows.back().frame) + ")");
      }
      row.frame = frame;
    }
    if (time_col != kNone) {
      const std::string& cell = cells[time_col];
      const std::optional<double> t = to_double(cell);
      if (!t || !std::isfinite(*t)) {
        throw core::InputError(where.at(time_col, "t_s") + ": " + shown(cell) +
                               " is not a time in seconds");
      }
      if (!log.rows.empty() && *t <= *log.rows.back().t_s) {
        std::ostringstream msg;
        msg << where.at(time_col, "t_s") << ": time " << *t << " s does not increase (line "
            << log.rows.back().line << " has " << *log.rows.back().t_s << " s)";
        throw core::InputError(msg.str());
      }
      row.t_s = t;
    }
    if (distance_col != kNone && !cells[distance_col].empty()) {
      const std::string& cell = cells[distance_col];
      const std::optional<double> d = to_double(cell);
      if (!d || !std::isfinite(*d) || *d < 0.0) {
        throw core::InputError(where.at(distance_col, header[distance_col]) + ": " + shown(cell) +
                               " is not a distance (a finite number of metres >= 0, or blank "
                               "for unknown)");
      }
      row.distance_m = d;
    }
    if (phase_col != kNone) row.phase = lower(cells[phase_col]);
    log.rows.push_back(std::move(row));
  }
  if (header.empty()) throw core::InputError(name + ": the truth log is empty (no header row)");
  if (log.rows.empty()) {
    throw core::InputError(name + ": the truth log has a header (line " +
                           std::to_string(header_line) + ") but no data row");
  }
  return log;
}

TruthLog read_truth_log(const std::filesystem::path& path, const TruthLogOptions& options) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw core::InputError("truth log " + path.string() + " does not exist (or is not a file)");
  }
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in) throw core::InputError("cannot read truth log " + path.string());
  return parse_truth_log(text.str(), path.string(), options);
}

std::vector<std::string> default_quiet_phases() {
  return {"still", "creep", "retreat", "quiet", "static", "stop"};
}

std::vector<std::string> parse_phase_list(const std::string& text) {
  std::vector<std::string> phases;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    std::string phase = lower(trim(std::string_view(text).substr(start, comma - start)));
    if (!phase.empty()) phases.push_back(std::move(phase));
    start = comma + 1;
  }
  return phases;
}

std::optional<double> fit_slope(const std::vector<double>& t, const std::vector<double>& y) {
  const std::size_t n = std::min(t.size(), y.size());
  if (n < 2) return std::nullopt;
  double mean_t = 0.0, mean_y = 0.0;
  for (std::size_t i = 0; i < n; ++i) mean_t += t[i], mean_y += y[i];
  mean_t /= static_cast<double>(n);
  mean_y /= static_cast<double>(n);
  double stt = 0.0, sty = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    stt += (t[i] - mean_t) * (t[i] - mean_t);
    sty += (t[i] - mean_t) * (y[i] - mean_y);
  }
  if (!(stt > 0.0)) return std::nullopt;
  return sty / stt;
}

std::vector<TruthFrame> derive_truth(const TruthLog& log, const TruthCriteria& c,
                                     double frame_period_s) {
  std::vector<TruthFrame> out(log.rows.size());
  for (std::size_t i = 0; i < log.rows.size(); ++i) {
    const TruthRow& row = log.rows[i];
    TruthFrame& f = out[i];
    f.frame = row.frame;
    f.t_s = row.t_s ? *row.t_s : *row.frame * frame_period_s;
    f.distance_m = row.distance_m;
    f.phase = row.phase;
  }
  // Closing speed: the rows' times increase, so each centred window is a contiguous range.
  std::size_t lo = 0, hi = 0;
  std::vector<double> ts, ds;
  for (TruthFrame& f : out) {
    while (out[lo].t_s < f.t_s - c.fit_half_window_s) ++lo;
    while (hi < out.size() && out[hi].t_s <= f.t_s + c.fit_half_window_s) ++hi;
    ts.clear();
    ds.clear();
    for (std::size_t j = lo; j < hi; ++j) {
      if (!out[j].distance_m) continue;
      ts.push_back(out[j].t_s);
      ds.push_back(*out[j].distance_m);
    }
    if (static_cast<int>(ts.size()) >= c.fit_min_points) {
      if (const std::optional<double> slope = fit_slope(ts, ds)) f.closing_mps = -*slope;
    }
  }
  for (TruthFrame& f : out) {
    const bool approaching = f.closing_mps && *f.closing_mps > c.min_closing_mps;
    if (approaching && f.distance_m) {
      f.ttc_s = *f.distance_m > c.z_contact_m ? (*f.distance_m - c.z_contact_m) / *f.closing_mps
                                              : 0.0;  // the contact plane is reached
    }
    if (log.has_phase) {
      f.quiet =
          std::find(c.quiet_phases.begin(), c.quiet_phases.end(), f.phase) != c.quiet_phases.end();
      f.still = f.quiet && f.phase == c.still_phase;
    } else {
      f.quiet = f.closing_mps && *f.closing_mps <= c.min_closing_mps;
      f.still = f.quiet && std::abs(*f.closing_mps) < c.min_closing_mps;
    }
    if (c.due_within_m) {
      f.due = !f.quiet && f.distance_m && *f.distance_m <= *c.due_within_m;
    } else {
      f.due = !f.quiet && f.ttc_s && *f.ttc_s >= 0.0 && *f.ttc_s <= c.horizon_s;
    }
  }
  return out;
}

std::optional<double> ContactScore::recall_last() const {
  return ratio(last_alarm_frames, last_frames);
}

std::optional<double> TruthReport::recall() const { return ratio(due_alarm_frames, due_frames); }

std::optional<double> TruthReport::false_alarm_rate() const {
  return ratio(quiet_alarm_frames, quiet_frames);
}

nlohmann::json TruthReport::to_json() const {
  nlohmann::json contacts_json = nlohmann::json::array();
  for (const ContactScore& c : contacts) {
    contacts_json.push_back({{"frame", c.frame},
                             {"t_s", c.t_s},
                             {"lead_s", optional_json(c.lead_s)},
                             {"last_frames", c.last_frames},
                             {"last_alarm_frames", c.last_alarm_frames},
                             {"recall_last", optional_json(c.recall_last())}});
  }
  return {{"frames", frames},
          {"scored_frames", scored_frames},
          {"unscored_frames", unscored_frames},
          {"rows_past_last_frame", rows_past_last_frame},
          {"matched_by", matched_by_frame ? "frame" : "t_s"},
          {"alarm_frames", alarm_frames},
          {"due_frames", due_frames},
          {"due_alarm_frames", due_alarm_frames},
          {"recall", optional_json(recall())},
          {"quiet_frames", quiet_frames},
          {"quiet_alarm_frames", quiet_alarm_frames},
          {"false_alarm_rate", optional_json(false_alarm_rate())},
          {"still_frames", still_frames},
          {"still_alarm_frames", still_alarm_frames},
          {"contacts", contacts_json},
          {"last_window_s", last_window_s},
          {"distance_frames", distance_frames},
          {"distance_rel_error_median", optional_json(distance_rel_error_median)}};
}

std::string TruthReport::table() const {
  std::ostringstream s;
  s << std::fixed;
  const auto value = [&s](const std::optional<double>& v, int digits) {
    if (v)
      s << std::setprecision(digits) << *v;
    else
      s << "-";
  };
  s << "  frames            " << frames << " (" << scored_frames << " scored, matched by "
    << (matched_by_frame ? "frame" : "nearest t_s") << ")\n";
  if (unscored_frames > 0)
    s << "  unscored frames   " << unscored_frames << " (no truth row: past the log or a gap)\n";
  s << "  alarm frames      " << alarm_frames << "\n";
  s << "  due frames        " << due_frames << " (" << due_alarm_frames << " alarm)\n";
  s << "  recall (due)      ";
  value(recall(), 3);
  s << "\n  quiet frames      " << quiet_frames << " (" << quiet_alarm_frames << " alarm)\n";
  s << "  false alarm rate  ";
  value(false_alarm_rate(), 3);
  s << "\n  still frames      " << still_frames << " (" << still_alarm_frames << " alarm)\n";
  for (const ContactScore& c : contacts) {
    s << "  contact frame " << std::setw(4) << c.frame << " t=" << std::setprecision(2) << c.t_s
      << " s  lead ";
    if (c.lead_s)
      s << std::setprecision(2) << *c.lead_s << " s";
    else
      s << "never";
    s << ", recall last " << std::setprecision(1) << last_window_s << " s ";
    value(c.recall_last(), 3);
    s << " (" << c.last_alarm_frames << " of " << c.last_frames << ")\n";
  }
  if (contacts.empty()) s << "  contacts          none in the log\n";
  s << "  distance error    median ";
  if (distance_rel_error_median)
    s << std::setprecision(1) << 100.0 * *distance_rel_error_median << " %";
  else
    s << "-";
  s << " (" << distance_frames << " alarm frames with truth and obstacle)\n";
  return s.str();
}

TruthScorer::TruthScorer(std::vector<TruthFrame> truth, TruthCriteria criteria)
    : truth_(std::move(truth)), criteria_(std::move(criteria)) {
  by_frame_ = !truth_.empty() && truth_.front().frame.has_value();
  if (!by_frame_ && truth_.size() >= 2) {
    std::vector<double> intervals;
    for (std::size_t i = 1; i < truth_.size(); ++i)
      intervals.push_back(truth_[i].t_s - truth_[i - 1].t_s);
    match_tolerance_s_ = median(intervals).value_or(0.0) / 2.0;
  }
  // Both t_s and frames come from clocks written as decimals: allow their rounding.
  match_tolerance_s_ = std::max(match_tolerance_s_, 1e-6);
}

int TruthScorer::match(const core::Detection& d) const {
  if (by_frame_) {
    const auto it =
        std::lower_bound(truth_.begin(), truth_.end(), d.frame,
                         [](const TruthFrame& f, int frame) { return *f.frame < frame; });
    if (it == truth_.end() || *it->frame != d.frame) return -1;
    return static_cast<int>(it - truth_.begin());
  }
  const auto it = std::lower_bound(truth_.begin(), truth_.end(), d.time_s,
                                   [](const TruthFrame& f, double t) { return f.t_s < t; });
  int best = -1;
  double best_gap = 0.0;
  for (auto candidate : {it, it == truth_.begin() ? truth_.end() : it - 1}) {
    if (candidate == truth_.end()) continue;
    const double gap = std::abs(candidate->t_s - d.time_s);
    if (best < 0 || gap < best_gap) {
      best = static_cast<int>(candidate - truth_.begin());
      best_gap = gap;
    }
  }
  return best >= 0 && best_gap <= match_tolerance_s_ ? best : -1;
}

void TruthScorer::add(const core::Detection& d) {
  Scored s;
  s.frame = d.frame;
  s.row = match(d);
  s.alarm = d.signal;
  for (const core::Obstacle& o : d.obstacles)
    if (!s.nearest_m || o.distance_m < *s.nearest_m) s.nearest_m = o.distance_m;
  scored_.push_back(s);
}

TruthReport TruthScorer::report() const {
  TruthReport r;
  r.matched_by_frame = by_frame_;
  r.last_window_s = criteria_.last_window_s;
  r.frames = static_cast<int>(scored_.size());
  std::vector<double> errors;
  // Scored frames in order: index into scored_.
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < scored_.size(); ++i) {
    const Scored& s = scored_[i];
    if (s.alarm) ++r.alarm_frames;
    if (s.row < 0) {
      ++r.unscored_frames;
      continue;
    }
    ++r.scored_frames;
    order.push_back(i);
    const TruthFrame& t = truth_[static_cast<std::size_t>(s.row)];
    if (t.due) {
      ++r.due_frames;
      if (s.alarm) ++r.due_alarm_frames;
    }
    if (t.quiet) {
      ++r.quiet_frames;
      if (s.alarm) ++r.quiet_alarm_frames;
    }
    if (t.still) {
      ++r.still_frames;
      if (s.alarm) ++r.still_alarm_frames;
    }
    if (s.alarm && t.distance_m && *t.distance_m > 0.0 && s.nearest_m) {
      errors.push_back(std::abs(*s.nearest_m - *t.distance_m) / *t.distance_m);
    }
  }
  r.distance_frames = static_cast<int>(errors.size());
  r.distance_rel_error_median = median(errors);

  // Rows past the last frame.
  if (!scored_.empty()) {
    int last_row = -1;
    for (const Scored& s : scored_) last_row = std::max(last_row, s.row);
    if (by_frame_) {
      const int last_frame = scored_.back().frame;
      for (const TruthFrame& t : truth_) r.rows_past_last_frame += *t.frame > last_frame ? 1 : 0;
    } else if (last_row >= 0) {
      r.rows_past_last_frame = static_cast<int>(truth_.size()) - 1 - last_row;
    } else {
      r.rows_past_last_frame = static_cast<int>(truth_.size());
    }
  }

  // Contact events over the scored frames.
  const auto row_of = [this](std::size_t k) -> const TruthFrame& {
    return truth_[static_cast<std::size_t>(scored_[k].row)];
  };
  std::optional<double> previous_distance;
  for (std::size_t n = 0; n < order.size(); ++n) {
    const TruthFrame& t = row_of(order[n]);
    if (!t.distance_m) continue;
    const bool crossed = previous_distance && *previous_distance > criteria_.z_contact_m &&
                         *t.distance_m <= criteria_.z_contact_m;
    previous_distance = t.distance_m;
    if (!crossed) continue;
    ContactScore c;
    c.frame = scored_[order[n]].frame;
    c.t_s = t.t_s;
    const double earliest = c.t_s - (criteria_.horizon_s + criteria_.lead_slack_s);
    std::optional<std::size_t> first_alarm;
    for (std::size_t m = n + 1; m-- > 0;) {
      const TruthFrame& before = row_of(order[m]);
      if (m < n && before.quiet) break;
      if (before.t_s < earliest) break;
      if (scored_[order[m]].alarm) first_alarm = m;
    }
    if (first_alarm) c.lead_s = c.t_s - row_of(order[*first_alarm]).t_s;
    for (std::size_t m = n + 1; m-- > 0;) {
      const TruthFrame& before = row_of(order[m]);
      if (before.t_s < c.t_s - criteria_.last_window_s) break;
      ++c.last_frames;
      if (scored_[order[m]].alarm) ++c.last_alarm_frames;
    }
    r.contacts.push_back(c);
  }
  return r;
}

}  // namespace sg::eval
