#pragma once
/// What kind of file a path names, from its name: the one place that reads extensions.
#include <filesystem>
#include <string>

namespace sg::io {

/// The extension of `path` with its dot, lower-cased ("IMG.PNG" -> ".png"; "" when none).
std::string lower_extension(const std::filesystem::path& path);

/// True for a name OpenCV's imread reads as a still image: .png, .jpg, .jpeg, .bmp, .pgm, .ppm,
/// .tif, .tiff, in any case.
bool is_image_file(const std::filesystem::path& path);

}  // namespace sg::io
