#pragma once
// Impacts heard and impacts seen, fused. A core with no I/O.
//
// - The audio-video offset: the shift that pairs the most heard impacts with seen ones
//   (within a frame or so), refined to the median of the pairs' differences.
// - Echoes go first: a click soon after a much louder one is that impact heard again.
// - The sound is used only if it agrees with the picture: at least min_matches pairs, and
//   min_match_fraction of the clicks heard during the seen impacts' span paired. Otherwise (a slow-motion file with
//   real-time sound, a dubbed track, music) it is reported and ignored.
// - A pair becomes one impact timed by the sound (source "both"); a seen impact nobody
//   heard stays "video"; heard impacts that continue the bounce train past the last one
//   both heard and seen (flight times shrinking as a bounce train's do) are "audio" (heard only). Other
//   lone sounds are not impacts.
// - A seen-only impact close to a heard one (a quarter of the flight around it, or a frame
//   and the tolerance) is that impact timed poorly by the picture: it pairs with it, or,
//   when the heard one is already paired, it is the picture seeing one impact twice (a
//   small arc split by a noisy sample) and is dropped (FusionResult::merged_seen). This
//   comes before the heard-only trains, so their flights start from the right impacts.
// - Between two heard impacts the flight time gives the apex height with no scale and no
//   frame rate (g dt^2/8, air drag included when the ball's is known).
#include <string>
#include <vector>

#include "detect/impact_detector.h"

namespace bouncefit {

enum class ImpactSource { kAudio, kVideo, kBoth };
const char* ImpactSourceName(ImpactSource s);  // "audio", "video", "both"

struct ImpactFusionConfig {
  double max_offset_s = 0.5;       // search the offset within +-this
  double match_tolerance_s = 0.02; // a heard and a seen impact this close (after the offset) pair
  int min_matches = 3;             // pairs needed; fewer seen impacts cannot check the sound
  // Of the clicks heard while the picture saw impacts (after the offset), at least this
  // fraction must pair with seen ones (small bounces may be too quiet to hear; but a
  // sound full of clicks the picture does not explain is not this drop's).
  double min_match_fraction = 0.6;
  // Heard-only impacts after the last seen one: each flight time at most this much longer
  // than the one before and at least this fraction of it.
  double train_growth = 1.05;
  double train_min_ratio = 0.3;
  // Too few seen (the tracker lost the ball): the heard impacts are listed only if they form
  // a bounce train of at least this many impacts, each flight shorter than the one before
  // by a ratio (the restitution, roughly) within [min, max] that changes by at most
  // ratio_step from one bounce to the next.
  int lone_train_min_impacts = 5;
  double lone_train_min_ratio = 0.45, lone_train_max_ratio = 1.0, lone_train_ratio_step = 0.03;
  double lone_train_echo_s = 0.02;  // a click this soon after an impact is its echo
  // A click this soon after one at least echo_loudness times as loud is its echo off the
  // room's walls (a gym's, 60 ms later), not another impact: sooner than the ball lands again
  // and quieter than its next impact can be. s; ratio.
  double echo_s = 0.1;
  double echo_loudness = 4;
  double frame_period_s = 0;       // the picture's, when known (widens the merge above)
  double g_mps2 = 9.81;
  double drag_per_m = 0;           // k of the deceleration k v^2, 1/m (0: vacuum)
};

struct FusedImpact {
  double t_s = 0;             // video clock
  ImpactSource source = ImpactSource::kVideo;
  double strength = 0;        // heard: the click's peak amplitude (full scale 1)
  double confidence = 0;      // heard: the detector's; seen only: 0
  double video_t_s = 0;       // the seen time (NaN when heard only)
  double audio_t_s = 0;       // the heard time in the sound's own clock (NaN when seen only)
};

// The arc between two consecutive heard impacts.
struct HeardFlight {
  int from = 0;               // index into FusionResult::impacts; the arc ends at from + 1
  double flight_s = 0;
  double apex_t_s = 0;        // video clock
  double height_m = 0;        // ball bottom at the apex, from the flight time
  bool heard_only = false;    // one end was not seen
};

struct FusionResult {
  bool sound_used = false;     // paired with the picture
  bool heard_train_only = false; // too few seen; impacts are a heard bounce train
  std::string verdict;        // one line: why the sound is used or not
  double offset_s = 0;        // heard time = seen time + offset
  int matched = 0;            // pairs
  int seen = 0, heard = 0;    // inputs (heard: within the video's span)
  int rejected_sounds = 0;    // heard clicks that are not impacts of this ball (their echoes too)
  std::vector<double> merged_seen;  // seen impacts (video clock) found to be a heard impact seen twice
  std::vector<FusedImpact> impacts;  // in time order
  std::vector<HeardFlight> flights;
};

// Apex height of a ball bottom between two floor contacts flight_s apart, with quadratic
// drag k (1/m; 0 = g dt^2 / 8).
double FlightTimeHeight(double flight_s, double g_mps2, double drag_per_m);

// heard: the detector's impacts (sound clock as decoded, i.e. the container's alignment);
// seen_t_s: the bounce detector's impact times (video clock), ascending; video_end_s: the
// end of the picture (heard impacts later than it + 1 s are ignored).
FusionResult FuseImpacts(const std::vector<AudioImpact>& heard, const std::vector<double>& seen_t_s,
                         double video_end_s, const ImpactFusionConfig& config = {});

}  // namespace bouncefit
