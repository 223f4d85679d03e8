#pragma once
/// Private helpers of the io sources: images to 8-bit gray, and text for messages.
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>

#include "sg/io/gray_image.hpp"

namespace sg::io::detail {

/// `raw` (1 to 4 channels, 8- or 16-bit; 16-bit scaled by 1/257) as 8-bit gray. `what` names the
/// image in the InputError thrown for an unsupported depth or channel count.
cv::Mat to_gray8(const cv::Mat& raw, const std::string& what);
using io::read_gray;  // sg/io/gray_image.hpp
/// "640x480".
std::string size_text(cv::Size size);
/// Throws InputError "size mismatch: <what> is WxH, <expected_what> is WxH" when sizes differ.
void check_size(const cv::Mat& image, cv::Size expected, const std::string& what,
                const std::string& expected_what);

}  // namespace sg::io::detail
