#include "pipeline/fit_stage.h"

#include <fmt/format.h>

#include <cmath>
#include <thread>

#include "fit/fit_export.h"
#include "fit/fit_notes.h"
#include "msgs/lcm_bus.h"
#include "msgs/node_clock.h"
#include "msgs/msg_json.h"
#include "pipeline/message_mapping.h"

namespace bouncefit {
void WriteSimulatedCsv(const std::filesystem::path& dir, const std::vector<SimulatedDrop>& drops,
                       double run_s_per_real_s) {
  std::ofstream f(dir / "simulated.csv", std::ios::trunc);
  if (!f) throw std::runtime_error("cannot write '" + (dir / "simulated.csv").string() + "'");
  f << "drop,t_s,height_m\n";
  for (const SimulatedDrop& d : drops)
    for (const auto& s : d.trajectory) {
      const double t = d.start_t_s + s.t_s * run_s_per_real_s;
      if (t > d.end_t_s) break;
      if (std::isfinite(s.bottom_height_m)) f << fmt::format("{},{:.6f},{:.5f}\n", d.drop, t, s.bottom_height_m);
    }
}

std::vector<SimulatedDrop> SimulateFitDrops(const BallModel& model, const FitUpdate& fit,
                                            const std::vector<FitDrop>& drops,
                                            const std::vector<double>& ends_t_s, double min_hop_m,
                                            double* run_s_per_real_s) {
  std::vector<SimulatedDrop> out;
  std::vector<FitDrop> simulated;
  std::vector<std::vector<double>> apex_times;
  for (size_t d = 0; d < drops.size(); ++d) {
    if (!std::isfinite(drops[d].start_t_s) || !(drops[d].start_height_m > 0)) continue;
    // 8 s at most: long enough for every drop filmed; cut to the drop's span below.
    const SimulationResult r = SimulateFromStart(model, fit.values, drops[d].start_height_m, 8.0, min_hop_m);
    if (!r.ok) continue;
    out.push_back({drops[d].drop, drops[d].start_t_s, d < ends_t_s.size() ? ends_t_s[d] : INFINITY, r.trajectory});
    simulated.push_back(drops[d]);
    apex_times.push_back(r.apex_times_s);
  }
  *run_s_per_real_s = RunSecondsPerRealSecond(simulated, apex_times);
  return out;
}

FitStage::FitStage(FitStageConfig config, LcmBus& bus, NoticeFn notice)
    : config_(std::move(config)), bus_(bus), notice_(std::move(notice)) {
  if (!notice_) notice_ = [](const std::string&) {};
  models_ = MakeFitModels(config_.fit);
  auto session = std::make_unique<FitSession>(*models_.model, models_.quick.get(), models_.session);
  // Called on the worker thread: Poll() publishes from the bus's.
  worker_ = std::make_unique<FitWorker>(std::move(session), [this](const FitUpdate& u) {
    std::lock_guard<std::mutex> lock(inbox_mutex_);
    inbox_.emplace_back(ToFitUpdateMsg(u), u);
  });
  const Channels& ch = config_.channels;
  bus_.Subscribe<stream_t>(ch.stream, [this](const stream_t& m) {
    if (m.state != "start") return;
    t0_ = m.utime;
    have_t0_ = true;
    input_ = m.input;
  });
  bus_.Subscribe<ball_box_t>(ch.ball_box, [this](const ball_box_t& m) {
    now_ = std::max(now_, m.utime);
    if (m.found && !config_.out_dir.empty()) boxes_.push_back(m);
  });
  bus_.Subscribe<calibration_t>(ch.calibration, [this](const calibration_t& m) { calibration_ = m; });
  bus_.Subscribe<bounce_peak_t>(ch.bounce_peak, [this](const bounce_peak_t& m) { OnPeak(m); });
  bus_.Subscribe<drop_t>(ch.drop, [this](const drop_t& m) { OnDrop(m); });
  if (!config_.out_dir.empty()) {
    fit_jsonl_ = std::make_unique<std::ofstream>(config_.out_dir / "fit.jsonl", std::ios::trunc);
    if (!*fit_jsonl_) throw std::runtime_error("cannot write '" + (config_.out_dir / "fit.jsonl").string() + "'");
  }
  worker_->Start();
}

FitStage::~FitStage() { Stop(); }

void FitStage::Stop() { worker_->Stop(); }

bool FitStage::busy() { return !worker_->WaitIdleFor(std::chrono::milliseconds(0)); }

void FitStage::Submit(const bounce_peak_t& m) { worker_->Submit(ToPeakInput(m)); }

void FitStage::OnPeak(const bounce_peak_t& m) {
  last_wall_us_ = last_peak_wall_us_ = SteadyMicros();
  now_ = std::max(now_, m.utime);
  if (!have_t0_) t0_ = m.utime, have_t0_ = true;  // no STREAM heard: the first peak's time
  // The rows of peaks.csv and withdrawals come after the drops' final fits: not fitted again
  // (the rows are, when those gave none: FitRows).
  if (m.revision == 3 && !stream_done_) rows_.push_back(m);
  if (m.revision == 3 && m.live_bounce >= 0) row_of_fitted_[{m.sequence, m.live_bounce}] = m;
  if (m.revision == 4) row_of_fitted_.erase({m.sequence, m.live_bounce});  // withdrawn: no row
  if (m.revision >= 3 || stream_done_) return;
  fitted_peaks_[{m.sequence, m.bounce}] = m;
  finished_since_peak_ = false;
  Submit(m);
}

void FitStage::OnDrop(const drop_t& m) {
  last_wall_us_ = SteadyMicros();
  now_ = std::max(now_, m.utime);
  t0_ = m.stream_start_utime;  // the detect node's zero, whatever was heard before
  have_t0_ = true;
  if (stream_done_) return;
  if (!finished_since_peak_) final_sims_start_ = worker_->simulations();  // a final fit begins
  if (!finished_since_peak_ || m.state == "done") {
    worker_->Finish();
    finished_since_peak_ = true;
  }
  if (m.state == "done") stream_done_ = true;
}

void FitStage::Poll() {
  std::deque<std::pair<fit_update_t, FitUpdate>> ready;
  {
    std::lock_guard<std::mutex> lock(inbox_mutex_);
    ready.swap(inbox_);
  }
  for (auto& [m, u] : ready) {
    m.published_utime = now_;
    bus_.Publish(config_.channels.fit_update, m);
    if (fit_jsonl_) *fit_jsonl_ << ToJson(m, t0_).dump() << '\n' << std::flush;
    if (u.drop_height_m > 0) fit_starts_[u.sequence] = {u.start_bounce, u.drop_height_m};
    if (u.final && u.model == models_.model->name()) {
      if (u.no_answer.empty()) {
        final_ = u;
        no_fit_why_.clear();
      } else {  // not an answer: no coefficients are written from it
        final_.reset();
        no_fit_why_ = u.no_answer;
      }
      for (const auto& line : FinalFitNotices(u, models_.ball)) notice_(line);
    }
    if (on_update_) on_update_(m, u);
  }
  // A drop with no DROP word (an older log): its final fit after a quiet spell.
  if (!stream_done_ && !finished_since_peak_ && config_.final_after_s > 0 &&
      (SteadyMicros() - last_peak_wall_us_) * 1e-6 > config_.final_after_s) {
    worker_->Finish();
    finished_since_peak_ = true;
  }
  if (stream_done_ && !done_ && ready.empty() && !busy()) {
    {
      std::lock_guard<std::mutex> lock(inbox_mutex_);
      if (!inbox_.empty()) return;  // a last update came in meanwhile: the next Poll
    }
    // No final fit from the peaks as they came: the rows may still hold a run to fit.
    if (!final_ && no_fit_why_.empty() && !rows_fitted_ && FitRows()) return;
    WriteExports();
    done_ = true;
  }
}

bool FitStage::FitRows() {
  rows_fitted_ = true;
  if (rows_.empty()) return false;
  // A sequence of its own, after every drop's: the session starts it afresh.
  int sequence = 0;
  for (const auto& r : rows_) sequence = std::max(sequence, r.sequence + 1);
  for (bounce_peak_t r : rows_) {
    if (!std::isfinite(r.fused_height_m)) continue;
    row_of_fitted_[{sequence, r.bounce}] = r;  // the fit numbers it as its row
    r.sequence = sequence;
    r.revision = 0;
    r.height_m = r.fused_height_m;
    Submit(r);
  }
  final_sims_start_ = worker_->simulations();
  worker_->Finish();
  return true;
}

void FitStage::WaitDone(const std::function<void(int, int)>& progress) {
  while (!done_) {
    Poll();
    if (done_) break;
    if (progress) progress(worker_->simulations() - final_sims_start_, worker_->final_budget());
    worker_->WaitIdleFor(std::chrono::milliseconds(200));
  }
}

void FitStage::WriteExports() {
  if (config_.out_dir.empty() || !final_) return;
  std::vector<FitDrop> drops = Drops(*final_);
  // Each drop ends where the next one (in time) starts; the last one runs on past the footage
  // (8 s, or until its bounces are under 1 cm), as a reader expects a whole drop.
  std::vector<double> ends(drops.size(), INFINITY);
  for (size_t d = 0; d < drops.size(); ++d)
    for (const FitDrop& other : drops)
      if (other.start_t_s > drops[d].start_t_s) ends[d] = std::min(ends[d], other.start_t_s);
  double run_s_per_real_s = 1;
  const std::vector<SimulatedDrop> simulated =
      SimulateFitDrops(*models_.model, *final_, drops, ends, models_.ball.chatter_hop_m(), &run_s_per_real_s);
  if (simulated.size() < drops.size())
    notice_("fit: warning: the fitted ball diverges dropped from " +
            std::to_string(drops.size() - simulated.size()) + " of the " + std::to_string(drops.size()) +
            " start apexes: simulated.csv leaves those drops out");
  const RecordedTrack recorded =
      drops.empty() ? RecordedTrack{} : Recorded(drops.front().start_t_s, ends.front(), run_s_per_real_s);
  FitExportContext context{input_, "run", recorded.t_s.empty() ? nullptr : &recorded};
  context.drops = &drops;
  context.run_s_per_real_s = run_s_per_real_s;
  WriteFitExports(config_.out_dir, *final_, models_.ball, context);
  if (!simulated.empty()) WriteSimulatedCsv(config_.out_dir, simulated, run_s_per_real_s);
}

std::vector<FitDrop> FitStage::Drops(const FitUpdate& u) const {
  const std::vector<FitDropSlice> slices = FitDropSlices(u);
  // The drops a joint fit kept are the earlier ones that had a fit, in order; each is checked
  // by its start height (the same number travelled both ways).
  std::vector<std::pair<int, int>> starts{{u.sequence, u.start_bounce}};  // (drop, fit's bounce)
  auto kept = fit_starts_.begin();
  for (size_t k = 1; k < slices.size(); ++k) {
    while (kept != fit_starts_.end() && kept->first < u.sequence &&
           std::abs(kept->second.second - slices[k].start_height_m) > 1e-9)
      ++kept;
    if (kept == fit_starts_.end() || kept->first >= u.sequence) break;  // not found: left out
    starts.push_back({kept->first, kept->second.first});
    ++kept;
  }
  std::vector<FitDrop> drops;
  for (size_t k = 0; k < starts.size(); ++k) {
    const auto [sequence, start] = starts[k];
    // A bounce's number and time in peaks.csv; without its row (an older log), as emitted.
    auto where = [&](int bounce, int* number, double* t_s) {
      if (auto it = row_of_fitted_.find({sequence, bounce}); it != row_of_fitted_.end()) {
        *number = it->second.bounce;
        *t_s = SecondsSince(it->second.apex_utime, t0_);
      } else if (auto f = fitted_peaks_.find({sequence, bounce}); f != fitted_peaks_.end()) {
        *number = bounce;
        *t_s = SecondsSince(f->second.apex_utime, t0_);
      } else {
        *number = bounce;
        *t_s = std::nan("");
      }
    };
    FitDrop d;
    d.drop = sequence;
    // The rows fitted as a drop of their own: the drop their start row is in.
    if (auto it = row_of_fitted_.find({sequence, start}); it != row_of_fitted_.end()) d.drop = it->second.sequence;
    d.start_height_m = slices[k].start_height_m;
    where(start, &d.start_bounce, &d.start_t_s);
    for (size_t i = 0; i < slices[k].count; ++i) {
      int number = 0;
      double t = 0;
      where(start + 1 + static_cast<int>(i), &number, &t);
      d.bounces.push_back(number);
      d.apex_t_s.push_back(t);
      d.recorded_m.push_back(u.recorded_m[slices[k].first + i]);
      d.simulated_m.push_back(slices[k].first + i < u.simulated_m.size() ? u.simulated_m[slices[k].first + i]
                                                                          : std::nan(""));
    }
    drops.push_back(std::move(d));
  }
  return drops;
}

RecordedTrack FitStage::Recorded(double start_t_s, double end_t_s, double run_s_per_real_s) const {
  RecordedTrack r;
  if (!calibration_ || !(calibration_->px_per_m > 0) || !std::isfinite(start_t_s)) return r;
  const calibration_t& c = *calibration_;
  const double down_x = std::sin(c.roll_rad), down_y = std::cos(c.roll_rad);
  for (const ball_box_t& b : boxes_) {
    const double t = SecondsSince(b.utime, t0_);
    if (t < start_t_s || t > end_t_s) continue;  // the animation starts at the start apex
    if (!std::isfinite(b.cx) || !std::isfinite(b.cy)) continue;  // seen, its centre not placed
    const double x = b.cx - b.camera_dx, y = b.cy - b.camera_dy;  // in the scene
    const double bottom_px = x * down_x + y * down_y + b.radius_px;
    r.t_s.push_back((t - start_t_s) / run_s_per_real_s);
    r.bottom_height_m.push_back((c.floor_px - bottom_px) / c.px_per_m);
    r.horizontal_m.push_back((x * down_y - y * down_x) / c.px_per_m);
  }
  if (!r.horizontal_m.empty()) {  // from where the ball was first seen
    const double x0 = r.horizontal_m.front();
    for (double& x : r.horizontal_m) x -= x0;
  }
  return r;
}

}  // namespace bouncefit
