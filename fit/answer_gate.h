#pragma once
// Whether a final fit is an answer (coefficients written) or none: its heights must be
// within max(floor_m, fraction x the highest recorded apex) RMS of the recorded ones, every
// drop of a joint fit within its own, the drops' restitution must agree, and the search must
// have found a usable point.
#include <string>

#include "fit/fit_update.h"

namespace bouncefit {

// "" for an answer, else why `u` is none (what FitUpdate::no_answer holds). search_failed:
// every point the search tried failed (u.warning says why).
std::string WhyNoAnswer(const FitUpdate& u, bool search_failed, double floor_m, double fraction);

// A joint fit's answer holds for every drop: "" when each drop's fitted heights are within
// max(floor_m, fraction x its highest apex) RMS of its recorded ones, else which drop is not
// (numbered in time: the kept drops, then the fit's own).
std::string DropOutsideItsGate(const FitUpdate& u, double floor_m, double fraction);

}  // namespace bouncefit
