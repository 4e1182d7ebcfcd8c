#pragma once
// Where a fit's drops sit on the run's timeline, so that every output puts the fitted ball
// where the fit started it: at each drop's start apex (its time and height) and with each
// fitted height paired with its bounce in peaks.csv. The fit itself knows bounces by the
// number they were first emitted with and heights without times; this joins the two.
#include <nlohmann/json.hpp>

#include <cmath>
#include <string>
#include <vector>

#include "fit/fit_update.h"
#include "model/ball_model.h"

namespace bouncefit {

struct FitDrop {
  int drop = 0;                  // peaks.csv's `drop` (several clips: in that clip's peaks.csv)
  std::string clip;              // several clips: the clip's directory ("" for one clip)
  int start_bounce = 0;          // peaks.csv bounce of the apex the simulated ball starts from
  double start_t_s = std::nan("");  // its apex time, s since the first frame (peaks.csv's clock)
  double start_height_m = 0;     // its height, m
  std::vector<int> bounces;      // peaks.csv bounce of each fitted height
  std::vector<double> apex_t_s;  // their apex times (peaks.csv's clock; NaN: unknown)
  std::vector<double> recorded_m, simulated_m;  // the fit's, for these bounces
};

// A fit's heights per drop, in FitUpdate's order: its own drop, then each of other_drop_*.
struct FitDropSlice {
  size_t first = 0, count = 0;  // in recorded_m / simulated_m
  double start_height_m = 0;
};
std::vector<FitDropSlice> FitDropSlices(const FitUpdate& u);

// coefficients.json's "drops" (docs/FORMATS.md).
nlohmann::json FitDropsToJson(const std::vector<FitDrop>& drops);

// Seconds of the run's clock per simulated (real) second. Heights are measured in real
// seconds, apex times on the stamps' clock: 1 for a clip on real time, the slow-down for a
// file whose stamps are slowed. Measured from the fitted apexes' times since each drop's
// start against the simulated ones (fit through the origin); within 15% of 1 it is 1 (drag
// and the fit's timing aside), within 5% of a whole slow-down it is that; 1 without times.
double RunSecondsPerRealSecond(const std::vector<FitDrop>& drops,
                               const std::vector<std::vector<double>>& simulated_apex_times_s);

// The fitted ball dropped from a drop's start apex, its trajectory sampled at rate_hz for
// duration_s (s, real) or until its hops fall under min_hop_m (the ball's contact chatter,
// BallPreset::chatter_hop_m: a big ball's centimetre hops are not flights).
SimulationResult SimulateFromStart(const BallModel& model, const CoefficientValues& values,
                                   double start_height_m, double duration_s, double min_hop_m,
                                   double rate_hz = 120);

}  // namespace bouncefit
