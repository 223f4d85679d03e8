#pragma once
/// The progress bar of `run` and `eval` on a terminal: frames done, frames per second and, when
/// the source knows its length, a bar and the time left. The caller decides whether to show it
/// (stderr is a terminal and --quiet is not given: stderr_is_terminal()).
#include <chrono>
#include <ostream>
#include <string>

namespace sg::io {

/// True when the process's stderr is a terminal.
bool stderr_is_terminal();

/// One progress line, no newline: with a known total (> 0)
/// "[#########...........]  57/143 frames  23.4 fps  ETA 0:04", else "57 frames  23.4 fps".
/// elapsed_s is the time since the first frame was read, s; fps and ETA are left out until it is
/// positive. Another `unit` ("scenes") replaces "frames", and its rate reads "<unit>/s".
std::string progress_line(int done, int total, double elapsed_s,
                          const std::string& unit = "frames");

class ProgressBar {
 public:
  /// Draws on `out` (a terminal); `total` frames, or -1 when unknown. Redraws at most every
  /// `min_interval` (and always for the last frame).
  ProgressBar(std::ostream& out, int total,
              std::chrono::milliseconds min_interval = std::chrono::milliseconds(100),
              std::string unit = "frames");
  /// Records one more frame done and redraws when due.
  void tick();
  /// Erases the line (before other output to the same terminal); the next tick redraws it.
  void clear();
  /// Erases the line for good.
  void finish() { clear(); }

 private:
  using Clock = std::chrono::steady_clock;
  std::ostream& out_;
  int total_;
  std::chrono::milliseconds min_interval_;
  Clock::time_point start_, last_draw_;
  int done_ = 0;
  bool drawn_ = false;
  std::string unit_;
};

}  // namespace sg::io
