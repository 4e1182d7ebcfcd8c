// The gate a final fit passes to be an answer: its heights within max(floor, fraction of the
// highest apex) RMS, every drop of a joint fit within its own, the search's failure and the
// drops' disagreeing restitution no answer.
#include <gtest/gtest.h>

#include "fit/answer_gate.h"

namespace bouncefit {
namespace {

TEST(AnswerGate, HeightsWithinTheLargerOfTheFloorAndTheFractionAreAnAnswer) {
  FitUpdate u;
  u.recorded_m = {0.60, 0.40, 0.25};
  u.simulated_m = {0.61, 0.39, 0.26};
  u.residual_m = 0.01;  // 10 mm: within 5% of 0.60 m (30 mm)
  EXPECT_EQ(WhyNoAnswer(u, false, 0.003, 0.05), "");
  const std::string why = WhyNoAnswer(u, false, 0.003, 0.01);  // 6 mm
  EXPECT_NE(why.find("10.0 mm RMS from the recorded ones, more than 6.0 mm"), std::string::npos) << why;
  EXPECT_EQ(WhyNoAnswer(u, false, 0.012, 0.01), "");  // the floor is larger
  u.warning = "no usable coefficient set found: diverged";
  EXPECT_EQ(WhyNoAnswer(u, true, 0.003, 0.05), u.warning);
  u.restitution.drops_agree = false;
  EXPECT_NE(WhyNoAnswer(u, false, 0.003, 0.05), "");
  u.recorded_m.clear();  // nothing fitted: nothing to gate
  EXPECT_EQ(WhyNoAnswer(u, true, 0.003, 0.05), "");
}

// A joint fit within the gate overall can still miss one drop: blue_rubberbasketball's
// second drop (0.399, 0.250 m) within 15 mm, its first (one rebound of 0.130 m) 23.5 mm off.
TEST(FitSession, AJointAnswerHoldsForEveryDropOrIsNone) {
  FitUpdate u;
  u.recorded_m = {0.399, 0.250, 0.130};  // this drop's two bounces, then the kept drop's one
  u.simulated_m = {0.404, 0.229, 0.1065};
  u.other_drop_bounces = {1};
  const std::string why = DropOutsideItsGate(u, 0.003, 0.05);
  EXPECT_NE(why.find("drop 1 of 2"), std::string::npos) << why;
  EXPECT_NE(why.find("23.5 mm"), std::string::npos) << why;
  u.simulated_m[2] = 0.126;  // 4 mm: within 5% of its 0.130 m
  EXPECT_EQ(DropOutsideItsGate(u, 0.003, 0.05), "");
  u.other_drop_bounces.clear();  // one drop: the overall gate is its gate
  u.simulated_m[2] = 0.1065;
  EXPECT_EQ(DropOutsideItsGate(u, 0.003, 0.05), "");
}

}  // namespace
}  // namespace bouncefit
