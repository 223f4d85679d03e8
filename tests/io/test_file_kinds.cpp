// File kinds from names: the one extension reader of the io layer.
#include "sg/io/file_kinds.hpp"

#include <gtest/gtest.h>

namespace sg::io {
namespace {

TEST(FileKinds, ExtensionsAreReadInAnyCase) {
  EXPECT_EQ(lower_extension("a/B.PNG"), ".png");
  EXPECT_EQ(lower_extension("calib.Yaml"), ".yaml");
  EXPECT_EQ(lower_extension("dir.d/noext"), "");
  EXPECT_EQ(lower_extension("archive.tar.GZ"), ".gz");
}

TEST(FileKinds, StillImagesAreWhatImreadReads) {
  for (const char* name :
       {"x.png", "x.JPG", "x.jpeg", "x.bmp", "x.pgm", "x.PPM", "x.tif", "x.TIFF"})
    EXPECT_TRUE(is_image_file(name)) << name;
  for (const char* name : {"x.flo", "x.pfm", "x.yaml", "x.mp4", "png", "x.png.txt"})
    EXPECT_FALSE(is_image_file(name)) << name;
}

}  // namespace
}  // namespace sg::io
