#pragma once
// `--pick-window`: the paper's interactive picking in an OpenCV HighGUI window. What it shows
// and computes is track/color_pick.h and track/pick_view.h; this is only the window and its
// event loop.
#include <functional>
#include <memory>
#include <string>

#include "capture/frame.h"
#include "capture/frame_source.h"
#include "track/tracker.h"

namespace bouncefit::cli {

// Throws std::runtime_error with a one-line reason unless an X display can be opened
// (DISPLAY unset, or set to a display that does not answer). Call before any output exists.
void CheckPickWindowDisplay();

// Shows `frame` in a window until the user confirms (Enter or space) a click on the ball,
// and writes the picked colour (or brightness mode for a grey ball), the dragged region of
// interest and the colour tolerance into *config. Returns one line saying what was picked.
// Throws std::runtime_error ("cancelled") on Esc or when the window is closed.
std::string PickInWindow(const Frame& frame, const std::string& title, TrackerConfig* config);

// PickInWindow on the first frame of the source `open` returns (a camera's frame 0.5 s after it
// started, once its exposure settled). The source is closed again before the window opens, so
// the caller opens its own afterwards: a clip starts at frame 0, a camera drops nothing.
std::string PickOnFirstFrame(const std::function<std::unique_ptr<FrameSource>()>& open,
                             TrackerConfig* config);

}  // namespace bouncefit::cli
