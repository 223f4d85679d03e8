#pragma once
/// Test helper: an OpenCV YAML stereo calibration written as text, so that a test can leave a
/// field out or put a NaN or a singular matrix in it.
#include <filesystem>
#include <fstream>
#include <string>

namespace sg::io::testing_util {

/// Writes M1 (left out when `m1` is empty; else its 9 numbers as text) and a valid D1 M2 D2 R T:
/// f 250 px, centre (160, 120), baseline 0.12 m.
inline void write_calibration_text(const std::filesystem::path& path, const std::string& m1) {
  std::ofstream out(path);
  auto mat = [&out](const char* name, int rows, int cols, const std::string& data) {
    out << name << ": !!opencv-matrix\n  rows: " << rows << "\n  cols: " << cols
        << "\n  dt: d\n  data: [" << data << "]\n";
  };
  out << "%YAML:1.0\n---\n";
  if (!m1.empty()) mat("M1", 3, 3, m1);
  mat("D1", 1, 5, "0, 0, 0, 0, 0");
  mat("M2", 3, 3, "250, 0, 160, 0, 250, 120, 0, 0, 1");
  mat("D2", 1, 5, "0, 0, 0, 0, 0");
  mat("R", 3, 3, "1, 0, 0, 0, 1, 0, 0, 0, 1");
  mat("T", 3, 1, "-0.12, 0, 0");
}

}  // namespace sg::io::testing_util
