#include "fit/fit_worker.h"

namespace bouncefit {

FitWorker::FitWorker(std::unique_ptr<FitSession> session, Callback on_update)
    : session_(std::move(session)), on_update_(std::move(on_update)) {}

FitWorker::~FitWorker() { Stop(); }

void FitWorker::Start() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (thread_.joinable()) return;
  stop_ = false;
  thread_ = std::thread([this] { Loop(); });
}

void FitWorker::Submit(const PeakInput& peak) {
  std::lock_guard<std::mutex> lock(mutex_);
  pending_.push_back(peak);
  ++stats_.peaks;
  // A new apex supersedes the running update; a revision of one already seen (every apex is
  // revised once or twice within ~0.2 s as the sound and the drop's refit come in) waits for
  // it, or on a busy machine no soft-ball update would ever get out between apexes.
  const bool newer = peak.sequence != newest_sequence_ || peak.bounce > newest_bounce_;
  if (newer) newest_sequence_ = peak.sequence, newest_bounce_ = peak.bounce;
  if (running_ && (newer || running_final_)) running_->Cancel();
  wake_.notify_one();
}

void FitWorker::Finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  finish_requested_ = true;
  // Cut a per-bounce update short for the final fit, but never the final fit itself (the
  // end of a stream asks for it twice: at the drop's end and at the stream's).
  if (running_ && !running_final_) running_->Cancel();
  wake_.notify_one();
}

void FitWorker::WaitIdle() {
  while (!WaitIdleFor(std::chrono::hours(1))) {
  }
}

bool FitWorker::WaitIdleFor(std::chrono::milliseconds timeout) {
  std::unique_lock<std::mutex> lock(mutex_);
  return idle_.wait_for(lock, timeout, [&] {
    return (!busy_ && pending_.empty() && !finish_requested_) || !thread_.joinable() || stop_;
  });
}

void FitWorker::Stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    pending_.clear();
    if (running_) running_->Cancel();
    wake_.notify_all();
  }
  if (thread_.joinable()) thread_.join();
  idle_.notify_all();
}

FitWorker::Stats FitWorker::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

void FitWorker::Deliver(const FitUpdate& u) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++stats_.updates_delivered;
    if (u.final) ++stats_.finals;
  }
  if (on_update_) on_update_(u);
}

void FitWorker::DeliverFinal(const CancelToken* token) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    running_final_ = true;
  }
  FitUpdate u;
  try {
    u = session_->FinalUpdate(token);
  } catch (...) {
    std::lock_guard<std::mutex> lock(mutex_);
    running_final_ = false;
    throw;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    running_final_ = false;
  }
  Deliver(u);
}

void FitWorker::Loop() {
  bool final_done = false;
  for (;;) {
    std::vector<PeakInput> peaks;
    bool finish = false;
    std::shared_ptr<CancelToken> token;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || !pending_.empty() || finish_requested_; });
      if (stop_) break;
      peaks.swap(pending_);
      finish = finish_requested_;
      finish_requested_ = false;
      busy_ = true;
      token = running_ = std::make_shared<CancelToken>();
    }
    try {
      bool need_fit = false;
      for (const auto& p : peaks) {
        if (p.sequence != session_->sequence()) {
          // A new drop: the previous one is over, fit it thoroughly (a later peak may cut
          // it short; it is delivered anyway as the drop's last word).
          if (session_->CanFit() && !final_done) DeliverFinal(token.get());
          // The ball dropped again: its final fits take the earlier drops too.
          if (session_->config().joint_drops)
            session_->KeepDropAndReset(p.sequence);
          else
            session_->Reset(p.sequence);
          final_done = false;
          need_fit = false;
        }
        session_->AddPeak(p);
        if (p.bounce >= 1) need_fit = true, final_done = false;
      }
      if (need_fit && session_->CanFit() && !token->cancelled()) {
        if (session_->config().quick_fit) {
          try {
            Deliver(session_->QuickUpdate());
          } catch (const std::logic_error&) {
            // no quick model: nothing to deliver
          }
        }
        if (!token->cancelled()) {
          FitUpdate u = session_->Update(token.get());
          if (u.cancelled) {
            std::lock_guard<std::mutex> lock(mutex_);
            ++stats_.superseded;
          } else {
            Deliver(u);
          }
        } else {
          std::lock_guard<std::mutex> lock(mutex_);
          ++stats_.superseded;
        }
      }
      if (finish && session_->CanFit() && !final_done) {
        // Finish() cancelled the token to cut a running update short; the final fit gets a
        // fresh one, cancelled by any later peak.
        {
          std::lock_guard<std::mutex> lock(mutex_);
          token = running_ = std::make_shared<CancelToken>();
          if (!pending_.empty()) token->Cancel();
        }
        DeliverFinal(token.get());
        final_done = true;
      }
    } catch (const std::exception& e) {
      // A failing fit must not take the worker down; the next peak starts afresh.
      std::lock_guard<std::mutex> lock(mutex_);
      ++stats_.errors;
      stats_.last_error = e.what();
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      busy_ = false;
      running_.reset();
    }
    idle_.notify_all();
  }
}

}  // namespace bouncefit
