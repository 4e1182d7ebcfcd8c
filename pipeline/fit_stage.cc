#include "pipeline/fit_stage.h"

#include <fmt/format.h>

#include <cmath>
#include <thread>

#include "fit/fit_export.h"
#include "fit/fit_notes.h"
#include "msgs/lcm_bus.h"
#include "msgs/node_clock.h"
#include "msgs/msg_json.h"

namespace bouncefit {
void WriteSimulatedCsv(const std::filesystem::path& dir, double t_release_s,
                       const std::vector<TrajectorySample>& trajectory) {
  std::ofstream f(dir / "simulated.csv", std::ios::trunc);
  if (!f) throw std::runtime_error("cannot write '" + (dir / "simulated.csv").string() + "'");
  f << "t_s,height_m\n";
  for (const auto& s : trajectory)
    if (std::isfinite(s.bottom_height_m)) f << fmt::format("{:.6f},{:.5f}\n", t_release_s + s.t_s, s.bottom_height_m);
}

FitStage::FitStage(FitStageConfig config, LcmBus& bus, NoticeFn notice)
    : config_(std::move(config)), bus_(bus), notice_(std::move(notice)) {
  if (!notice_) notice_ = [](const std::string&) {};
  node_ = std::make_unique<FitNode>(config_.node, [this](const fit_update_t& m, const FitUpdate& u) {
    std::lock_guard<std::mutex> lock(inbox_mutex_);
    inbox_.emplace_back(m, u);
  });
  const Channels& ch = config_.node.channels;
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
  node_->Start();
}

FitStage::~FitStage() { Stop(); }

void FitStage::Stop() { node_->Stop(); }

bool FitStage::busy() { return !node_->WaitIdleFor(std::chrono::milliseconds(0)); }

void FitStage::OnPeak(const bounce_peak_t& m) {
  last_wall_us_ = last_peak_wall_us_ = SteadyMicros();
  now_ = std::max(now_, m.utime);
  if (!have_t0_) t0_ = m.utime, have_t0_ = true;  // no STREAM heard: the first peak's time
  // The rows of peaks.csv and withdrawals come after the drops' final fits: not fitted again
  // (the rows are, when those gave none: FitRows).
  if (m.revision == 3 && !stream_done_) rows_.push_back(m);
  if (m.revision >= 3 || stream_done_) return;
  if (m.bounce == 0 && m.revision == 0 && release_utime_ == 0) release_utime_ = m.apex_utime;
  finished_since_peak_ = false;
  node_->OnPeak(m);
}

void FitStage::OnDrop(const drop_t& m) {
  last_wall_us_ = SteadyMicros();
  now_ = std::max(now_, m.utime);
  t0_ = m.stream_start_utime;  // the detect node's zero, whatever was heard before
  have_t0_ = true;
  if (stream_done_) return;
  if (!finished_since_peak_) final_sims_start_ = node_->simulations();  // a final fit begins
  if (!finished_since_peak_ || m.state == "done") {
    node_->Finish();
    finished_since_peak_ = true;
  }
  if (m.state == "done") {
    stream_done_ = true;
    if (m.release_utime) release_utime_ = m.release_utime;
  }
}

void FitStage::Poll() {
  std::deque<std::pair<fit_update_t, FitUpdate>> ready;
  {
    std::lock_guard<std::mutex> lock(inbox_mutex_);
    ready.swap(inbox_);
  }
  for (auto& [m, u] : ready) {
    m.published_utime = now_;
    bus_.Publish(config_.node.channels.fit_update, m);
    if (fit_jsonl_) *fit_jsonl_ << ToJson(m, t0_).dump() << '\n' << std::flush;
    if (u.final && u.model == node_->model().name()) {
      if (u.no_answer.empty()) {
        final_ = u;
        no_fit_why_.clear();
      } else {  // not an answer: no coefficients are written from it
        final_.reset();
        no_fit_why_ = u.no_answer;
      }
      for (const auto& line : FinalFitNotices(u, node_->ball())) notice_(line);
    }
    if (on_update_) on_update_(m, u);
  }
  // A drop with no DROP word (an older log): its final fit after a quiet spell.
  if (!stream_done_ && !finished_since_peak_ && config_.final_after_s > 0 &&
      (SteadyMicros() - last_peak_wall_us_) * 1e-6 > config_.final_after_s) {
    node_->Finish();
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
    r.sequence = sequence;
    r.revision = 0;
    r.height_m = r.fused_height_m;
    node_->OnPeak(r);
  }
  final_sims_start_ = node_->simulations();
  node_->Finish();
  return true;
}

void FitStage::WaitDone(const std::function<void(int, int)>& progress) {
  while (!done_) {
    Poll();
    if (done_) break;
    if (progress) progress(node_->simulations() - final_sims_start_, node_->final_budget());
    node_->WaitIdleFor(std::chrono::milliseconds(200));
  }
}

void FitStage::WriteExports() {
  if (config_.out_dir.empty() || !final_) return;
  const RecordedTrack recorded = Recorded();
  WriteFitExports(config_.out_dir, *final_, node_->ball(),
                  FitExportContext{input_, "run", recorded.t_s.empty() ? nullptr : &recorded});
  // The model's trajectory with the final coefficients, on the stream clock.
  SimulationOptions so;
  so.drop_height_m = final_->drop_height_m;
  so.record_trajectory = true;
  so.duration_s = 8.0;
  const SimulationResult r = node_->model().Simulate(final_->values, so);
  if (r.ok) WriteSimulatedCsv(config_.out_dir, SecondsSince(release_utime_, t0_), r.trajectory);
}

RecordedTrack FitStage::Recorded() const {
  RecordedTrack r;
  if (!calibration_ || !(calibration_->px_per_m > 0) || release_utime_ == 0) return r;
  const calibration_t& c = *calibration_;
  const double down_x = std::sin(c.roll_rad), down_y = std::cos(c.roll_rad);
  for (const ball_box_t& b : boxes_) {
    if (b.utime < release_utime_) continue;  // the animation starts at the release
    const double x = b.cx - b.camera_dx, y = b.cy - b.camera_dy;  // in the scene
    const double bottom_px = x * down_x + y * down_y + b.radius_px;
    r.t_s.push_back(SecondsSince(b.utime, release_utime_));
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
