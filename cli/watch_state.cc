#include "cli/watch_state.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "report/report_run_data.h"

namespace bouncefit::cli {
namespace {

ReportCalibration ToReportCalibration(const calibration_t& c) {
  ReportCalibration r;
  r.px_per_m = c.px_per_m;
  r.px_per_m_sigma = c.px_per_m_sigma;
  r.roll_rad = c.roll_rad;
  r.roll_sigma_rad = c.roll_sigma_rad;
  r.floor_px = c.floor_px;
  r.floor_sigma_px = c.floor_sigma_px;
  r.method = c.method;
  r.samples = c.samples;
  return r;
}

}  // namespace

void WatchState::Count(const std::string& kind, int64_t now_utime) {
  auto& s = stats_[kind];
  ++s.count;
  if (s.first_recv_utime == 0) s.first_recv_utime = now_utime;
  s.recent_recv_utime.push_back(now_utime);
  const int64_t window = static_cast<int64_t>(config_.rate_window_s * 1e6);
  while (!s.recent_recv_utime.empty() && s.recent_recv_utime.front() < now_utime - window) {
    s.recent_recv_utime.pop_front();
  }
  last_recv_utime_ = now_utime;
}

void WatchState::NewStream() {
  trace_.clear();
  peaks_.clear();
  impacts_.clear();
  fit_.reset();
  latest_by_model_.clear();
  previous_by_model_.clear();
  calibration_.reset();
  last_frame_ = -1;
  sequence_ = -1;
  lowest_bottom_px_ = -1e300;
  stream_start_utime_ = 0;
  final_rows_ = fused_impacts_ = false;
}

void WatchState::OnBox(const ball_box_t& m, int64_t now_utime) {
  Count("box", now_utime);
  const int64_t back = static_cast<int64_t>(config_.restart_gap_s * 1e6);
  if (last_box_utime_ != 0 &&
      (m.frame < last_frame_ || m.utime < last_box_utime_ - back)) {
    ++restarts_;
    NewStream();
  }
  if (stream_start_utime_ == 0) stream_start_utime_ = m.utime;
  if (last_frame_ >= 0 && m.frame > last_frame_ + 1) frame_gaps_ += m.frame - last_frame_ - 1;
  last_frame_ = m.frame;
  last_box_utime_ = m.utime;
  if (!m.found) ++lost_frames_;
  TraceSample s{m.utime, static_cast<bool>(m.found), m.cx, m.cy, m.h};
  if (s.found) lowest_bottom_px_ = std::max(lowest_bottom_px_, s.cy + 0.5 * s.h);
  trace_.push_back(s);
  const int64_t window = static_cast<int64_t>(config_.trace_window_s * 1e6);
  while (!trace_.empty() && trace_.front().utime < m.utime - window) trace_.pop_front();
}

void WatchState::OnCalibration(const calibration_t& m, int64_t now_utime) {
  Count("calibration", now_utime);
  calibration_ = m;
}

void WatchState::OnStream(const stream_t& m, int64_t now_utime) {
  Count("stream", now_utime);
  if (m.state != "start") return;
  if (last_box_utime_ != 0) {
    ++restarts_;
    NewStream();
    last_box_utime_ = 0;
  }
  stream_start_utime_ = m.utime;  // the zero of every time shown, as in the run's files
}

void WatchState::OnPeak(const bounce_peak_t& m, int64_t now_utime) {
  Count("peak", now_utime);
  if (m.revision == 3 && !final_rows_) {
    peaks_.clear();  // the stream ended: its rows of peaks.csv replace the live table
    final_rows_ = true;
  }
  if (final_rows_ && m.revision != 3) return;
  if (m.revision == 3) {
    bounce_peak_t row = m;
    row.height_m = m.fused_height_m;  // the height to quote
    peaks_.push_back(row);
    return;
  }
  if (m.sequence != sequence_) {
    peaks_.clear();  // a new drop: its own table
    sequence_ = m.sequence;
  }
  if (m.revision == 4) {  // withdrawn
    peaks_.erase(std::remove_if(peaks_.begin(), peaks_.end(), [&](const bounce_peak_t& p) { return p.bounce == m.live_bounce; }),
                 peaks_.end());
    return;
  }
  const int key = m.revision == 0 ? m.bounce : m.live_bounce;  // a revision names the bounce it revises
  auto it = std::find_if(peaks_.begin(), peaks_.end(), [&](const bounce_peak_t& p) { return p.bounce == key; });
  if (it != peaks_.end()) {
    *it = m;
  } else {
    peaks_.push_back(m);
    std::sort(peaks_.begin(), peaks_.end(),
              [](const auto& a, const auto& b) { return a.bounce < b.bounce; });
  }
}

void WatchState::OnImpact(const impact_t& m, int64_t now_utime) {
  Count("impact", now_utime);
  if (m.fused && !fused_impacts_) {
    impacts_.clear();  // the stream ended: the impacts heard and seen, fused, replace the live list
    fused_impacts_ = true;
  }
  if (fused_impacts_ && !m.fused) return;
  impacts_.push_back(m);
  const size_t kMaxImpacts = 1000;  // a long session's list stays bounded
  if (impacts_.size() > kMaxImpacts) impacts_.erase(impacts_.begin());
}

void WatchState::OnFit(const fit_update_t& m, int64_t now_utime) {
  Count("fit", now_utime);
  ++fits_received_;
  auto it = latest_by_model_.find(m.model);
  if (it != latest_by_model_.end()) previous_by_model_[m.model] = it->second;
  latest_by_model_[m.model] = m;
  fit_ = m;
}

const fit_update_t* WatchState::previous_fit() const {
  if (!fit_) return nullptr;
  auto it = previous_by_model_.find(fit_->model);
  return it == previous_by_model_.end() ? nullptr : &it->second;
}

double WatchState::Rate(const std::string& kind, int64_t now_utime) const {
  auto it = stats_.find(kind);
  if (it == stats_.end()) return 0;
  // Over the window, or since the channel's first message when that is shorter (a stream
  // that just started is not averaged with the silence before it).
  const int64_t window = static_cast<int64_t>(config_.rate_window_s * 1e6);
  const int64_t since_first = now_utime - it->second.first_recv_utime;
  const int64_t span = std::max<int64_t>(std::min(window, since_first), 250'000);
  const auto n = std::count_if(it->second.recent_recv_utime.begin(),
                               it->second.recent_recv_utime.end(),
                               [&](int64_t t) { return t >= now_utime - span; });
  return static_cast<double>(n) / (static_cast<double>(span) * 1e-6);
}

int64_t WatchState::Count(const std::string& kind) const {
  auto it = stats_.find(kind);
  return it == stats_.end() ? 0 : it->second.count;
}

double WatchState::SilenceS(int64_t now_utime) const {
  if (last_recv_utime_ == 0) return -1;
  return static_cast<double>(now_utime - last_recv_utime_) * 1e-6;
}

bool WatchState::Waiting(int64_t now_utime) const {
  return last_recv_utime_ == 0 || SilenceS(now_utime) > config_.stale_after_s;
}

double WatchState::SampleHeight(const TraceSample& s, bool* metres) const {
  const bool calibrated = calibration_ && std::isfinite(calibration_->px_per_m) &&
                          calibration_->px_per_m > 0 && std::isfinite(calibration_->floor_px);
  if (metres) *metres = calibrated;
  if (!s.found) return std::numeric_limits<double>::quiet_NaN();
  if (calibrated) return BallBottomHeightM(s.cx, s.cy, s.h, ToReportCalibration(*calibration_));
  return lowest_bottom_px_ - (s.cy + 0.5 * s.h);
}

}  // namespace bouncefit::cli
