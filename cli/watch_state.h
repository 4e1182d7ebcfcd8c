#pragma once
// What `bouncefit watch` knows about the session it is attached to, built from the bus
// messages. No terminal and no clock inside: every call takes the receive time.
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "bouncefit/ball_box_t.hpp"
#include "bouncefit/bounce_peak_t.hpp"
#include "bouncefit/calibration_t.hpp"
#include "bouncefit/fit_update_t.hpp"
#include "bouncefit/impact_t.hpp"
#include "bouncefit/stream_t.hpp"

namespace bouncefit::cli {

struct WatchConfig {
  double trace_window_s = 10;   // height trace kept and shown, seconds of stream time
  double stale_after_s = 2;     // no message for this long: "waiting for data"
  double rate_window_s = 2;     // message rates averaged over this, seconds
  double restart_gap_s = 1;     // a box this far back in stream time starts a new stream
};

struct WatchChannelStats {
  int64_t count = 0;
  int64_t first_recv_utime = 0;
  std::deque<int64_t> recent_recv_utime;  // receive times inside the rate window
};

class WatchState {
 public:
  explicit WatchState(WatchConfig config = {}) : config_(config) {}

  // now_utime: when the message was received (wall clock of the watcher).
  void OnStream(const stream_t& m, int64_t now_utime);
  void OnBox(const ball_box_t& m, int64_t now_utime);
  void OnCalibration(const calibration_t& m, int64_t now_utime);
  void OnPeak(const bounce_peak_t& m, int64_t now_utime);
  void OnFit(const fit_update_t& m, int64_t now_utime);
  void OnImpact(const impact_t& m, int64_t now_utime);

  struct TraceSample {
    int64_t utime;
    bool found;
    double cx, cy, h;  // box centre and height, pixels
  };
  const std::deque<TraceSample>& trace() const { return trace_; }
  const std::optional<calibration_t>& calibration() const { return calibration_; }
  const std::vector<bounce_peak_t>& peaks() const { return peaks_; }  // current drop
  const std::optional<fit_update_t>& fit() const { return fit_; }     // latest, any model
  // The fit before the latest one of the same model (for the change column), if any.
  const fit_update_t* previous_fit() const;
  // The latest fit of each model (a run may fit a quick model and the soft body in turn).
  const std::map<std::string, fit_update_t>& latest_by_model() const { return latest_by_model_; }
  int64_t fits_received() const { return fits_received_; }
  // Impacts of this stream as they arrived (heard, seen, or both), the last 1000.
  const std::vector<impact_t>& impacts() const { return impacts_; }

  // Messages per second on each channel over the rate window ending at now.
  double Rate(const std::string& kind, int64_t now_utime) const;
  int64_t Count(const std::string& kind) const;
  bool AnyData() const { return last_recv_utime_ > 0; }
  // Seconds since the last message (any channel); < 0 if none ever.
  double SilenceS(int64_t now_utime) const;
  bool Waiting(int64_t now_utime) const;

  // The stream's first frame (STREAM, else the first box seen); a file's is 0.
  int64_t stream_start_utime() const { return stream_start_utime_; }
  bool has_stream_start() const { return has_stream_start_; }
  int64_t last_box_utime() const { return last_box_utime_; }
  int64_t frame_gaps() const { return frame_gaps_; }    // frames missing from the box stream
  int64_t lost_frames() const { return lost_frames_; }  // boxes with found == false
  int64_t restarts() const { return restarts_; }        // producer restarts seen
  int current_sequence() const { return sequence_; }

  // Height of the ball bottom for a trace sample: metres above the floor with a usable
  // calibration, else pixels above the lowest bottom seen. NaN if not found.
  double SampleHeight(const TraceSample& s, bool* metres) const;

 private:
  void Count(const std::string& kind, int64_t now_utime);
  void NewStream();

  WatchConfig config_;
  std::map<std::string, WatchChannelStats> stats_;
  std::deque<TraceSample> trace_;
  std::optional<calibration_t> calibration_;
  std::vector<bounce_peak_t> peaks_;
  std::vector<impact_t> impacts_;
  std::optional<fit_update_t> fit_;
  std::map<std::string, fit_update_t> latest_by_model_, previous_by_model_;
  int64_t fits_received_ = 0;
  int64_t last_recv_utime_ = 0;
  int64_t stream_start_utime_ = 0;
  bool has_stream_start_ = false;
  int64_t last_box_utime_ = 0;
  int64_t last_frame_ = -1;
  int64_t frame_gaps_ = 0;
  int64_t lost_frames_ = 0;
  int64_t restarts_ = 0;
  int sequence_ = -1;
  double lowest_bottom_px_ = -1e300;
  bool final_rows_ = false;      // peaks_ holds the rows of peaks.csv (the stream ended)
  bool fused_impacts_ = false;   // impacts_ holds the fused impacts (the stream ended)
};

}  // namespace bouncefit::cli
