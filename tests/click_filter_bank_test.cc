// The click filter bank: half-octave bands from the high-pass up, a tone passing its own
// band and hardly its neighbours', hum and speech's fundamentals removed.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "detect/click_filter_bank.h"

namespace bouncefit {
namespace {

// Each band's mean square of a unit sine at f_hz, after the filters settle.
std::vector<double> BandPowers(ClickFilterBank& bank, double f_hz, int rate) {
  std::vector<double> y(rate / 2), energy(bank.bands(), 0.0);
  for (int i = 0; i < rate / 2; ++i)
    y[i] = bank.HighPass(std::sin(2 * std::numbers::pi * f_hz * i / rate));
  const int settle = rate / 10;
  std::vector<double> scratch(bank.bands(), 0.0);
  bank.AddBandEnergies(y.data(), settle, scratch.data());
  bank.AddBandEnergies(y.data() + settle, rate / 2 - settle, energy.data());
  for (double& e : energy) e /= rate / 2 - settle;
  return energy;
}

TEST(ClickFilterBank, HalfOctaveBandsFromTheHighPassUp) {
  const ClickFilterBank b44(2000, 16000, 2, 44100);
  ASSERT_EQ(b44.bands(), 6);
  EXPECT_NEAR(b44.band_low_hz(0), 2000, 1e-9);
  EXPECT_NEAR(b44.band_high_hz(5), 16000, 1e-6);
  EXPECT_NEAR(b44.band_high_hz(0) / b44.band_low_hz(0), std::sqrt(2.0), 1e-9);
  // A narrow sound track keeps what fits under 0.45 of its rate.
  EXPECT_EQ(ClickFilterBank(2000, 16000, 2, 16000).bands(), 3);
  EXPECT_EQ(ClickFilterBank(2000, 16000, 2, 8000).bands(), 1);
}

TEST(ClickFilterBank, ATonePassesItsBandAndHumDoesNot) {
  const int rate = 44100;
  ClickFilterBank bank(2000, 16000, 2, rate);
  const double centre = std::sqrt(bank.band_low_hz(2) * bank.band_high_hz(2));
  const std::vector<double> p = BandPowers(bank, centre, rate);
  EXPECT_NEAR(p[2], 0.5, 0.05);  // a unit sine's mean square, through at the centre
  EXPECT_LT(p[0], 0.05 * p[2]);
  EXPECT_LT(p[5], 0.05 * p[2]);
  ClickFilterBank again(2000, 16000, 2, rate);
  for (double e : BandPowers(again, 50, rate)) EXPECT_LT(e, 1e-6);  // mains hum
}

}  // namespace
}  // namespace bouncefit
