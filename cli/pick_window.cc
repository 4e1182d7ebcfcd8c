#include "cli/pick_window.h"

#include <X11/Xlib.h>
#include <fmt/format.h>
#include <opencv2/highgui.hpp>

#include <cmath>
#include <cstdlib>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>

#include "replay/video_file_source.h"
#include "track/color_pick.h"
#include "track/pick_view.h"

namespace bouncefit::cli {

namespace {

// What the mouse has done so far, in frame pixels.
struct PickState {
  PickLayout layout;
  std::optional<cv::Point2d> click;
  cv::Rect roi;                       // empty: whole frame
  std::optional<cv::Point> press;     // view pixels, while the left button is down
  bool dragging = false;
  bool dirty = true;                  // redraw (and recompute) before the next wait
};

constexpr int kDragPx = 5;  // a press that moves further is a drag, view pixels

cv::Rect FrameRect(const PickLayout& l, cv::Point a, cv::Point b) {
  const cv::Point2d fa = l.ToFrame(a), fb = l.ToFrame(b);
  return cv::Rect(cv::Point(static_cast<int>(std::floor(std::min(fa.x, fb.x))),
                            static_cast<int>(std::floor(std::min(fa.y, fb.y)))),
                  cv::Point(static_cast<int>(std::ceil(std::max(fa.x, fb.x))) + 1,
                            static_cast<int>(std::ceil(std::max(fa.y, fb.y))) + 1));
}

void OnMouse(int event, int x, int y, int, void* data) {
  auto& s = *static_cast<PickState*>(data);
  const cv::Point at(x, y);
  if (event == cv::EVENT_LBUTTONDOWN) {
    if (s.layout.InFrame(at)) s.press = at, s.dragging = false;
  } else if (event == cv::EVENT_MOUSEMOVE && s.press) {
    if (!s.dragging && std::hypot(at.x - s.press->x, at.y - s.press->y) > kDragPx) s.dragging = true;
    if (s.dragging) s.roi = FrameRect(s.layout, *s.press, at), s.dirty = true;
  } else if (event == cv::EVENT_LBUTTONUP && s.press) {
    if (s.dragging) {
      s.roi = FrameRect(s.layout, *s.press, at);
      if (s.roi.width < 8 || s.roi.height < 8) s.roi = cv::Rect();  // too small: whole frame
    } else {
      s.click = s.layout.ToFrame(*s.press);
    }
    s.press.reset();
    s.dragging = false;
    s.dirty = true;
  }
}

std::string RoiText(const cv::Rect& r) {
  if (r.area() <= 0) return "whole frame";
  return std::to_string(r.x) + "," + std::to_string(r.y) + "," + std::to_string(r.width) + "," +
         std::to_string(r.height) + " px";
}

}  // namespace

void CheckPickWindowDisplay() {
  const char* name = std::getenv("DISPLAY");
  if (!name || !*name)
    throw std::runtime_error("--pick-window needs a display to open its window, and DISPLAY is unset "
                             "(use --pick X,Y or --color without one)");
  Display* d = XOpenDisplay(nullptr);
  if (!d)
    throw std::runtime_error(std::string("--pick-window: cannot open the display DISPLAY=") + name);
  XCloseDisplay(d);
}

std::string PickInWindow(const Frame& frame, const std::string& title, TrackerConfig* config) {
  CheckPickWindowDisplay();
  PickState s;
  s.layout = LayoutPickView(FramePixelSize(frame), PickViewParams{});
  // A --roi given with the flag is where the window starts.
  if (config->roi_w > 0 && config->roi_h > 0)
    s.roi = cv::Rect(config->roi_x, config->roi_y, config->roi_w, config->roi_h) & cv::Rect({}, s.layout.frame_size);
  std::unique_ptr<PickPreview> preview;
  std::string status = "click the ball";
  double tolerance = config->color.tolerance_rel;

  // GUI_NORMAL: no toolbar, so the image starts at the window's corner and is shown 1:1.
  cv::namedWindow(title, cv::WINDOW_AUTOSIZE | cv::WINDOW_GUI_NORMAL);
  cv::setMouseCallback(title, OnMouse, &s);
  auto close = [&] {
    cv::destroyWindow(title);
    for (int i = 0; i < 5; ++i) cv::waitKey(1);
  };
  bool shown = false;
  // Recomputes the preview and redraws after the mouse changed something.
  auto refresh = [&] {
    if (!s.dirty) return;
    s.dirty = false;
    preview.reset();
    if (s.click) {
      ColorModelParams cp = config->color;
      cp.tolerance_rel = tolerance;
      preview = std::make_unique<PickPreview>(ComputePickPreview(
          frame, *s.click, s.roi, cp, config->segment, config->blur_sigma_px));
      status = DescribePick(*preview);
      if (!preview->picked.grey && preview->ball_blob < 0)
        status += "; if the ball is there, widen the tolerance (+)";
      if (s.roi.area() > 0 && !s.roi.contains(cv::Point(static_cast<int>(s.click->x),
                                                         static_cast<int>(s.click->y))))
        status += "; the click is outside the region";
    }
    const std::string where =
        s.click ? fmt::format("ball at {:.0f},{:.0f} px", s.click->x, s.click->y) : "no click yet";
    cv::imshow(title, ComposePickView(frame, s.layout, preview.get(), s.roi,
                                      {"click the ball; drag a region of interest (r: whole frame); "
                                       "+/-: colour tolerance; Enter or space: confirm; Esc: cancel",
                                       fmt::format("{}; region {}; tolerance {:.2f} of the ball's chroma", where,
                                                   RoiText(s.roi), tolerance),
                                       status}));
    shown = true;
  };
  while (true) {
    refresh();
    const int key = cv::waitKey(20);
    // Closed by its title bar's button (the window manager's WM_DELETE_WINDOW): Qt hides it.
    if (shown && cv::getWindowProperty(title, cv::WND_PROP_VISIBLE) < 1) {
      close();
      throw std::runtime_error("--pick-window: cancelled (the window was closed); nothing written");
    }
    if (key < 0) continue;
    const int k = key & 0xff;
    if (k == 27) {
      close();
      throw std::runtime_error("--pick-window: cancelled (Esc); nothing written");
    }
    if (k == 13 || k == 10 || k == ' ') {
      refresh();  // a click in the same wait as the key counts
      if (!preview) {
        status = "click the ball first, then confirm";
        s.dirty = true;
        continue;
      }
      break;
    }
    if (k == '+' || k == '=') tolerance = std::min(2.0, tolerance * 1.25), s.dirty = true;
    if (k == '-' || k == '_') tolerance = std::max(0.05, tolerance / 1.25), s.dirty = true;
    if (k == 'r') s.roi = cv::Rect(), s.dirty = true;
  }
  close();

  const std::string at = fmt::format("{:.0f},{:.0f}", s.click->x, s.click->y);
  if (preview->picked.grey) {
    config->luma_mode = true;
    config->luma.polarity = preview->picked.polarity;
    config->color_name = "picked in the window at " + at + ", nearly grey";
  } else {
    config->has_chroma = true;
    config->chroma_nu = preview->picked.color.nu();
    config->chroma_nv = preview->picked.color.nv();
    config->color_name = "picked in the window at " + at;
  }
  config->color.tolerance_rel = tolerance;
  config->roi_x = s.roi.x, config->roi_y = s.roi.y;  // all 0: the whole frame
  config->roi_w = s.roi.width, config->roi_h = s.roi.height;
  return fmt::format("pick-window: ball at {} px, region {}, tolerance {:.2f}: {}", at, RoiText(s.roi), tolerance,
                     DescribePick(*preview));
}

std::string PickOnFirstFrame(const std::function<std::unique_ptr<FrameSource>()>& open,
                             TrackerConfig* config) {
  CheckPickWindowDisplay();
  std::optional<Frame> first;
  std::string what;
  {
    // Closed again before the window opens: a camera does not stream (and drop) meanwhile.
    const std::unique_ptr<FrameSource> source = open();
    const bool live = source->Info().frame_count < 0;
    what = source->Info().description;
    first = source->Next();
    // A camera's first frames are often dark while its exposure settles: take one 0.5 s on.
    if (live && first) {
      const int64_t start = first->utime;
      while (first && first->utime - start < 500000) first = source->Next();
    }
    if (first) first->image = first->image.clone();
  }
  if (!first || first->image.empty())
    throw std::runtime_error("--pick-window: " + what + " gave no frame to pick on");
  return PickInWindow(*first, "bouncefit: pick the ball", config);
}

}  // namespace bouncefit::cli
