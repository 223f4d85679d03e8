#include "sg/io/csv_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "sg/core/error.hpp"

namespace sg::io {
namespace {

/// Fixed `decimals` places; empty when not finite.
std::string fixed(double v, int decimals) {
  if (!std::isfinite(v)) return "";
  std::ostringstream s;
  s << std::fixed << std::setprecision(decimals) << v;
  return s.str();
}

}  // namespace

std::string csv_row(const core::Detection& d, bool timing) {
  std::string regions;
  int dangerous_px = 0;
  for (const auto& r : d.regions) {
    dangerous_px += r.dangerous_px;
    if (!r.fired) continue;
    if (!regions.empty()) regions += ' ';
    regions += r.name;
  }
  std::optional<double> nearest, min_ttc;
  for (const auto& o : d.obstacles) {
    nearest = nearest ? std::min(*nearest, o.distance_m) : o.distance_m;
    if (o.ttc_s) min_ttc = min_ttc ? std::min(*min_ttc, *o.ttc_s) : *o.ttc_s;
  }
  std::ostringstream s;
  s << d.frame << ',' << fixed(d.time_s, 4) << ',' << (d.signal ? 1 : 0) << ','
    << core::to_string(d.severity) << ',' << core::to_string(d.steering) << ',' << regions << ','
    << dangerous_px << ',' << d.obstacles.size() << ',' << (nearest ? fixed(*nearest, 3) : "")
    << ',' << (min_ttc ? fixed(*min_ttc, 3) : "") << ',' << (timing ? fixed(d.latency_ms, 3) : "");
  return s.str();
}

CsvWriter::CsvWriter(const std::filesystem::path& path, bool timing)
    : out_(path, std::ios::trunc), path_(path), timing_(timing) {
  if (!out_) throw core::InputError("--csv: cannot open " + path_.string() + " for writing");
  out_ << kCsvHeader << '\n';
  out_.flush();
}

void CsvWriter::write(const core::Detection& d) {
  out_ << csv_row(d, timing_) << '\n';
  out_.flush();
  if (!out_) throw core::InputError("--csv: cannot write " + path_.string());
}

}  // namespace sg::io
