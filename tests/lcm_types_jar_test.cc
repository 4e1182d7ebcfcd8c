// lcm-spy decodes our messages only with Java classes whose fingerprints match the C++ ones.
// The jar is built when a JDK and lcm.jar are present (msgs/CMakeLists.txt); skip otherwise.
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>

#include "bouncefit/ball_box_t.hpp"
#include "bouncefit/bounce_peak_t.hpp"
#include "bouncefit/calibration_t.hpp"
#include "bouncefit/fit_update_t.hpp"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

template <class Msg>
void ExpectSameFingerprint(const std::string& jar, const std::string& name) {
  std::string out;
  ASSERT_EQ(testing::RunCommand("javap -cp '" + jar + "' -constants bouncefit." + name, &out), 0)
      << out;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(out, m, std::regex("LCM_FINGERPRINT_BASE = (-?\\d+)l"))) << out;
  const uint64_t java_base = static_cast<uint64_t>(std::stoll(m[1]));
  // C++ getHash() is the base rotated left by one bit.
  const uint64_t cpp_hash = static_cast<uint64_t>(Msg::getHash());
  const uint64_t cpp_base = (cpp_hash >> 1) | (cpp_hash << 63);
  EXPECT_EQ(java_base, cpp_base) << name;
}

TEST(LcmTypesJar, JavaClassesMatchTheCppTypes) {
  const auto jar = std::filesystem::path(BOUNCEFIT_EXE).parent_path() / "msgs" /
                   "bouncefit_lcmtypes.jar";
  if (!std::filesystem::exists(jar))
    GTEST_SKIP() << "no " << jar << " (built only with a JDK and lcm.jar from liblcm-java)";
  std::string out;
  if (testing::RunCommand("javap -version", &out) != 0) GTEST_SKIP() << "no javap";
  ExpectSameFingerprint<ball_box_t>(jar.string(), "ball_box_t");
  ExpectSameFingerprint<calibration_t>(jar.string(), "calibration_t");
  ExpectSameFingerprint<bounce_peak_t>(jar.string(), "bounce_peak_t");
  ExpectSameFingerprint<fit_update_t>(jar.string(), "fit_update_t");
}

}  // namespace
}  // namespace bouncefit
