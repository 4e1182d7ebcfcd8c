#pragma once
// Seen apexes placed on the arcs the sound heard. A core with no I/O.
//
// Two heard impacts bound one arc, so one arc holds one apex: when the picture split an arc
// in two (a 30 fps clip's few samples per small bounce, a noisy sample read as an impact),
// the apex nearest the heard arc's own apex is the bounce and the others are not.
#include <vector>

#include "detect/impact_fusion.h"

namespace bouncefit {

struct ApexOnArc {
  int flight = -1;         // index into FusionResult::flights (-1: no heard arc holds it)
  bool duplicate = false;  // another seen apex of the same heard arc is nearer its apex
};

// apex_t_s: seen apex times (video clock, s), in any order; returns one entry each.
std::vector<ApexOnArc> PlaceApexesOnHeardArcs(const std::vector<double>& apex_t_s,
                                              const FusionResult& fused);

}  // namespace bouncefit
