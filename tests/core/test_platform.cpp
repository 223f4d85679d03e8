#include <gtest/gtest.h>

#include "sg/core/error.hpp"
#include "sg/core/platform.hpp"

namespace sg::core {
namespace {

TEST(Platform, CarPresetSetsItsEnvelopeRangeAndDepthLimits) {
  DetectorParams p;
  apply_platform("car", p);
  EXPECT_DOUBLE_EQ(p.envelope.half_width_m, 1.0);
  EXPECT_DOUBLE_EQ(p.envelope.z_contact_m, 2.0);
  EXPECT_EQ(p.bm.num_disparities, 128);
  EXPECT_DOUBLE_EQ(p.scene_flow.z_max_m, 60.0);
  EXPECT_DOUBLE_EQ(p.stereo.z_max_m, 40.0);
  const Envelope e = platform_envelope("car");
  EXPECT_DOUBLE_EQ(e.y_top_m, p.envelope.y_top_m);
}

TEST(Platform, PresetsOverwriteOneAnotherAndRobotIsTheDefaults) {
  DetectorParams p;
  apply_platform("car", p);
  apply_platform("robot", p);
  const DetectorParams defaults;
  EXPECT_DOUBLE_EQ(p.envelope.half_width_m, defaults.envelope.half_width_m);
  EXPECT_DOUBLE_EQ(p.envelope.z_contact_m, defaults.envelope.z_contact_m);
  EXPECT_EQ(p.bm.num_disparities, defaults.bm.num_disparities);
  EXPECT_DOUBLE_EQ(p.scene_flow.z_max_m, defaults.scene_flow.z_max_m);
  EXPECT_DOUBLE_EQ(p.scene_flow.ground.z_max_m, defaults.scene_flow.ground.z_max_m);
  // "" leaves everything as it is; every preset validates.
  p.envelope.half_width_m = 0.7;
  apply_platform("", p);
  EXPECT_DOUBLE_EQ(p.envelope.half_width_m, 0.7);
  for (const std::string& name : platform_names()) {
    DetectorParams q;
    apply_platform(name, q);
    Camera wide;
    wide.width = 960;
    EXPECT_TRUE(validate(q, wide).empty()) << name;
  }
}

TEST(Platform, UnknownNameListsTheKnownOnes) {
  DetectorParams p;
  try {
    apply_platform("boat", p);
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("boat"), std::string::npos) << what;
    EXPECT_NE(what.find("walker"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace sg::core
