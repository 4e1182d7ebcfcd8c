#pragma once
// The fit node: BOUNCE_PEAK (each bounce and its revisions) and DROP in; FIT_UPDATE out
// after every bounce and at the end of every drop. The fits run on a worker thread; what
// they give is published from the bus's thread by Poll(). It owns fit.jsonl and, once the
// stream is done, coefficients.json, fitted_ball/ and simulated.csv.
#include <chrono>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "bouncefit/ball_box_t.hpp"
#include "bouncefit/calibration_t.hpp"
#include "bouncefit/bounce_peak_t.hpp"
#include "bouncefit/drop_t.hpp"
#include "bouncefit/fit_update_t.hpp"
#include "bouncefit/stream_t.hpp"
#include "fit/fit_models.h"
#include "fit/fit_timeline.h"
#include "fit/fit_worker.h"
#include "fit/fitted_ball_gltf.h"
#include "model/ball_model.h"
#include "msgs/channels.h"

namespace bouncefit {

class LcmBus;

struct FitStageConfig {
  FitSetup fit;
  Channels channels;
  std::filesystem::path out_dir;  // empty: nothing written
  // A drop is over when no peak came for this long, s, and no DROP said so (an older log; 0: never).
  double final_after_s = 0;
};

// One drop of simulated.csv: the fitted ball from the drop's start apex, at start_t_s on the
// run's clock, until end_t_s (the next drop's start; infinite for the last).
struct SimulatedDrop {
  int drop = 0;
  double start_t_s = 0, end_t_s = 0;
  std::vector<TrajectorySample> trajectory;  // s since the start, real seconds
};

// simulated.csv in `dir` (docs/FORMATS.md): each drop's simulated trajectory on the run's
// clock (run_s_per_real_s of it per simulated second), beside the recorded one.
void WriteSimulatedCsv(const std::filesystem::path& dir, const std::vector<SimulatedDrop>& drops,
                       double run_s_per_real_s);

// Simulates each of the fit's drops from its start apex with the fit's values, for its span of
// the run's clock (ends: each drop's end, s since the first frame), and measures the run's
// clock against the simulation (*run_s_per_real_s). Drops whose ball diverges are left out.
// min_hop_m: where each simulated drop ends (SimulateFromStart).
std::vector<SimulatedDrop> SimulateFitDrops(const BallModel& model, const FitUpdate& fit,
                                            const std::vector<FitDrop>& drops,
                                            const std::vector<double>& ends_t_s, double min_hop_m,
                                            double* run_s_per_real_s);

class FitStage {
 public:
  using NoticeFn = std::function<void(const std::string&)>;

  // Builds the models and subscribes; throws std::invalid_argument for an unknown ball or model.
  FitStage(FitStageConfig config, LcmBus& bus, NoticeFn notice = {});
  ~FitStage();

  // Publishes the updates the worker finished, writes fit.jsonl; once the stream is done
  // and the last fit is out, writes the exports. Call from the bus's thread.
  void Poll();
  // The stream is done and everything is written.
  bool done() const { return done_; }
  // Waits (polling) until done; progress gets simulations run and the final fit's budget.
  void WaitDone(const std::function<void(int, int)>& progress);
  // Stops the worker (an interrupted session): what was published stays.
  void Stop();

  // Called from Poll() with every update as it is published.
  void set_update_observer(std::function<void(const fit_update_t&, const FitUpdate&)> fn) { on_update_ = std::move(fn); }
  // The last final fit that is an answer (none when the last one was not: no_fit_why()).
  const std::optional<FitUpdate>& final_fit() const { return final_; }
  // Why the last final fit is no answer ("" when it is one, or when none ran).
  const std::string& no_fit_why() const { return no_fit_why_; }
  const BallPreset& ball() const { return models_.ball; }
  int final_budget() const { return worker_->final_budget(); }
  int64_t last_message_wall_us() const { return last_wall_us_; }
  bool busy();

 private:
  void OnPeak(const bounce_peak_t& m);
  // Hands a bounce to the worker: never waits for a fit.
  void Submit(const bounce_peak_t& m);
  void OnDrop(const drop_t& m);
  void WriteExports();
  // The final fit's drops on the run's timeline: its own drop first, then the earlier drops it
  // was fitted with, each with its start apex and its bounces as peaks.csv numbers them.
  std::vector<FitDrop> Drops(const FitUpdate& u) const;
  // The tracked ball in metres above the floor from the start apex at start_t_s (s since the
  // first frame) to end_t_s, in real seconds since it (for the .glb).
  RecordedTrack Recorded(double start_t_s, double end_t_s, double run_s_per_real_s) const;

  FitStageConfig config_;
  LcmBus& bus_;
  NoticeFn notice_;
  std::function<void(const fit_update_t&, const FitUpdate&)> on_update_;
  FitModels models_;                    // before the worker: its session fits them
  std::unique_ptr<FitWorker> worker_;
  std::mutex inbox_mutex_;
  std::deque<std::pair<fit_update_t, FitUpdate>> inbox_;
  std::optional<FitUpdate> final_;
  std::string no_fit_why_;
  std::unique_ptr<std::ofstream> fit_jsonl_;
  int64_t t0_ = 0, now_ = 0;
  bool have_t0_ = false;  // t0_ is the stream's first frame (a file's is 0)
  bool stream_done_ = false, done_ = false, finished_since_peak_ = true;
  int final_sims_start_ = 0;
  int64_t last_wall_us_ = 0, last_peak_wall_us_ = 0;
  std::string input_;                    // the clip or camera (STREAM)
  std::vector<ball_box_t> boxes_;        // the frames the ball was found in
  // The rows of peaks.csv (revision 3): fitted when the peaks as they came gave no final fit
  // (bounces heard only, or renumbered into a run only at the end).
  std::vector<bounce_peak_t> rows_;
  bool rows_fitted_ = false;
  // Submits the rows as a drop of their own and its final fit; false when there are none.
  bool FitRows();
  std::optional<calibration_t> calibration_;
  // Bounces by (drop, the number they were emitted with: the fit's): the latest apex the fit
  // took, and the row of peaks.csv it became (its number there and its time).
  std::map<std::pair<int, int>, bounce_peak_t> fitted_peaks_, row_of_fitted_;
  // Each drop's start apex (the fit's number) and height, from its latest fit update.
  std::map<int, std::pair<int, double>> fit_starts_;
};

}  // namespace bouncefit
