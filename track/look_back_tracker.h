#pragma once
// The tracker with a look back. Frames in which it does not find the ball, or does not place its
// centre (a ball the border cuts, too little of it in view), wait (a quarter of a second at
// most), and so do those of a lock the tracker is not sure of (Tracker::tentative: an arm
// reaching in, the ball beside it); once it places the ball again it looks for it in them,
// newest first, from where it placed it (its radius known now, a ball cut by the border is
// placed by its rim). A finder that sees what moves finds a ball held still only once it falls
// (at 30 fps a 10 cm drop is four frames), and a streak rising from an impact may slip past
// the window for a frame: such frames are found this way. Every frame still comes out once,
// in order, with its own time; only frames without the ball (or with a tentative lock) wait,
// so a ball followed frame after frame comes out at once.
#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include "capture/frame.h"
#include "track/ball_observation.h"
#include "track/tracker.h"

namespace bouncefit {

struct LookBackConfig {
  double max_wait_s = 0.25;  // a frame without the ball waits at most this long, s ...
  int max_frames = 16;       // ... and among at most this many (the pictures kept)
  // A tentative lock's frames (an arm that may hold the ball) wait longer: a toss is carried
  // for a few tenths of a second before the ball leaves the hand and is chosen, s and frames.
  double tentative_wait_s = 0.6;
  int tentative_frames = 32;
};

// A frame and what the tracker made of it.
struct TrackedFrame {
  Frame frame;
  BallObservation obs;
  bool tentative = false;  // Tracker::tentative(): waits as a frame without the ball does
};

class LookBackTracker {
 public:
  // Throws std::invalid_argument for a config out of range.
  LookBackTracker(Tracker& tracker, LookBackConfig config = {});

  // Tracks `frame`: the frames settled by it, oldest first (none while they wait).
  std::vector<TrackedFrame> Track(const Frame& frame);
  // The end of the stream: every frame still waiting, oldest first.
  std::vector<TrackedFrame> Flush();

 private:
  // The index of the first waiting frame the ball was found in (waiting_.size(): none).
  size_t FirstFound() const;
  // Looks for the ball in the waiting frames before `first`, the first one it was found in,
  // newest first, until one does not show it.
  void LookBack(size_t first);
  // Settles the `n` oldest waiting frames into *out.
  void Settle(size_t n, std::vector<TrackedFrame>* out);

  Tracker& tracker_;
  LookBackConfig config_;
  std::deque<TrackedFrame> waiting_;
  // The ball in the frame settled just before the waiting ones, when it was found there.
  std::optional<BallObservation> before_;
};

}  // namespace bouncefit
