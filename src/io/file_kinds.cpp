#include "sg/io/file_kinds.hpp"

#include <algorithm>
#include <cctype>

namespace sg::io {

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

bool is_image_file(const std::filesystem::path& path) {
  const std::string ext = lower_extension(path);
  for (const char* e : {".png", ".jpg", ".jpeg", ".bmp", ".pgm", ".ppm", ".tif", ".tiff"})
    if (ext == e) return true;
  return false;
}

}  // namespace sg::io
