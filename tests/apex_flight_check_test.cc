// An apex of the picture against the flight times around it (detect/apex_flight_check.h):
// flights built from known heights with the drag-free law, the picture right or off.
#include <gtest/gtest.h>

#include <cmath>

#include "detect/apex_flight_check.h"

namespace bouncefit {
namespace {

constexpr double kG = 9.81;
double TimeFor(double h) { return std::sqrt(2 * h / kG); }  // apex to floor, drag-free

ApexFlightInput Flight(double picture_m, double rise_m, double fall_m, double fps) {
  ApexFlightInput in;
  in.picture_m = picture_m;
  in.picture_sigma_m = 0.002;
  in.rise_s = TimeFor(rise_m);
  in.fall_s = std::isfinite(fall_m) ? TimeFor(fall_m) : NAN;
  in.time_sigma_s = 0.3 / fps;
  return in;
}

TEST(ApexFlightCheck, APictureThatAgreesGoesOutAsMeasured) {
  const ApexFlightResult live = CheckApexAgainstFlight(Flight(0.200, 0.203, NAN, 60));
  EXPECT_EQ(live.verdict, ApexVerdict::kAsMeasured);
  EXPECT_NEAR(live.flight_m, 0.203, 1e-9);
  EXPECT_EQ(CheckApexAgainstFlight(Flight(0.200, 0.203, 0.198, 60)).verdict, ApexVerdict::kAsMeasured);
}

TEST(ApexFlightCheck, LiveDisagreementWaitsForTheImpactAfter) {
  // The picture's floor line 3 cm below where the arc touched: the rise says 0.10 m.
  EXPECT_EQ(CheckApexAgainstFlight(Flight(0.130, 0.100, NAN, 120)).verdict, ApexVerdict::kHold);
}

TEST(ApexFlightCheck, BothSidesAgreeingReplaceAPictureOffTheirHeight) {
  const ApexFlightResult r = CheckApexAgainstFlight(Flight(0.130, 0.100, 0.101, 120));
  EXPECT_EQ(r.verdict, ApexVerdict::kFlightHeight);
  EXPECT_NEAR(r.flight_m, 0.1005, 1e-6);
  EXPECT_GT(r.flight_sigma_m, 0);
  EXPECT_LT(r.flight_sigma_m, 0.005);
}

TEST(ApexFlightCheck, SidesThatDisagreeWithEachOtherAndThePictureWithholdIt) {
  // The tail of a thrown ball at 30 fps: the picture 0.074 m, the flight 0.154 m from impact to
  // impact, of which the fall is long (an impact missed after the apex): nothing to trust.
  const double rise = 0.060, fall = 0.290;  // g (t_rise + t_fall)^2 / 8 = 0.154 m
  ASSERT_NEAR(kG * std::pow(TimeFor(rise) + TimeFor(fall), 2) / 8, 0.154, 0.002);
  EXPECT_EQ(CheckApexAgainstFlight(Flight(0.074, rise, fall, 30)).verdict, ApexVerdict::kWithhold);
}

TEST(ApexFlightCheck, AtALowFrameRateTheFlightMeasuresLessAndJudgesLess) {
  // 0.085 m in the picture against 0.066 m by the flight: beyond a 120 fps flight's
  // measurement, within a 30 fps one's (a third of a frame on each impact: 3 and 11 mm a side).
  EXPECT_EQ(CheckApexAgainstFlight(Flight(0.085, 0.066, 0.066, 120)).verdict, ApexVerdict::kFlightHeight);
  EXPECT_EQ(CheckApexAgainstFlight(Flight(0.085, 0.066, 0.066, 30)).verdict, ApexVerdict::kAsMeasured);
}

TEST(ApexFlightCheck, NoImpactBeforeNoCheck) {
  ApexFlightInput in = Flight(0.5, 0.1, 0.1, 60);
  in.rise_s = NAN;
  EXPECT_EQ(CheckApexAgainstFlight(in).verdict, ApexVerdict::kAsMeasured);
}

}  // namespace
}  // namespace bouncefit
