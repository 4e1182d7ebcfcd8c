// The sliding percentile against a sort of the same window, on noise whose level jumps.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <random>
#include <vector>

#include "detect/sliding_percentile.h"

namespace bouncefit {
namespace {

TEST(SlidingPercentile, MatchesASortedWindowToATenthOfADecibel) {
  std::mt19937 rng(3);
  std::exponential_distribution<double> energy(1.0);
  for (const double p : {0.1, 0.3, 0.5, 0.9}) {
    SlidingPercentile sp(200, p);
    std::deque<double> window;
    for (int i = 0; i < 3000; ++i) {
      const double level = i < 1000 ? 1e-6 : i < 2000 ? 1e-2 : 1e-4;  // jumps up, then down
      const double e = level * energy(rng);
      sp.Push(e);
      window.push_back(e);
      if (window.size() > 200) window.pop_front();
      std::vector<double> sorted(window.begin(), window.end());
      std::sort(sorted.begin(), sorted.end());
      const double want = sorted[static_cast<size_t>(p * (sorted.size() - 1))];
      ASSERT_NEAR(10 * std::log10(sp.Value()), 10 * std::log10(want), 0.06) << "p " << p << " push " << i;
    }
    EXPECT_EQ(sp.size(), 200);
  }
}

TEST(SlidingPercentile, EmptyIsZeroAndBadArgumentsThrow) {
  EXPECT_EQ(SlidingPercentile(10, 0.5).Value(), 0.0);
  EXPECT_THROW(SlidingPercentile(0, 0.5), std::invalid_argument);
  EXPECT_THROW(SlidingPercentile(10, 1.0), std::invalid_argument);
}

}  // namespace
}  // namespace bouncefit
