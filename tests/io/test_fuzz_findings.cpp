// Regression tests for what the fuzz targets (tests/fuzz) found in the parsers of user input: each
// input below once crashed a parser, made it allocate without bound or hit undefined behaviour;
// now it is a core::InputError naming the file.
#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include "calibration_text.hpp"
#include "io_test_util.hpp"
#include "sg/io/calibration.hpp"
#include "sg/io/config.hpp"
#include "sg/io/sources.hpp"
#include "sg/io/stereo_folder.hpp"
#include "sg/io/stereo_gt.hpp"

namespace sg::io {
namespace {

using testing_util::input_error_of;
using testing_util::ScratchDir;

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// fuzz_pfm: a 17-byte header announcing 65536 x 65536 floats made read_pfm allocate 16 GiB
// before finding the data missing (libFuzzer: out-of-memory).
TEST(FuzzFindings, PfmHeaderLargerThanTheFileIsRefusedBeforeAllocating) {
  ScratchDir dir;
  std::ofstream(dir.path() / "big.pfm", std::ios::binary) << "Pf\n65536 65536\n-1\n";
  const std::string message = input_error_of([&] { read_pfm(dir.path() / "big.pfm"); });
  EXPECT_TRUE(contains(message, "truncated")) << message;
  EXPECT_TRUE(contains(message, "needs 17179869184 bytes of data, the file holds 0")) << message;
  std::ofstream(dir.path() / "short.pfm", std::ios::binary) << "Pf\n2 2\n-1\n"
                                                            << std::string(15, 'x');
  EXPECT_TRUE(contains(input_error_of([&] { read_pfm(dir.path() / "short.pfm"); }),
                       "needs 16 bytes of data, the file holds 15"));
}

// fuzz_datasets_xml: a scale that std::stod refused ("." -> std::invalid_argument, 400 digits ->
// std::out_of_range) escaped find_stereo_gt_pairs as a non-InputError exception.
TEST(FuzzFindings, DatasetsXmlScaleThatIsNotANumberIsAnInputError) {
  for (const std::string& scale :
       std::vector<std::string>{".", "1.2.3", std::string(400, '9'), "0"}) {
    ScratchDir dir;
    std::filesystem::create_directories(dir.path() / "scene1");
    for (const char* f : {"im2.png", "im6.png", "disp2.png"})
      std::ofstream(dir.path() / "scene1" / f);
    std::ofstream(dir.path() / "datasets.xml")
        << "<datasets>\n\tscene1 \"" << scale << "\" \"0\"\n";
    const std::string message = input_error_of([&] { find_stereo_gt_pairs(dir.path(), 0.0); });
    EXPECT_TRUE(contains(message, "datasets.xml:2: scale")) << scale << ": " << message;
  }
  // Valid scales and lines that are not scale lines still work.
  ScratchDir dir;
  std::filesystem::create_directories(dir.path() / "scene1");
  for (const char* f : {"im2.png", "im6.png", "disp2.png"})
    std::ofstream(dir.path() / "scene1" / f);
  std::ofstream(dir.path() / "datasets.xml")
      << "<?xml version=\"1.0\"?>\n<!-- name, scaleFactor, unknValue -->\n\tscene1 \"4\" \"0\"\n";
  const auto pairs = find_stereo_gt_pairs(dir.path(), 0.0);
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_EQ(pairs[0].scale, 4.0);
}

// fuzz_kitti_times: "2011-09-31 00:074327100:00" overflowed int (minutes * 60) in the date
// arithmetic (UBSan: signed integer overflow); fields out of range are not a timestamp.
TEST(FuzzFindings, KittiTimestampWithAFieldOutOfRangeIsAnInputError) {
  for (const std::string line :
       {"2011-09-31 00:074327100:00", "2011-13-01 00:00:00", "2011-00-01 00:00:00",
        "2011-09-26 24:00:00", "2147483647-09-26 13:02:25.9", "-2147483648-01-01 00:00:00",
        "2011-09-2147483647 13:02:25.9", "2011-09-26 13:60:00"}) {
    ScratchDir dir;
    std::ofstream(dir.path() / "timestamps.txt") << "2011-09-26 13:02:25.964389445\n"
                                                 << line << "\n";
    const std::string message =
        input_error_of([&] { read_kitti_times(dir.path() / "timestamps.txt"); });
    EXPECT_TRUE(contains(message, "timestamps.txt:2: not a timestamp")) << line << ": " << message;
  }
  ScratchDir dir;
  std::ofstream(dir.path() / "timestamps.txt")
      << "2011-09-26 13:02:25.964389445\n\n2011-09-26 13:02:26.064389445\n";
  const auto times = read_kitti_times(dir.path() / "timestamps.txt");
  ASSERT_EQ(times.size(), 2u);
  EXPECT_NEAR(times[1] - times[0], 0.1, 1e-9);
}

// Found reading the code behind fuzz_euroc_csv: open_euroc subtracts timestamps, which overflowed
// for a negative stamp next to a large one; strtoll's ERANGE was taken as a stamp.
TEST(FuzzFindings, EurocNegativeOrOverflowingTimestampIsAnInputError) {
  for (const std::string stamp : {"-9223372036854775807", "-5", "99999999999999999999"}) {
    ScratchDir dir;
    std::filesystem::create_directories(dir.path() / "cam0");
    std::ofstream(dir.path() / "cam0" / "data.csv") << "#timestamp [ns],filename\n100,a.png\n"
                                                    << stamp << ",b.png\n";
    const std::string message = input_error_of([&] { read_euroc_csv(dir.path() / "cam0"); });
    EXPECT_TRUE(contains(message, "data.csv:3: timestamp '" + stamp + "'")) << message;
  }
}

// fuzz_calibration: a key like ":dtd" inside a matrix made OpenCV 4.6's YAML reader throw
// std::length_error out of cv::FileStorage::open, past read_opencv_calibration.
TEST(FuzzFindings, OpenCvCalibrationThatOpenCvCannotParseIsAnInputError) {
  ScratchDir dir;
  std::ofstream(dir.path() / "calib.yml")
      << "%YAML:1.0\n---\nM1: !!opencv-matrix\n  rows: 3\n  :dtd \n  data: [1]\n";
  EXPECT_TRUE(contains(input_error_of([&] { read_opencv_calibration(dir.path() / "calib.yml"); }),
                       "cannot parse calibration file"));
  EXPECT_TRUE(contains(input_error_of([&] { read_calibration(dir.path() / "calib.yml"); }),
                       "cannot parse calibration file"));
}

// fuzz_calibration: a file whose top level is a list made cv::FileStorage::operator[] assert
// (cv::Exception "isMap()") when the fields were looked up.
TEST(FuzzFindings, OpenCvCalibrationWhoseTopLevelIsNotAMappingIsAnInputError) {
  ScratchDir dir;
  std::ofstream(dir.path() / "calib.yml") << "%YAML:1.0\n---\n- 1\n";
  EXPECT_TRUE(contains(input_error_of([&] { read_calibration(dir.path() / "calib.yml"); }),
                       "the top level is not a mapping"));
}

// fuzz_calibration: a garbled `rows:` of a matrix made OpenCV allocate 16 GiB for it before
// reading its data (libFuzzer: out-of-memory, malloc(17179869248)).
TEST(FuzzFindings, OpenCvCalibrationMatrixWithHugeRowsIsRefusedBeforeAllocating) {
  for (const std::string rows : {"2147483647", "-3", "65", "\"3\""}) {
    ScratchDir dir;
    std::ofstream(dir.path() / "calib.yml")
        << "%YAML:1.0\n---\nM1: !!opencv-matrix\n  rows: " << rows
        << "\n  cols: 1\n  dt: d\n  data: [1, 2, 3]\n";
    EXPECT_TRUE(contains(input_error_of([&] { read_calibration(dir.path() / "calib.yml"); }),
                         "field 'M1' states rows/cols that are not integers from 0 to 64"))
        << rows;
  }
}

// fuzz_config: a complex YAML key ("? ...") in the config (or a section of it) made yaml-cpp's bad
// conversion escape apply_config_file.
TEST(FuzzFindings, ConfigKeyThatIsNotANameIsAnInputError) {
  ScratchDir dir;
  std::ofstream(dir.path() / "c.yaml") << "stereo:\n?  nu block_size: 4\n";
  core::DetectorParams params;
  RunSettings settings;
  EXPECT_TRUE(
      contains(input_error_of([&] { apply_config_file(dir.path() / "c.yaml", params, settings); }),
               "config has a key that is not a name"));
}

// fuzz_calibration: image_width 2147483647 overflowed int in cv::Size::area() when
// make_rectification compared the stated size with the frames' (UBSan).
TEST(FuzzFindings, CalibrationForHugeImagesIsASizeMismatchNotAnOverflow) {
  ScratchDir dir;
  testing_util::write_calibration_text(dir.path() / "calib.yml",
                                       "250, 0, 160, 0, 250, 120, 0, 0, 1");
  std::ofstream(dir.path() / "calib.yml", std::ios::app)
      << "image_width: 2147483647\nimage_height: 48\n";
  const StereoCalibration calib = read_opencv_calibration(dir.path() / "calib.yml");
  EXPECT_TRUE(contains(input_error_of([&] {
                         make_rectification(calib, {64, 48}, "calib.yml");
                       }),
                       "is for 2147483647x48 images, the frames are 64x48"));
}

// fuzz_stereo_gt: a 22-byte OpenEXR header named .png kept cv::imread busy for seconds (libFuzzer
// slow unit); read_stereo_gt now refuses what is not PNG or PGM before decoding.
TEST(FuzzFindings, GtImageThatIsNotPngOrPgmIsRefusedBeforeDecoding) {
  ScratchDir dir;
  const unsigned char exr[] = {0x76, 0x2f, 0x31, 0x01, 0x02, 0x00, 0x00, 0x00, 0xd5, 0x00, 0x00,
                               0x00, 0x0c, 0x6a, 0x50, 0x20, 0x20, 0x0d, 0x0a, 0x87, 0x0a};
  std::ofstream(dir.path() / "disp.png", std::ios::binary)
      .write(reinterpret_cast<const char*>(exr), sizeof exr);
  for (const double scale : {0.0, 4.0}) {
    EXPECT_TRUE(contains(input_error_of([&] { read_stereo_gt(dir.path() / "disp.png", scale); }),
                         "GT disparity is not a PNG or PGM image"));
  }
  EXPECT_TRUE(contains(input_error_of([&] { read_middlebury_png(dir.path() / "disp.png", 4.0); }),
                       "GT disparity is not a PNG or PGM image"));
}

/// The input error of reading an EuRoC pair whose left sensor.yaml has these resolution and
/// distortion lists (the right one is sound).
std::string euroc_error(const std::string& resolution, const std::string& distortion) {
  ScratchDir dir;
  const auto write = [&dir](const char* name, const std::string& res, const std::string& dist) {
    std::ofstream(dir.path() / name)
        << "T_BS:\n  cols: 4\n  rows: 4\n  data: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]\n"
        << "rate_hz: 20\nintrinsics: [50, 50, 32, 24]\nresolution: " << res
        << "\ndistortion_coefficients: " << dist << "\n";
  };
  write("left.yaml", resolution, distortion);
  write("right.yaml", "[64, 48]", "[0, 0, 0, 0]");
  return input_error_of(
      [&] { read_euroc_calibration(dir.path() / "left.yaml", dir.path() / "right.yaml"); });
}

// fuzz_euroc_calib: `resolution: [5.6e34, 48]` was cast to int (UBSan float-cast-overflow).
TEST(FuzzFindings, EurocResolutionBeyondIntIsAnInputError) {
  EXPECT_TRUE(contains(euroc_error("[5.6e34, 48]", "[0, 0, 0, 0]"),
                       "resolution must be two whole numbers"));
}

// fuzz_euroc_calib: `distortion_coefficients: []` made cv::Mat::reshape throw a cv::Exception,
// which nothing caught (terminate).
TEST(FuzzFindings, EurocEmptyDistortionIsAnInputError) {
  EXPECT_TRUE(contains(euroc_error("[64, 48]", "[]"),
                       "calib.D1: must hold 4, 5, 8, 12 or 14 coefficients, has 0"));
}

// fuzz_kitti_calib: `S_rect_00: 1.242e+43 3.750000e+02` was cast to int (UBSan
// float-cast-overflow), as the EuRoC resolution was.
TEST(FuzzFindings, KittiRectifiedSizeBeyondIntIsAnInputError) {
  ScratchDir dir;
  const auto write = [&](const std::string& size) {
    std::ofstream(dir.path() / "calib_cam_to_cam.txt")
        << "S_rect_00: " << size << "\n"
        << "P_rect_00: 7.2e+02 0 6.0e+02 0 0 7.2e+02 1.7e+02 0 0 0 1 0\n"
        << "S_rect_01: 1.242e+03 3.75e+02\n"
        << "P_rect_01: 7.2e+02 0 6.0e+02 -3.9e+02 0 7.2e+02 1.7e+02 0 0 0 1 0\n";
  };
  for (const char* bad : {"1.242e+43 3.75e+02", "1242.5 375", "0 375", "-1 375"}) {
    write(bad);
    EXPECT_TRUE(contains(
        input_error_of([&] { read_kitti_calibration(dir.path() / "calib_cam_to_cam.txt", 0, 1); }),
        "S_rect_00 must be two whole numbers"))
        << bad;
  }
  write("1.242e+03 3.75e+02");
  const core::Camera cam = read_kitti_calibration(dir.path() / "calib_cam_to_cam.txt", 0, 1);
  EXPECT_EQ(cam.width, 1242);
  EXPECT_EQ(cam.height, 375);
}

// fuzz_calibration: 40 bytes of malformed YAML kept OpenCV 4.6's YAML reader looping for over
// ten minutes. A YAML calibration must now parse with yaml-cpp first, which refuses it at once.
TEST(FuzzFindings, MalformedYamlThatHangsOpenCvIsRefusedFirst) {
  ScratchDir dir;
  std::ofstream(dir.path() / "c.yml", std::ios::binary) << "%YAML:1. 3\n  dt:\xfe\xff\xff\xff"
                                                           "3\n : [-0, 0 [-0, 0]\n";
  EXPECT_TRUE(contains(input_error_of([&] { read_calibration(dir.path() / "c.yml", false); }),
                       "cannot parse"));
}

// fuzz_stereo_gt: a file that starts like a PGM ("P2") but holds DICOM's "DICM" mark at byte
// 128 went to OpenCV's GDCM decoder, which aborted the process. PGMs are parsed by us now.
TEST(FuzzFindings, PgmWithADicomMarkIsAnInputErrorNotADecoderAbort) {
  ScratchDir dir;
  std::string bytes = "P2\x15\x15\x15\x01";
  bytes.resize(128, '\0');
  bytes += "DICM\x15\x15\n";
  std::ofstream(dir.path() / "disp2.png", std::ios::binary) << bytes;
  const std::string message =
      input_error_of([&] { read_stereo_gt(dir.path() / "disp2.png", 4.0); });
  EXPECT_TRUE(contains(message, "not a valid PGM image")) << message;
  // Headers announcing more samples than the file holds, or samples above maxval, are refused.
  std::ofstream(dir.path() / "big.pgm", std::ios::binary) << "P5 65536 65536 255\n";
  EXPECT_TRUE(
      contains(input_error_of([&] { read_stereo_gt(dir.path() / "big.pgm", 1.0); }), "truncated"));
  std::ofstream(dir.path() / "over.pgm", std::ios::binary) << "P2 2 1 10\n3 11\n";
  EXPECT_TRUE(contains(input_error_of([&] { read_stereo_gt(dir.path() / "over.pgm", 1.0); }),
                       "exceeds maxval"));
}

}  // namespace
}  // namespace sg::io

