#pragma once
// What a video container says about its own clock beyond the frame times: the capture rate
// a phone writes into a slow-motion file (frames captured at 120 or 240 fps, stored on a
// slowed 30 fps timeline, sometimes only a middle part of the clip through the container's
// edit list). The detector uses it only as a hint that gravity against the ball's size must
// confirm (docs/ACCURACY.md "The clock").
#include <string>

namespace bouncefit {

struct ContainerClock {
  double capture_fps = 0;  // the rate the frames were captured at (0: the file does not say)
  double stored_fps = 0;   // the video stream's nominal rate
  std::string tag;         // where capture_fps came from ("com.android.capture.fps")
  // How many times slower than real time the file plays (capture / stored; 1 when unknown).
  double SlowDown() const {
    return capture_fps > 0 && stored_fps > 0 && capture_fps > 1.05 * stored_fps
               ? capture_fps / stored_fps
               : 1.0;
  }
};

// Reads the container's metadata (libavformat). Never throws: a file it cannot read says
// nothing (the frames themselves are read elsewhere, with their own errors).
ContainerClock ReadContainerClock(const std::string& path);

}  // namespace bouncefit
