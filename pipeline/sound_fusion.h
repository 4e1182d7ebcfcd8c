#pragma once
// The detect node's side of the sound: the impacts the capture node heard (IMPACT, source
// "audio") beside the impacts the picture saw, fused (detect/impact_fusion.h) into the
// flight-time heights of the bounces heard end to end, impacts.csv, and the rows of
// peaks.csv (bounces numbered by the impacts heard, and bounces heard but not seen).
#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "bouncefit/bounce_peak_t.hpp"
#include "bouncefit/impact_t.hpp"
#include "detect/impact_fusion.h"
#include "detect/watched_arcs.h"
#include "model/ball_preset.h"

namespace bouncefit {

class SoundFusion {
 public:
  explicit SoundFusion(const BallPreset& ball) : ball_(ball) {}

  // The picture's frame period, s (a seen impact is timed to about a frame).
  void set_frame_period_s(double s) { frame_period_s_ = s; }
  // A frame of the picture (video clock), the ball found in it or not.
  void OnFrame(double t_s, bool found) { picture_.AddFrame(t_s, found); }
  // An impact heard by the capture node (t0: the stream's first frame).
  void OnHeard(const impact_t& m, int64_t t0_utime);
  bool any_heard() const { return !heard_.empty(); }

  // A seen impact as a message. `key` is the detector's (sequence, impact index): an impact
  // the detector revises replaces the earlier one and goes out again with the same index.
  impact_t Seen(double t_s, int64_t t0_utime, std::pair<int, int> key);
  // The peaks emitted so far whose arc was heard from end to end (both impacts, the sound
  // checked against the picture so far), each once: revision 1 of the bounce, with the
  // flight-time height as height_m and flight_height_m (utime: now).
  std::vector<bounce_peak_t> HeardPeaks(const std::vector<bounce_peak_t>& emitted,
                                        int64_t t0_utime, int64_t now_utime);
  bool WasHeard(int sequence, int bounce) const { return heard_peaks_.count({sequence, bounce}) > 0; }

  // The stream ended: fuses every impact heard with the seen ones (video clock, s).
  // no_sound: why nothing could be heard ("no sound track", "--no-audio"; "" if it could).
  // held_releases_t_s: the apexes of the releases from a hold seen still (bounce 0 of their
  // drop): a ball held still is not bouncing, so a heard "flight" across one is no flight,
  // and the release stays the drop's bounce 0, whatever was heard before it.
  const FusionResult& Finish(const std::vector<double>& seen_t_s, double video_end_s,
                             const std::string& no_sound,
                             const std::vector<double>& held_releases_t_s = {});
  const FusionResult& fused() const { return fused_; }

  // What each emitted peak became once its drop ended (NaN where nothing).
  struct AfterRefit {
    double refit_m = std::numeric_limits<double>::quiet_NaN();
    double flight_m = std::numeric_limits<double>::quiet_NaN();
    bool released_from_hold = false;  // bounce 0 of a drop released from a hold seen still
  };
  // After Finish: the rows of peaks.csv as revision-3 messages, in apex order, and the
  // emitted peaks the sound withdrew (revision 4: the picture split one heard arc in two).
  // A release from a seen hold stays bounce 0, and the impacts heard before it are not its
  // drop's bounces.
  std::vector<bounce_peak_t> FinalRows(const std::vector<bounce_peak_t>& emitted,
                                       const std::vector<AfterRefit>& after_refit,
                                       int64_t t0_utime, int64_t now_utime,
                                       std::vector<bounce_peak_t>* withdrawn) const;
  // After Finish: the fused impacts as messages (the rows of impacts.csv, source "both",
  // "audio" or "video", index = row).
  std::vector<impact_t> FusedImpacts(int64_t t0_utime) const;

  // impacts.csv (docs/FORMATS.md).
  void WriteImpactsCsv(const std::filesystem::path& dir) const;
  // The sound's part of summary.json.
  nlohmann::json Summary(const std::string& track_description) const;

 private:
  ImpactFusionConfig FusionConfig() const;

  BallPreset ball_;
  std::vector<AudioImpact> heard_;
  std::vector<double> seen_t_s_;  // seen impacts so far (video clock)
  std::map<std::pair<int, int>, std::pair<size_t, int>> seen_keys_;  // key -> (in seen_t_s_, message index)
  std::set<std::pair<int, int>> heard_peaks_;  // (sequence, bounce) already revised as heard
  FusionResult fused_;
  PictureCoverage picture_;
  int next_seen_index_ = 0;
  double frame_period_s_ = 0;
};

}  // namespace bouncefit
