#pragma once
// JSON forms of the bus messages, as written to the run directory (docs/FORMATS.md) and
// printed by `--json`. Times become seconds since `t0_utime` (the stream's first frame).
#include <nlohmann/json.hpp>

#include <cstdint>

#include "bouncefit/ball_box_t.hpp"
#include "bouncefit/bounce_peak_t.hpp"
#include "bouncefit/calibration_t.hpp"
#include "bouncefit/fit_update_t.hpp"

namespace bouncefit {

double SecondsSince(int64_t utime, int64_t t0_utime);

// JSON has no NaN or infinity: an unknown value is null.
nlohmann::json FiniteOrNull(double v);

nlohmann::json ToJson(const ball_box_t& m, int64_t t0_utime);
nlohmann::json ToJson(const calibration_t& m, int64_t t0_utime);
nlohmann::json ToJson(const bounce_peak_t& m, int64_t t0_utime);
nlohmann::json ToJson(const fit_update_t& m, int64_t t0_utime);

}  // namespace bouncefit
