#pragma once
// The cores' structs as the messages the stages send, and back: the one place where a core's
// struct becomes its LCM message.
#include "bouncefit/bounce_peak_t.hpp"
#include "bouncefit/fit_update_t.hpp"
#include "fit/fit_session.h"

namespace bouncefit {

fit_update_t ToFitUpdateMsg(const FitUpdate& update);
// What the fit takes of a bounce: its height and sigma, its times in seconds.
PeakInput ToPeakInput(const bounce_peak_t& peak);

}  // namespace bouncefit