namespace sg::io {
namespace {

// Profiling the fuzz targets: deeply nested flow collections (`[[[[...` from InsertRepeatedBytes)
// cost yaml-cpp one recursion per level up to its limit of a few hundred levels, where it throws
// from deep in the stack: about 4.5 ms per execution of a 320-byte input under ASan against 0.5 ms
// for a real calibration file, and such inputs took over the long runs of every YAML target
// (fuzz_calibration: 2,300 -> 200 exec/s). Files nested more than 32 levels are refused first.
TEST(FuzzFindings, DeeplyNestedYamlIsRefusedBeforeYamlCpp) {
  ScratchDir dir;
  const std::string deep = std::string(33, '[') + "1" + std::string(33, ']');
  const auto write = [&](const char* name, const std::string& text) {
    std::ofstream(dir.path() / name, std::ios::binary) << text;
    return dir.path() / name;
  };
  const auto refused = [&](const std::string& message, const std::filesystem::path& file) {
    return contains(message, file.string()) &&
           contains(message, "collections ([ ] or { }) nested more than 32 levels deep");
  };
  const auto camera = write("camera.yaml", "focal_px: " + deep + "\n");
  EXPECT_TRUE(refused(input_error_of([&] { read_camera_yaml(camera, {64, 48}); }), camera));
  const auto config = write("config.yaml", "stereo: " + deep + "\n");
  EXPECT_TRUE(refused(input_error_of([&] {
                        core::DetectorParams p;
                        RunSettings s;
                        apply_config_file(config, p, s);
                      }),
                      config));
  const auto calib = write("calib.yml", "%YAML:1.0\nM1: " + deep + "\n");
  EXPECT_TRUE(refused(input_error_of([&] { read_calibration(calib, false); }), calib));
  const auto left = write("left.yaml", "intrinsics: " + deep + "\n");
  EXPECT_TRUE(refused(input_error_of([&] { read_euroc_calibration(left, left); }), left));
  // 32 levels are still read (and refused for what they hold, not for the nesting).
  const std::string at_limit = std::string(32, '[') + "1" + std::string(32, ']');
  const auto config32 = write("config32.yaml", "stereo: " + at_limit + "\n");
  const std::string message = input_error_of([&] {
    core::DetectorParams p;
    RunSettings s;
    apply_config_file(config32, p, s);
  });
  EXPECT_TRUE(contains(message, "stereo must be a map")) << message;
}

}  // namespace
}  // namespace sg::io
