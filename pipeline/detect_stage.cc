#include "pipeline/detect_stage.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "msgs/lcm_bus.h"
#include "msgs/node_clock.h"
#include "msgs/msg_json.h"
#include "msgs/peaks_csv.h"
#include "pipeline/clock_report.h"
#include "pipeline/message_mapping.h"
#include "pipeline/output_dir.h"
#include "pipeline/sound_fusion.h"
#include "replay/container_clock.h"

namespace bouncefit {
namespace {

// "; refitted with the whole drop, m: 1 0.733, 2 0.515, ..." for the apexes a drop emitted.
std::string RefitHeights(const SequenceSummary& d) {
  std::string line;
  for (const BouncePeak& p : d.peaks) {
    const double h = d.FinalHeightOf(p.bounce);
    if (std::isfinite(h)) line += fmt::format("{}{} {:.3f}", line.empty() ? " " : ", ", p.bounce, h);
  }
  return line.empty() ? line : "; refitted with the whole drop, m:" + line;
}

}  // namespace

DetectStage::DetectStage(DetectStageConfig config, LcmBus& bus, NoticeFn notice)
    : config_(std::move(config)), bus_(bus), notice_(std::move(notice)) {
  if (!notice_) notice_ = [](const std::string&) {};
  // The scale given, checked before the first frame: the calibrator's rules, not a copy.
  CalibratorConfig& scale = detector_config_.calibration;
  scale.ball_diameter_m = config_.ball.diameter_m;
  scale.px_per_m = config_.px_per_m;
  scale.drop_height_m = config_.drop_height_m;
  std::string error;
  if (!scale.IsValid(&error)) throw std::invalid_argument(error);
  sound_ = std::make_unique<SoundFusion>(config_.ball);
  const Channels& ch = config_.channels;
  bus_.Subscribe<stream_t>(ch.stream, [this](const stream_t& m) { OnStream(m); });
  bus_.Subscribe<ball_box_t>(ch.ball_box, [this](const ball_box_t& m) { OnBox(m); });
  bus_.Subscribe<impact_t>(ch.impact, [this](const impact_t& m) { OnImpact(m); });
  if (!config_.out_dir.empty()) {
    WritePeaksCsv(config_.out_dir / "peaks.csv", {});  // the header, at once
    peaks_csv_ = std::make_unique<std::ofstream>(config_.out_dir / "peaks.csv", std::ios::app);
  }
}

DetectStage::~DetectStage() = default;

void DetectStage::StartStream(int64_t t0_utime) {
  started_ = true;
  t0_ = now_ = t0_utime;
  BounceDetectorConfig& dc = detector_config_;
  dc.time_scale = config_.time_scale;
  retiming_config_.mode = config_.keep_frame_times ? FrameTimes::kStamped : FrameTimes::kRetimed;
  ContainerClock container;
  container.capture_fps = start_.container_capture_fps;
  container.stored_fps = start_.container_stored_fps;
  dc.capture_slowdown_hint = container.SlowDown();
  dc.image_width_px = start_.width > 0 ? start_.width : config_.frame_width_px;
  dc.image_height_px = start_.height > 0 ? start_.height : config_.frame_height_px;
  std::string error;
  if (!dc.IsValid(&error)) throw std::invalid_argument(error);
  detector_ = std::make_unique<CaptureClockDetector>(detector_config_, retiming_config_);
  clock_ = std::make_unique<ClockReport>(
      ContainerClockWords{start_.container_capture_fps, start_.container_stored_fps, start_.container_tag},
      config_.time_scale > 0);
  if (start_.nominal_fps > 0) sound_->set_frame_period_s(1.0 / start_.nominal_fps);
}

void DetectStage::OnStream(const stream_t& m) {
  if (done_ || !fatal_.empty()) return;
  if (m.state == "start") {
    if (started_) return;  // one stream per node; a second start waits for another node
    start_ = m;
    StartStream(m.utime);
    if (config_.announce_stream)
      notice_(fmt::format("detect: {}, {:.2f} fps; ball {} ({:.1f} mm, {:.1f} g); sound: {}", m.description,
                        m.nominal_fps, config_.ball.name, config_.ball.diameter_m * 1e3,
                        config_.ball.mass_kg * 1e3, m.sound));
  } else if (m.state == "end") {
    end_ = m;
    have_end_ = true;
    if (!started_) StartStream(m.utime);
    Finish();
  }
}

void DetectStage::FinishWithoutEnd() {
  if (done_) return;
  if (!started_) StartStream(0);
  Finish();
}

void DetectStage::OnBox(const ball_box_t& m) {
  if (done_ || !fatal_.empty()) return;
  if (!started_) StartStream(m.utime);  // a log without STREAM: the first box starts it
  ++boxes_;
  last_box_wall_us_ = SteadyMicros();
  now_ = m.utime;
  sound_->OnFrame(SecondsSince(m.utime, t0_), m.found);
  const bool retiming_known = detector_->retiming().decided;
  std::vector<DetectorEvent> events;
  if (have_box_ && m.utime < last_box_utime_) events = RestartDetector();
  have_box_ = true;
  last_box_utime_ = m.utime;
  const int64_t t0 = SteadyMicros();
  const std::vector<DetectorEvent> more = detector_->Push(FromBallBox(m));
  detect_s_ += (SteadyMicros() - t0) * 1e-6;
  events.insert(events.end(), more.begin(), more.end());
  if (!retiming_known && detector_->retiming().retimed && !retiming_said_) {
    retiming_said_ = true;
    notice_("clock: " + detector_->retiming().verdict);
  }
  if (const ClockChoice& choice = detector_->choice(); choice.tested && !slow_motion_said_) {
    slow_motion_said_ = true;
    const CaptureClock& cc = detector_->capture_clock();
    notice_(fmt::format("clock: stamps up to {:.1f}x the {:.0f} fps capture period apart; {}", cc.max_slowdown(),
                        1 / cc.capture_period_s(), choice.verdict));
  }
  Handle(events);
}

std::vector<DetectorEvent> DetectStage::RestartDetector() {
  std::vector<DetectorEvent> events = detector_->Finish();
  for (const auto& s : detector_->detector().Summaries()) earlier_summaries_.push_back(s);
  detector_ = std::make_unique<CaptureClockDetector>(detector_config_, retiming_config_);
  return events;
}

std::vector<SequenceSummary> DetectStage::Summaries() const {
  std::vector<SequenceSummary> all = earlier_summaries_;
  for (const auto& s : detector_->detector().Summaries()) all.push_back(s);
  return all;
}

void DetectStage::OnImpact(const impact_t& m) {
  if (done_ || !fatal_.empty() || m.source != "audio" || m.fused) return;  // its own seen ones come back too
  if (!started_) StartStream(m.utime);
  // A file whose stamps hold slow motion: the sound runs on the file's clock, the picture on the
  // capture clock; a heard impact would meet no seen one, or the wrong one.
  if (detector_->capture_clock().shows_slow_motion() && !detector_->choice().stamped) {
    if (!sound_off_said_) notice_("sound: the stamps hold slow motion: impacts heard on the file's clock are not used");
    sound_off_said_ = true;
    return;
  }
  sound_->OnHeard(m, t0_);
  PublishHeardPeaks();
}

void DetectStage::EmitPeak(bounce_peak_t m) {
  bus_.Publish(config_.channels.bounce_peak, m);
  if (m.revision != 0) return;
  emitted_.push_back(m);
  if (m.bounce == 0 && release_utime_ == 0) release_utime_ = m.apex_utime;
  if (peaks_csv_) {
    // The live row as it is emitted: whatever happens later, it is on disk.
    *peaks_csv_ << PeaksCsvLine(PeaksCsvRowOf(m, t0_)) << std::flush;
  }
}

void DetectStage::PublishHeardPeaks() {
  for (const bounce_peak_t& m : sound_->HeardPeaks(emitted_, t0_, now_)) EmitPeak(m);
}

void DetectStage::CheckFlags(const Calibration& c) {
  if (config_.force || !fatal_.empty()) return;
  const double size_px_per_m = c.radius_px > 0 && config_.ball.diameter_m > 0 ? 2 * c.radius_px / config_.ball.diameter_m : 0;
  if (!(size_px_per_m > 0) || !c.FreeFallMeasured(0.25)) return;
  const auto off = [](double a, double b) { return std::abs(std::log(a / b)) > std::log(2.0); };
  std::string flag;
  if (config_.px_per_m > 0 && off(config_.px_per_m, c.free_fall_px_per_m) && off(config_.px_per_m, size_px_per_m))
    flag = fmt::format("--px-per-m {:g}", config_.px_per_m);
  else if (config_.drop_height_m > 0 && c.method == "drop-height" && off(c.px_per_m, c.free_fall_px_per_m) &&
           off(c.px_per_m, size_px_per_m))
    flag = fmt::format("--drop-height {:g} (a scale of {:.0f} px/m)", config_.drop_height_m, c.px_per_m);
  else if (config_.time_scale > 0 && c.gravity_over_size > 0 &&
           std::abs(std::log(c.gravity_over_size)) > 2 * std::log(2.0))
    flag = fmt::format("--time-scale {:g} (gravity's scale {:.2f}x the ball size's on that clock)",
                       config_.time_scale, c.gravity_over_size);
  if (flag.empty()) return;
  fatal_ = fmt::format("{} contradicts the measurement by more than 2x: the free fall says {:.0f} px/m, the "
                       "ball's size {:.0f} px/m (--force to use it anyway)",
                       flag, c.free_fall_px_per_m, size_px_per_m);
}

void DetectStage::OnCalibration(const Calibration& c) {
  CheckFlags(c);
  if (!fatal_.empty()) return;
  const std::string said = clock_->Update(c);
  if (!said.empty()) notice_(said);
  const calibration_t m = ToCalibrationMsg(c);
  bus_.Publish(config_.channels.calibration, m);
  calibration_ = m;
  if (!config_.out_dir.empty()) WriteJsonAtomically(config_.out_dir / "calibration.json", ToJson(m, t0_));
}

void DetectStage::Handle(const std::vector<DetectorEvent>& events) {
  for (const DetectorEvent& e : events) {
    if (!fatal_.empty()) return;
    switch (e.kind) {
      case DetectorEvent::Kind::kCalibration:
        OnCalibration(e.calibration);
        break;
      case DetectorEvent::Kind::kPeak:
        EmitPeak(ToBouncePeakMsg(e.peak));
        break;
      case DetectorEvent::Kind::kImpact:
        bus_.Publish(config_.channels.impact,
                     sound_->Seen(SecondsSince(e.impact.utime, t0_), t0_, {e.impact.sequence, e.impact.index}));
        PublishHeardPeaks();
        break;
      case DetectorEvent::Kind::kSequenceEnd: {
        const auto ended = Summaries();
        notice_("drop ended (" + e.reason + ")" + (ended.empty() ? "" : RefitHeights(ended.back())));
        // The refitted heights go out as revisions (the fit node's final fit takes them; a
        // bounce heard end to end keeps its flight-time height).
        if (!ended.empty())
          for (const bounce_peak_t& m : RefittedPeakMsgs(ended.back(), now_))
            if (!sound_->WasHeard(m.sequence, m.bounce)) EmitPeak(m);
        drop_t d{};
        d.utime = now_;
        d.sequence = ended.empty() ? 0 : ended.back().sequence;
        d.state = "ended";
        d.reason = e.reason;
        d.stream_start_utime = t0_;
        bus_.Publish(config_.channels.drop, d);
        break;
      }
    }
  }
}

void DetectStage::Finish() {
  if (done_ || !fatal_.empty()) return;
  Handle(detector_->Finish());
  if (!fatal_.empty()) return;
  PublishHeardPeaks();
  const std::vector<SequenceSummary> summaries = Summaries();  // every drop has ended
  std::vector<double> seen;
  for (const auto& d : summaries)
    for (const auto& i : d.impacts) seen.push_back(SecondsSince(i.utime, t0_));
  // What each emitted bounce became when its drop ended, and the releases from a seen hold.
  std::vector<SoundFusion::AfterRefit> after(emitted_.size());
  std::vector<double> held_releases;
  for (size_t i = 0; i < emitted_.size(); ++i)
    for (const auto& d : summaries)
      if (d.sequence == emitted_[i].sequence) {
        after[i].refit_m = d.FinalHeightOf(emitted_[i].bounce);
        after[i].flight_m = d.FlightHeightOf(emitted_[i].bounce);
        after[i].released_from_hold = emitted_[i].bounce == 0 && d.released_from_hold;
        if (after[i].released_from_hold) held_releases.push_back(SecondsSince(emitted_[i].apex_utime, t0_));
      }
  const std::string no_sound = start_.listening ? std::string() : start_.sound.empty() ? "no sound" : start_.sound;
  const double end_s = SecondsSince(have_end_ ? end_.utime : now_, t0_);
  notice_("sound: " + sound_->Finish(seen, end_s, no_sound, held_releases).verdict);
  std::vector<bounce_peak_t> withdrawn;
  const std::vector<bounce_peak_t> rows = sound_->FinalRows(emitted_, after, t0_, now_, &withdrawn);
  for (const bounce_peak_t& m : withdrawn) EmitPeak(m);
  for (const bounce_peak_t& m : rows) EmitPeak(m);
  for (const impact_t& m : sound_->FusedImpacts(t0_)) bus_.Publish(config_.channels.impact, m);
  rows_ = static_cast<int>(rows.size());
  rebounds_ = static_cast<int>(std::count_if(rows.begin(), rows.end(), [](const bounce_peak_t& m) { return m.bounce > 0; }));
  if (!config_.out_dir.empty()) {
    peaks_csv_.reset();
    std::vector<PeaksCsvRow> csv;
    for (const auto& m : rows) csv.push_back(PeaksCsvRowOf(m, t0_));
    WritePeaksCsv(config_.out_dir / "peaks.csv", csv);
    sound_->WriteImpactsCsv(config_.out_dir);
    WriteSummary(rows);
  }
  drop_t d{};
  d.utime = now_;
  d.sequence = summaries.empty() ? 0 : summaries.back().sequence;
  d.state = "done";
  d.reason = have_end_ ? (end_.stopped ? "stopped" : "end of stream") : "the capture node went silent";
  d.peaks = rows_;
  d.stream_start_utime = t0_;
  d.release_utime = release_utime_;
  bus_.Publish(config_.channels.drop, d);
  done_ = true;
}

}  // namespace bouncefit
