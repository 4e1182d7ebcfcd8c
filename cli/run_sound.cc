#include "cli/run_sound.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "detect/bounce_detector.h"
#include "detect/heard_peaks.h"
#include "msgs/msg_json.h"

namespace bouncefit::cli {
namespace {

double CpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

std::string Cell(double v, const char* format) {
  if (!std::isfinite(v)) return "";
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

int64_t Utime(double t_s, int64_t t0_utime) { return t0_utime + std::llround(t_s * 1e6); }

}  // namespace

RunSound::RunSound(const std::string& clip, const BallPreset& ball) : ball_(ball) {
  if (clip.empty()) {
    description_ = "no sound";
    return;
  }
  auto source = std::make_unique<AudioFileSource>(clip);
  if (!source->has_audio()) {
    description_ = "no sound track";
    return;
  }
  description_ = source->Describe();
  detector_ = std::make_unique<ImpactDetector>(ImpactDetectorConfig{}, source->sample_rate());
  source_ = std::move(source);
}

RunSound::RunSound(const AlsaMicrophoneConfig& mic, const BallPreset& ball) : ball_(ball) {
  mic_ = std::make_unique<MicrophoneReader>(mic);
  description_ = mic_->Describe();
  detector_ = std::make_unique<ImpactDetector>(ImpactDetectorConfig{}, mic_->sample_rate());
}

RunSound::~RunSound() = default;

void RunSound::Listen(const AudioChunk& chunk, double shift_s, int64_t t0_utime,
                      std::vector<impact_t>* out) {
  const size_t before = heard_.size();
  const double t0 = chunk.t0_s - shift_s;
  if (std::isnan(first_sample_t_s_)) first_sample_t_s_ = t0;
  Envelope(chunk, t0);
  for (const auto& i : detector_->Push(t0, chunk.samples.data(), chunk.samples.size()))
    heard_.push_back(i);
  decoded_to_s_ = t0 + static_cast<double>(chunk.samples.size()) / chunk.sample_rate;
  Publish(before, t0_utime, out);
}

void RunSound::Envelope(const AudioChunk& chunk, double t0_s) {
  const size_t n = chunk.samples.size();
  const double rate = chunk.sample_rate;
  for (size_t i = 0; i < n;) {
    const auto bin = static_cast<int64_t>(std::floor((t0_s + i / rate) / kWaveBinS));
    const auto end = std::clamp<size_t>(
        static_cast<size_t>(std::ceil(((bin + 1) * kWaveBinS - t0_s) * rate)), i + 1, n);
    float peak = 0;
    for (size_t k = i; k < end; ++k) peak = std::max(peak, std::abs(chunk.samples[k]));
    if (wave_peak_.empty()) wave_first_bin_ = bin;
    if (bin >= wave_first_bin_) {
      const auto at = static_cast<size_t>(bin - wave_first_bin_);
      if (at >= wave_peak_.size()) wave_peak_.resize(at + 1, 0.0f);
      wave_peak_[at] = std::max(wave_peak_[at], peak);
    }
    i = end;
  }
}

void RunSound::WriteWaveformCsv(const std::filesystem::path& dir) const {
  if (wave_peak_.empty()) return;
  std::ofstream f(dir / "waveform.csv", std::ios::trunc);
  if (!f) throw std::runtime_error("cannot write '" + (dir / "waveform.csv").string() + "'");
  f << "t_s,peak\n";
  // In the video's clock, like every other time: the sound's offset from the picture removed.
  const double shift = fused_.sound_used ? fused_.offset_s : 0;
  for (size_t k = 0; k < wave_peak_.size(); ++k)
    f << Cell((wave_first_bin_ + static_cast<int64_t>(k)) * kWaveBinS - shift, "%.4f") << ','
      << Cell(wave_peak_[k], "%.4f") << '\n';
}

void RunSound::Publish(size_t from, int64_t t0_utime, std::vector<impact_t>* out) {
  for (size_t k = from; k < heard_.size(); ++k) {
    impact_t m;
    m.utime = Utime(heard_[k].t_s, t0_utime);
    m.index = next_index_++;
    m.source = "audio";
    m.strength = heard_[k].strength;
    m.confidence = heard_[k].confidence;
    out->push_back(m);
  }
}

std::vector<impact_t> RunSound::AdvanceTo(double t_s, int64_t t0_utime) {
  std::vector<impact_t> out;
  if (!enabled() || ended_) return out;
  const double cpu0 = CpuSeconds();
  if (mic_) {
    // Live: whatever the microphone heard so far; its CLOCK_MONOTONIC is the frames' clock.
    for (const AudioChunk& chunk : mic_->Take()) Listen(chunk, t0_utime * 1e-6, t0_utime, &out);
  } else {
    AudioChunk chunk;
    while (decoded_to_s_ < t_s) {
      if (!source_->Next(&chunk)) {
        ended_ = true;
        const size_t before = heard_.size();
        for (const auto& i : detector_->Finish()) heard_.push_back(i);
        Publish(before, t0_utime, &out);
        break;
      }
      Listen(chunk, 0, t0_utime, &out);
    }
  }
  cpu_s_ += CpuSeconds() - cpu0;
  return out;
}

std::vector<impact_t> RunSound::EndLive(int64_t t0_utime) {
  std::vector<impact_t> out;
  if (!mic_ || ended_) return out;
  mic_->Stop();
  out = AdvanceTo(0, t0_utime);
  ended_ = true;
  const size_t before = heard_.size();
  for (const auto& i : detector_->Finish()) heard_.push_back(i);
  Publish(before, t0_utime, &out);
  return out;
}

impact_t RunSound::Seen(double t_s, int64_t t0_utime, std::pair<int, int> key) {
  impact_t m;
  m.utime = Utime(t_s, t0_utime);
  const auto it = seen_keys_.find(key);
  if (it != seen_keys_.end()) {
    seen_t_s_[it->second.first] = t_s;
    m.index = it->second.second;
  } else {
    seen_t_s_.push_back(t_s);
    m.index = next_index_++;
    seen_keys_[key] = {seen_t_s_.size() - 1, m.index};
  }
  m.source = "video";
  m.strength = 0;
  m.confidence = 0;
  return m;
}

ImpactFusionConfig RunSound::FusionConfig() const {
  ImpactFusionConfig fc;
  const double area = std::numbers::pi * ball_.diameter_m * ball_.diameter_m / 4;
  fc.drag_per_m = 0.5 * 1.2 * ball_.drag_coefficient * area / ball_.mass_kg;
  fc.frame_period_s = frame_period_s_;
  return fc;
}

std::vector<bounce_peak_t> RunSound::HeardPeaks(const std::vector<bounce_peak_t>& published,
                                                int64_t t0, int64_t now_utime) {
  std::vector<bounce_peak_t> out;
  if (!enabled() || published.empty() || static_cast<int>(seen_t_s_.size()) < 3) return out;
  std::vector<double> seen = seen_t_s_;
  std::sort(seen.begin(), seen.end());
  const FusionResult live = FuseImpacts(heard_, seen, SecondsSince(now_utime, t0), FusionConfig());
  if (!live.sound_used) return out;
  std::vector<double> apex_t;
  for (const auto& m : published) apex_t.push_back(m.bounce > 0 ? SecondsSince(m.apex_utime, t0) : NAN);
  const std::vector<ApexOnArc> on_arc = PlaceApexesOnHeardArcs(apex_t, live);
  for (size_t p = 0; p < published.size(); ++p) {
    if (on_arc[p].flight < 0 || on_arc[p].duplicate) continue;
    if (!heard_peaks_.insert({published[p].sequence, published[p].bounce}).second) continue;
    const HeardFlight& fl = live.flights[on_arc[p].flight];
    bounce_peak_t m = published[p];
    m.utime = m.emitted_utime = now_utime;
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

const FusionResult& RunSound::Finish(const std::vector<double>& seen_t_s, double video_end_s) {
  if (enabled() && !mic_) AdvanceTo(1e300, 0);
  const ImpactFusionConfig fc = FusionConfig();
  fused_ = FuseImpacts(heard_, seen_t_s, video_end_s, fc);
  if (!enabled()) fused_.verdict = description_ + ": impacts from the picture only";
  finished_ = true;
  return fused_;
}

void RunSound::WriteImpactsCsv(const std::filesystem::path& dir) const {
  std::ofstream f(dir / "impacts.csv", std::ios::trunc);
  if (!f) throw std::runtime_error("cannot write '" + (dir / "impacts.csv").string() + "'");
  f << "impact,t_s,source,strength,confidence,video_t_s,flight_s,flight_height_m\n";
  for (size_t i = 0; i < fused_.impacts.size(); ++i) {
    const FusedImpact& m = fused_.impacts[i];
    double flight = NAN, height = NAN;
    for (const auto& fl : fused_.flights)
      if (fl.from == static_cast<int>(i)) flight = fl.flight_s, height = fl.height_m;
    const bool heard = m.source != ImpactSource::kVideo;
    f << i << ',' << Cell(m.t_s, "%.6f") << ',' << ImpactSourceName(m.source) << ','
      << (heard ? Cell(m.strength, "%.4f") : "") << ',' << (heard ? Cell(m.confidence, "%.3f") : "")
      << ',' << Cell(m.video_t_s, "%.6f") << ',' << Cell(flight, "%.6f") << ','
      << Cell(height, "%.5f") << '\n';
  }
}

void RunSound::RewritePeaksCsv(const std::filesystem::path& dir,
                               const std::vector<bounce_peak_t>& peaks,
                               const std::vector<AfterRefit>& after_refit, int64_t t0) const {
  const auto path = dir / "peaks.csv";
  const std::string tmp = path.string() + ".tmp";
  std::ofstream f(tmp, std::ios::trunc);
  if (!f) throw std::runtime_error("cannot write '" + tmp + "'");
  f << "bounce,t_s,height_m,height_px,flight_height_m,emitted_t_s,heard,fused_height_m,refit_height_m\n";
  // Impacts heard before the picture's first seen one (the tracker locked on late) begin
  // the drop: the seen bounces move up by their count, and the picture's "release" (its
  // bounce 0) is the apex of the arc that ends at its first seen impact.
  int heard_before = 0;
  for (const auto& i : fused_.impacts) {
    if (!std::isnan(i.video_t_s)) break;
    ++heard_before;
  }
  // One heard arc holds one apex: a second seen apex on it is the picture splitting the arc,
  // dropped, and the bounces after it move down by one.
  std::vector<double> apex_t;
  for (const auto& m : peaks)
    apex_t.push_back(m.bounce > 0 || heard_before > 0 ? SecondsSince(m.apex_utime, t0) : NAN);
  const std::vector<ApexOnArc> on_arc = PlaceApexesOnHeardArcs(apex_t, fused_);
  // With the sound checked against the picture, its impacts are the drop's: bounce k is the
  // arc after the k-th impact since the release the picture saw (bounces the picture missed
  // or split, heard before it locked on, are counted right).
  // A seen "release" with an impact within twice its fall time before it was the apex of a
  // bounce the picture came in on, not a release (a hand holds a ball still before it lets go).
  std::vector<double> releases;
  for (const auto& m : peaks) {
    if (m.bounce != 0) continue;
    const double t = SecondsSince(m.apex_utime, t0);
    const double fall_s = std::sqrt(2 * std::max(m.height_m, 0.0) / 9.81);
    if (std::none_of(fused_.impacts.begin(), fused_.impacts.end(),
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
  std::vector<std::pair<double, std::string>> rows;  // apex time, line
  std::vector<bool> arc_seen(fused_.flights.size(), false);
  int last_bounce = -1, dropped = 0;
  double first_t = 1e300, last_t = -1e300;
  for (size_t p = 0; p < peaks.size(); ++p) {
    const bounce_peak_t& m = peaks[p];
    if (on_arc[p].duplicate) {
      ++dropped;
      continue;
    }
    const double t_s = SecondsSince(m.apex_utime, t0);
    const HeardFlight* fl = on_arc[p].flight >= 0 ? &fused_.flights[on_arc[p].flight] : nullptr;
    if (fl) arc_seen[on_arc[p].flight] = true;
    const AfterRefit after = p < after_refit.size() ? after_refit[p] : AfterRefit{};
    const double flight_h = fl ? fl->height_m : std::isfinite(after.flight_m) ? after.flight_m : m.flight_height_m;
    // The height to use: heard end to end, its flight time; else refitted with the whole drop.
    const double use_h = fl ? fl->height_m : std::isfinite(after.refit_m) ? after.refit_m : m.height_m;
    const int bounce = fused_.sound_used ? impacts_before(t_s) : m.bounce - dropped + heard_before;
    std::ostringstream line;
    line << bounce << ',' << Cell(t_s, "%.6f") << ',' << Cell(m.height_m, "%.5f") << ','
         << Cell(m.height_px, "%.3f") << ',' << Cell(flight_h, "%.5f") << ','
         << Cell(SecondsSince(m.emitted_utime, t0), "%.6f") << ',' << (fl ? "both" : "") << ','
         << Cell(use_h, "%.5f") << ',' << Cell(after.refit_m, "%.5f");
    rows.emplace_back(t_s, line.str());
    last_bounce = std::max(last_bounce, bounce);
    first_t = std::min(first_t, t_s);
    last_t = std::max(last_t, t_s);
  }
  // Bounces heard but not seen: with the sound checked, every heard arc no seen apex is on;
  // a heard train alone, those before the picture found the ball and after the last bounce
  // it saw (too small to see).
  // A hop shorter than the picture can show (BounceDetectorConfig::min_flight_frames frames:
  // 3.4 cm at 24 fps) is not listed as a bounce: the detector ends a drop there, and a person
  // watching does not see one. Its impacts stay in impacts.csv.
  const double min_flight_s = BounceDetectorConfig{}.min_flight_frames * frame_period_s_;
  for (size_t k = 0; k < fused_.flights.size(); ++k) {
    const HeardFlight& fl = fused_.flights[k];
    if (arc_seen[k]) continue;
    if (!fused_.sound_used && (!fl.heard_only || (fl.apex_t_s > first_t && fl.apex_t_s <= last_t)))
      continue;
    if (fl.flight_s < min_flight_s) continue;
    const int bounce = fused_.sound_used ? impacts_before(fl.apex_t_s)
                       : fl.apex_t_s < first_t ? fl.from + 1
                                               : ++last_bounce;
    rows.emplace_back(fl.apex_t_s, std::to_string(bounce) + ',' + Cell(fl.apex_t_s, "%.6f") + ',' +
                                       Cell(fl.height_m, "%.5f") + ",," + Cell(fl.height_m, "%.5f") +
                                       ",,heard only," +
                                       Cell(fl.height_m, "%.5f") + ",");
  }
  std::stable_sort(rows.begin(), rows.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& r : rows) f << r.second << '\n';
  f.close();
  std::filesystem::rename(tmp, path);
}

nlohmann::json RunSound::Summary() const {
  nlohmann::json j;
  j["track"] = description_;
  j["used"] = fused_.sound_used;
  j["verdict"] = fused_.verdict;
  j["offset_s"] = fused_.offset_s;
  j["heard"] = fused_.heard;
  j["seen"] = fused_.seen;
  j["matched"] = fused_.matched;
  j["rejected_sounds"] = fused_.rejected_sounds;
  j["impacts"] = fused_.impacts.size();
  j["cpu_s"] = cpu_s_;
  j["first_sample_t_s"] = std::isfinite(first_sample_t_s_) ? nlohmann::json(first_sample_t_s_) : nlohmann::json();
  if (mic_) j["overruns"] = mic_->overruns();
  nlohmann::json heard = nlohmann::json::array();  // every click heard, impact or not
  for (const auto& a : heard_)
    heard.push_back({{"t_s", a.t_s}, {"strength", a.strength}, {"snr_db", a.snr_db},
                     {"confidence", a.confidence}});
  j["clicks"] = heard;
  return j;
}

}  // namespace bouncefit::cli
