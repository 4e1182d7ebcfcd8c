#include "pipeline/sound_fusion.h"
#include "msgs/csv_cell.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <stdexcept>

#include "detect/bounce_detector.h"
#include "detect/heard_peaks.h"
#include "msgs/msg_json.h"

namespace bouncefit {
namespace {

int64_t Utime(double t_s, int64_t t0_utime) { return t0_utime + std::llround(t_s * 1e6); }

}  // namespace

void SoundFusion::OnHeard(const impact_t& m, int64_t t0) {
  AudioImpact a;
  a.t_s = SecondsSince(m.utime, t0);
  a.strength = m.strength;
  a.confidence = m.confidence;
  a.snr_db = m.snr_db;
  heard_.push_back(a);
}

impact_t SoundFusion::Seen(double t_s, int64_t t0_utime, std::pair<int, int> key) {
  impact_t m{};
  m.utime = Utime(t_s, t0_utime);
  const auto it = seen_keys_.find(key);
  if (it != seen_keys_.end()) {
    seen_t_s_[it->second.first] = t_s;
    m.index = it->second.second;
  } else {
    seen_t_s_.push_back(t_s);
    m.index = next_seen_index_++;
    seen_keys_[key] = {seen_t_s_.size() - 1, m.index};
  }
  m.source = "video";
  return m;
}

ImpactFusionConfig SoundFusion::FusionConfig() const {
  ImpactFusionConfig fc;
  const double area = std::numbers::pi * ball_.diameter_m * ball_.diameter_m / 4;
  fc.drag_per_m = 0.5 * 1.2 * ball_.drag_coefficient * area / ball_.mass_kg;
  fc.frame_period_s = frame_period_s_;
  return fc;
}

std::vector<bounce_peak_t> SoundFusion::HeardPeaks(const std::vector<bounce_peak_t>& emitted,
                                                   int64_t t0, int64_t now_utime) {
  std::vector<bounce_peak_t> out;
  if (heard_.empty() || emitted.empty() || static_cast<int>(seen_t_s_.size()) < 3) return out;
  std::vector<double> seen = seen_t_s_;
  std::sort(seen.begin(), seen.end());
  const FusionResult live = FuseImpacts(heard_, seen, SecondsSince(now_utime, t0), FusionConfig());
  if (!live.sound_used) return out;
  std::vector<double> apex_t;
  for (const auto& m : emitted) apex_t.push_back(m.bounce > 0 ? SecondsSince(m.apex_utime, t0) : NAN);
  const std::vector<ApexOnArc> on_arc = PlaceApexesOnHeardArcs(apex_t, live);
  for (size_t p = 0; p < emitted.size(); ++p) {
    if (on_arc[p].flight < 0 || on_arc[p].duplicate) continue;
    if (!heard_peaks_.insert({emitted[p].sequence, emitted[p].bounce}).second) continue;
    const HeardFlight& fl = live.flights[on_arc[p].flight];
    bounce_peak_t m = emitted[p];
    m.utime = now_utime;
    m.revision = 1;
    m.height_m = m.flight_height_m = fl.height_m;
    // A flight timed to ~0.1 ms is a height to ~0.05%: a few tenths of a mm.
    m.height_sigma_m = std::min(m.height_sigma_m, std::max(0.002 * fl.height_m, 0.0005));
    m.height_px = NAN;  // not measured in pixels
    m.impact_before_utime = Utime(live.impacts[fl.from].t_s, t0);
    m.impact_after_utime = Utime(live.impacts[fl.from].t_s + fl.flight_s, t0);
    out.push_back(m);
  }
  return out;
}

const FusionResult& SoundFusion::Finish(const std::vector<double>& seen_t_s, double video_end_s,
                                        const std::string& no_sound,
                                        const std::vector<double>& held_releases_t_s) {
  fused_ = FuseImpacts(heard_, seen_t_s, video_end_s, FusionConfig());
  // A heard "flight" across a release from a seen hold is none: the ball was in the hand.
  std::erase_if(fused_.flights, [&](const HeardFlight& fl) {
    const double from = fused_.impacts[fl.from].t_s, to = from + fl.flight_s;
    return std::any_of(held_releases_t_s.begin(), held_releases_t_s.end(),
                       [&](double r) { return from < r && r < to; });
  });
  if (!no_sound.empty()) fused_.verdict = no_sound + ": impacts from the picture only";
  return fused_;
}

std::vector<impact_t> SoundFusion::FusedImpacts(int64_t t0) const {
  std::vector<impact_t> out;
  for (size_t i = 0; i < fused_.impacts.size(); ++i) {
    const FusedImpact& f = fused_.impacts[i];
    impact_t m{};
    m.utime = Utime(f.t_s, t0);
    m.index = static_cast<int32_t>(i);
    m.source = ImpactSourceName(f.source);
    m.strength = f.strength;
    m.confidence = f.confidence;
    m.fused = true;
    out.push_back(m);
  }
  return out;
}

void SoundFusion::WriteImpactsCsv(const std::filesystem::path& dir) const {
  std::ofstream f(dir / "impacts.csv", std::ios::trunc);
  if (!f) throw std::runtime_error("cannot write '" + (dir / "impacts.csv").string() + "'");
  f << "impact,t_s,source,strength,confidence,video_t_s,flight_s,flight_height_m\n";
  for (size_t i = 0; i < fused_.impacts.size(); ++i) {
    const FusedImpact& m = fused_.impacts[i];
    double flight = NAN, height = NAN;
    for (const auto& fl : fused_.flights)
      if (fl.from == static_cast<int>(i)) flight = fl.flight_s, height = fl.height_m;
    const bool heard = m.source != ImpactSource::kVideo;
    f << i << ',' << CsvCell(m.t_s, 6) << ',' << ImpactSourceName(m.source) << ','
      << (heard ? CsvCell(m.strength, 4) : "") << ',' << (heard ? CsvCell(m.confidence, 3) : "") << ','
      << CsvCell(m.video_t_s, 6) << ',' << CsvCell(flight, 6) << ',' << CsvCell(height, 5) << '\n';
  }
}

std::vector<bounce_peak_t> SoundFusion::FinalRows(const std::vector<bounce_peak_t>& peaks,
                                                  const std::vector<AfterRefit>& after_refit,
                                                  int64_t t0, int64_t now_utime,
                                                  std::vector<bounce_peak_t>* withdrawn) const {
  // Impacts heard before the picture's first seen one (the tracker locked on late) begin
  // the drop: the seen bounces move up by their count, and the picture's "release" (its
  // bounce 0) is the apex of the arc that ends at its first seen impact.
  // Those heard before a release from a seen hold are not the drop's (the ball was held).
  const auto held_release = [&](size_t p) { return p < after_refit.size() && after_refit[p].released_from_hold; };
  double first_seen_s = std::numeric_limits<double>::infinity();
  for (const auto& i : fused_.impacts)
    if (!std::isnan(i.video_t_s)) first_seen_s = std::min(first_seen_s, i.t_s);
  double held_since = -std::numeric_limits<double>::infinity();
  for (size_t p = 0; p < peaks.size(); ++p)
    if (const double t = SecondsSince(peaks[p].apex_utime, t0); held_release(p) && t < first_seen_s)
      held_since = std::max(held_since, t);
  const int heard_before = static_cast<int>(std::count_if(
      fused_.impacts.begin(), fused_.impacts.end(),
      [&](const FusedImpact& i) { return i.t_s < first_seen_s && i.t_s > held_since; }));
  // One heard arc holds one apex: a second seen apex on it is the picture splitting the arc,
  // withdrawn, and the bounces after it move down by one. A release from a seen hold is on
  // no heard arc.
  std::vector<double> apex_t;
  for (size_t p = 0; p < peaks.size(); ++p)
    apex_t.push_back((peaks[p].bounce > 0 || heard_before > 0) && !held_release(p)
                         ? SecondsSince(peaks[p].apex_utime, t0)
                         : NAN);
  const std::vector<ApexOnArc> on_arc = PlaceApexesOnHeardArcs(apex_t, fused_);
  // With the sound checked against the picture, its impacts are the drop's: bounce k is the
  // arc after the k-th impact since the release the picture saw (bounces the picture missed
  // or split, heard before it locked on, are counted right).
  // A seen "release" whose hold was not seen, with an impact within twice its fall time
  // before it, was the apex of a bounce the picture came in on, not a release (a hand holds a
  // ball still before it lets go). One from a seen hold is a release.
  std::vector<double> releases;
  for (size_t p = 0; p < peaks.size(); ++p) {
    const bounce_peak_t& m = peaks[p];
    if (m.bounce != 0) continue;
    const double t = SecondsSince(m.apex_utime, t0);
    const double fall_s = std::sqrt(2 * std::max(m.height_m, 0.0) / 9.81);
    if (held_release(p) ||
        std::none_of(fused_.impacts.begin(), fused_.impacts.end(),
                     [&](const FusedImpact& i) { return i.t_s < t && i.t_s >= t - 2 * fall_s; }))
      releases.push_back(t);
  }
  constexpr double kNoRelease = -std::numeric_limits<double>::infinity();
  const auto release_before = [&](double t) {
    double since = kNoRelease;
    for (double r : releases)
      if (r <= t) since = std::max(since, r);
    return since;
  };
  const auto impacts_between = [&](double since, double t) {
    return static_cast<int>(std::count_if(fused_.impacts.begin(), fused_.impacts.end(),
                                          [&](const FusedImpact& i) { return i.t_s > since && i.t_s < t; }));
  };
  // The picture came in on a bounce whose impact nobody heard or saw (the detector numbered
  // its arc from that impact): those impacts count before the first release too.
  int unseen = 0;
  if (!peaks.empty()) {
    const auto first = std::min_element(peaks.begin(), peaks.end(), [](const bounce_peak_t& a, const bounce_peak_t& b) {
      return a.apex_utime < b.apex_utime;
    });
    const double t = SecondsSince(first->apex_utime, t0);
    if (release_before(t) == kNoRelease) unseen = std::max(0, first->bounce - impacts_between(kNoRelease, t));
  }
  const auto impacts_before = [&](double t) {
    const double since = release_before(t);
    return impacts_between(since, t) + (since == kNoRelease ? unseen : 0);
  };
  std::vector<bounce_peak_t> rows;
  std::vector<bool> arc_seen(fused_.flights.size(), false);
  int last_bounce = -1, dropped = 0;
  double first_t = 1e300, last_t = -1e300;
  for (size_t p = 0; p < peaks.size(); ++p) {
    bounce_peak_t m = peaks[p];
    m.utime = now_utime;
    m.live_bounce = peaks[p].bounce;
    if (on_arc[p].duplicate) {
      ++dropped;
      m.revision = 4;
      if (withdrawn) withdrawn->push_back(m);
      continue;
    }
    const double t_s = SecondsSince(m.apex_utime, t0);
    const HeardFlight* fl = on_arc[p].flight >= 0 ? &fused_.flights[on_arc[p].flight] : nullptr;
    if (fl) arc_seen[on_arc[p].flight] = true;
    const AfterRefit after = p < after_refit.size() ? after_refit[p] : AfterRefit{};
    m.revision = 3;
    m.flight_height_m = fl ? fl->height_m : std::isfinite(after.flight_m) ? after.flight_m : m.flight_height_m;
    // The height to use: heard end to end, its flight time; else refitted with the whole drop.
    m.fused_height_m = fl ? fl->height_m : std::isfinite(after.refit_m) ? after.refit_m : m.height_m;
    m.refit_height_m = after.refit_m;
    m.heard = fl ? "both" : "";
    m.bounce = fused_.sound_used ? impacts_before(t_s) : m.live_bounce - dropped + heard_before;
    rows.push_back(m);
    last_bounce = std::max(last_bounce, m.bounce);
    first_t = std::min(first_t, t_s);
    last_t = std::max(last_t, t_s);
  }
  // Bounces heard but not seen: with the sound checked, every heard arc no seen apex is on;
  // a heard train alone, those before the picture found the ball and after the last bounce
  // it saw (too small to see). A hop shorter than the picture can show
  // (BounceDetectorConfig::min_flight_frames frames), or one the picture followed the ball
  // through past its last seen impact without seeing it (detect/watched_arcs.h), is not a
  // bounce a person sees: its impacts stay in impacts.csv.
  const double min_flight_s = BounceDetectorConfig{}.min_flight_frames * frame_period_s_;
  std::vector<std::pair<double, bounce_peak_t>> heard_only;
  const std::vector<bool> watched_unseen = ArcsWatchedUnseen(fused_, picture_);
  for (size_t k = 0; k < fused_.flights.size(); ++k) {
    const HeardFlight& fl = fused_.flights[k];
    if (arc_seen[k]) continue;
    if (fused_.sound_used && watched_unseen[k]) continue;
    if (!fused_.sound_used && (!fl.heard_only || (fl.apex_t_s > first_t && fl.apex_t_s <= last_t)))
      continue;
    if (fl.flight_s < min_flight_s) continue;
    bounce_peak_t m{};
    m.utime = now_utime;
    m.sequence = peaks.empty() ? 0 : peaks.back().sequence;
    m.bounce = fused_.sound_used ? impacts_before(fl.apex_t_s) : fl.apex_t_s < first_t ? fl.from + 1 : ++last_bounce;
    m.live_bounce = -1;
    m.revision = 3;
    m.apex_utime = Utime(fl.apex_t_s, t0);
    m.height_m = m.flight_height_m = m.fused_height_m = fl.height_m;
    m.height_px = m.height_sigma_m = m.refit_height_m = NAN;
    m.height_sigma_m = std::max(0.002 * fl.height_m, 0.0005);
    m.impact_before_utime = Utime(fused_.impacts[fl.from].t_s, t0);
    m.impact_after_utime = Utime(fused_.impacts[fl.from].t_s + fl.flight_s, t0);
    m.heard = "heard only";
    rows.push_back(m);
  }
  std::stable_sort(rows.begin(), rows.end(),
                   [](const bounce_peak_t& a, const bounce_peak_t& b) { return a.apex_utime < b.apex_utime; });
  return rows;
}

nlohmann::json SoundFusion::Summary(const std::string& track_description) const {
  nlohmann::json j;
  j["track"] = track_description;
  j["used"] = fused_.sound_used;
  j["verdict"] = fused_.verdict;
  j["offset_s"] = fused_.offset_s;
  j["heard"] = fused_.heard;
  j["seen"] = fused_.seen;
  j["matched"] = fused_.matched;
  j["rejected_sounds"] = fused_.rejected_sounds;
  j["impacts"] = fused_.impacts.size();
  nlohmann::json clicks = nlohmann::json::array();  // every click heard, impact or not
  for (const auto& a : heard_)
    clicks.push_back({{"t_s", a.t_s}, {"strength", a.strength}, {"snr_db", a.snr_db},
                      {"confidence", a.confidence}});
  j["clicks"] = clicks;
  return j;
}

}  // namespace bouncefit
