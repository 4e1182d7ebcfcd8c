#pragma once
// Runs a FitSession on a thread of its own, so whoever feeds it peaks never waits.
//
// Supersede, never queue: every peak is recorded, but only the newest bounce is fitted.
// A peak that arrives while an update is running cancels it (the token is checked between
// simulations); the cancelled update is not delivered and the next one starts from its
// best point. After each rebound peak the point-mass estimate is delivered first
// (milliseconds), then the model's update. A peak of a new sequence, or Finish(), runs the
// final, thorough fit of the drop (delivered even when a later peak cuts it short, marked
// cancelled, since it is the drop's last word).
#include <chrono>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "fit/fit_session.h"

namespace bouncefit {

class FitWorker {
 public:
  using Callback = std::function<void(const FitUpdate&)>;

  // The session's models must outlive the worker. The callback runs on the worker thread.
  FitWorker(std::unique_ptr<FitSession> session, Callback on_update);
  ~FitWorker();  // Stop()
  FitWorker(const FitWorker&) = delete;
  FitWorker& operator=(const FitWorker&) = delete;

  void Start();
  // Never blocks on a fit: records the peak; a new apex (or any peak during a final fit)
  // cancels the running update, a revision of an apex already seen lets it finish.
  void Submit(const PeakInput& peak);
  // Asks for the final fit of the current drop (end of stream, or the drop is over).
  void Finish();
  // Blocks until nothing is pending or running (for offline use and tests).
  void WaitIdle();
  // Waits at most `timeout` for the same; true if idle.
  bool WaitIdleFor(std::chrono::milliseconds timeout);
  int simulations() const { return session_->simulations(); }  // progress of the fits
  int final_budget() const { return session_->FinalBudget(); }
  // Cancels what runs, drops what is pending, joins the thread.
  void Stop();

  struct Stats {
    int peaks = 0;
    int updates_delivered = 0;
    int superseded = 0;  // updates cancelled by a newer peak
    int finals = 0;
    int errors = 0;          // fits that threw (the worker carries on)
    std::string last_error;
  };
  Stats stats() const;

 private:
  void Loop();
  void Deliver(const FitUpdate& u);
  void DeliverFinal(const CancelToken* token);  // FinalUpdate, marked as running_final_

  std::unique_ptr<FitSession> session_;
  Callback on_update_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable idle_;
  std::vector<PeakInput> pending_;
  bool finish_requested_ = false;
  bool stop_ = false;
  bool busy_ = false;
  std::shared_ptr<CancelToken> running_;
  bool running_final_ = false;  // the running fit is a final one: Finish() lets it end
  // The newest apex submitted (sequence, bounce): a revision of an apex already seen (a
  // height refitted or heard) does not cut the running update short, a new apex does.
  int newest_sequence_ = -1, newest_bounce_ = -1;
  std::thread thread_;
  Stats stats_;
};

}  // namespace bouncefit
