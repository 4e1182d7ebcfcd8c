// summary.json: what the detect node knows of the whole stream once it ended (docs/FORMATS.md).
#include <fmt/format.h>

#include "msgs/msg_json.h"
#include "pipeline/clock_report.h"
#include "pipeline/detect_stage.h"
#include "pipeline/output_dir.h"
#include "pipeline/sound_fusion.h"

namespace bouncefit {

void DetectStage::WriteSummary(const std::vector<bounce_peak_t>& rows) {
  const std::vector<SequenceSummary> summaries = Summaries();
  nlohmann::json s;
  const stream_t& st = have_end_ ? end_ : start_;
  s["input"] = st.input;
  s["ball"] = {{"name", config_.ball.name}, {"diameter_m", config_.ball.diameter_m}, {"mass_kg", config_.ball.mass_kg}};
  s["frames"] = st.frames;
  s["found_frames"] = st.found;
  s["dropped_frames"] = st.dropped;
  s["repeated_frames"] = st.repeated;
  s["duration_s"] = SecondsSince(st.utime, t0_);
  s["wall_time_s"] = st.wall_s;
  s["timings_ms"] = {{"decode", st.read_s * 1e3},
                     {"track", st.track_s * 1e3},
                     {"detect", detect_s_ * 1e3},
                     {"sound", st.sound_cpu_s * 1e3}};
  s["sound"] = sound_->Summary(start_.sound);
  s["stopped_by_user"] = static_cast<bool>(end_.stopped);
  if (!end_.failure.empty()) s["failure"] = end_.failure;
  s["calibration"] = calibration_ ? ToJson(*calibration_, t0_) : nlohmann::json();
  s["clock"] = {{"time_scale", detector_->detector().time_scale()},
                {"container_capture_fps", start_.container_capture_fps},
                {"container_stored_fps", start_.container_stored_fps},
                {"report", clock_->last()},
                {"frame_times", detector_->retiming().verdict}};
  // The rows are on the clock the pictures were taken on; track.csv keeps the stamps.
  const Retiming& retiming = detector_->retiming();
  s["clock"]["frames_retimed"] = retiming.applied ? nlohmann::json{{"source_fps", retiming.source_fps},
                                                                   {"phase", retiming.phase},
                                                                   {"first_frame_s", t0_ * 1e-6}}
                                                  : nlohmann::json();
  // Slow motion in the stamps: the rows' times are real seconds on the capture clock.
  const CaptureClock& cc = detector_->capture_clock();
  s["clock"]["slow_motion"] = detector_->choice().verdict;
  s["clock"]["capture_clock"] = detector_->on_capture_clock()
                                    ? nlohmann::json{{"capture_fps", 1 / cc.capture_period_s()},
                                                     {"slowed_steps", cc.slowed_steps()},
                                                     {"max_slowdown", cc.max_slowdown()},
                                                     {"slowed_stamp_s", cc.slowed_stamp_s()},
                                                     {"slowed_real_s", cc.slowed_real_s()}}
                                    : nlohmann::json();
  // Every bounce as it was emitted, with its height refitted with its whole drop.
  nlohmann::json peaks = nlohmann::json::array();
  for (const bounce_peak_t& m : emitted_) {
    nlohmann::json j = ToJson(m, t0_);
    double refit = NAN;
    for (const auto& d : summaries)
      if (d.sequence == m.sequence) refit = d.FinalHeightOf(m.bounce);
    j["refit_height_m"] = FiniteOrNull(refit);
    peaks.push_back(j);
  }
  s["peaks"] = peaks;
  s["rows"] = static_cast<int>(rows.size());
  nlohmann::json drops = nlohmann::json::array();
  for (const auto& d : summaries) {
    nlohmann::json impacts = nlohmann::json::array();
    for (const auto& i : d.impacts)
      impacts.push_back({{"bounce", i.index},
                         {"t_s", SecondsSince(i.utime, t0_)},
                         {"speed_in_mps", i.speed_in_mps},
                         {"speed_out_mps", i.speed_out_mps},
                         {"restitution", i.restitution}});
    nlohmann::json final_h = nlohmann::json::array(), flight_h = nlohmann::json::array();
    for (double h : d.final_height_m) final_h.push_back(FiniteOrNull(h));
    for (double h : d.flight_height_m) flight_h.push_back(FiniteOrNull(h));
    // Each drop's own scale: a ball rolled towards or away from the camera between drops
    // is seen at another px/m in each.
    drops.push_back({{"sequence", d.sequence},
                     {"end", d.end_reason},
                     {"px_per_m", FiniteOrNull(d.calibration.px_per_m)},
                     {"scale_method", d.calibration.method},
                     {"ball_radius_px", FiniteOrNull(d.calibration.radius_px)},
                     {"first_bounce", d.first_bounce},
                     {"released_from_hold", d.released_from_hold},
                     {"final_height_m", final_h},
                     {"flight_height_m", flight_h},
                     {"impacts", impacts},
                     {"restitution_intercept", FiniteOrNull(d.restitution_intercept)},
                     {"restitution_slope_per_mps", FiniteOrNull(d.restitution_slope_per_mps)}});
  }
  s["drops"] = drops;
  WriteJsonAtomically(config_.out_dir / "summary.json", s);
}

}  // namespace bouncefit
