#pragma once
// The cores' structs as the messages the stages send, and back: the one place where a
// calibration, a bounce or a fit update becomes its LCM message.
#include <cstdint>
#include <vector>

#include "bouncefit/bounce_peak_t.hpp"
#include "bouncefit/calibration_t.hpp"
#include "bouncefit/fit_update_t.hpp"
#include "detect/calibrator.h"
#include "detect/detector_events.h"
#include "fit/fit_session.h"

namespace bouncefit {

calibration_t ToCalibrationMsg(const Calibration& c);
// A bounce as first emitted: revision 0, no refit or fused height yet.
bounce_peak_t ToBouncePeakMsg(const BouncePeak& p);
// Drop `d`'s apexes again, each with its height refitted with every arc of the drop when it
// ended (the live one saw only the floor before it; height_px at the live apex's scale),
// `utime` and `emitted_utime` = now_utime, revision 2. Apexes the refit has no height for are left out.
std::vector<bounce_peak_t> RefittedPeakMsgs(const SequenceSummary& d, int64_t now_utime);

fit_update_t ToFitUpdateMsg(const FitUpdate& update);
// What the fit takes of a bounce: its height and sigma, its times in seconds.
PeakInput ToPeakInput(const bounce_peak_t& peak);

}  // namespace bouncefit
