#include "sg/io/progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <sstream>
#include <utility>

namespace sg::io {

bool stderr_is_terminal() { return ::isatty(STDERR_FILENO) == 1; }

std::string progress_line(int done, int total, double elapsed_s, const std::string& unit) {
  constexpr int kBarWidth = 20;
  std::ostringstream s;
  if (total > 0) {
    const int filled = std::clamp(done * kBarWidth / total, 0, kBarWidth);
    s << '[' << std::string(filled, '#') << std::string(kBarWidth - filled, '.') << "]  " << done
      << '/' << total << ' ' << unit;
  } else {
    s << done << ' ' << unit;
  }
  if (elapsed_s > 0 && done > 0) {
    const double fps = done / elapsed_s;
    s << "  " << std::fixed << std::setprecision(1) << fps
      << (unit == "frames" ? std::string(" fps") : " " + unit + "/s");
    if (total > 0) {
      const long left = std::lround(std::max(0, total - done) / fps);
      s << "  ETA " << left / 60 << ':' << std::setw(2) << std::setfill('0') << left % 60;
    }
  }
  return s.str();
}

ProgressBar::ProgressBar(std::ostream& out, int total, std::chrono::milliseconds min_interval,
                         std::string unit)
    : out_(out),
      total_(total),
      min_interval_(min_interval),
      start_(Clock::now()),
      unit_(std::move(unit)) {}

void ProgressBar::tick() {
  ++done_;
  const Clock::time_point now = Clock::now();
  if (drawn_ && done_ != total_ && now - last_draw_ < min_interval_) return;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  // \r back to the line start, \033[K erase to its end: the line shrinks cleanly.
  out_ << '\r' << progress_line(done_, total_, elapsed, unit_) << "\033[K" << std::flush;
  last_draw_ = now;
  drawn_ = true;
}

void ProgressBar::clear() {
  if (!drawn_) return;
  out_ << "\r\033[K" << std::flush;
  drawn_ = false;
}

}  // namespace sg::io
