#include "cli/tracker_flags.h"

#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "model/ball_preset.h"

namespace bouncefit::cli {

namespace {

struct NamedColor {
  const char* name;
  double b, g, r;
};

constexpr NamedColor kColors[] = {
    {"red", 40, 40, 220},     {"orange", 20, 120, 250}, {"yellow", 50, 235, 230},
    {"green", 60, 200, 60},   {"optic-green", 60, 220, 200}, {"blue", 200, 120, 30},
    {"purple", 160, 50, 130}, {"pink", 180, 120, 250},
};

std::vector<double> ParseNumbers(const std::string& text, size_t count, const char* what) {
  std::vector<double> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      size_t used = 0;
      out.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw std::invalid_argument(std::string(what) + ": '" + text + "' is not " +
                                  std::to_string(count) + " comma-separated numbers");
    }
  }
  if (out.size() != count)
    throw std::invalid_argument(std::string(what) + ": '" + text + "' is not " +
                                std::to_string(count) + " comma-separated numbers");
  return out;
}

std::string ColorNames() {
  std::string s;
  for (const auto& c : kColors) s += std::string(s.empty() ? "" : ", ") + c.name;
  return s;
}

}  // namespace

void ParseTrackerColor(const std::string& text, double bgr[3]) {
  for (const auto& c : kColors)
    if (text == c.name) {
      bgr[0] = c.b, bgr[1] = c.g, bgr[2] = c.r;
      return;
    }
  if (auto preset = FindBallPreset(text)) {
    for (int k = 0; k < 3; ++k) bgr[k] = preset->color_bgr[k];
    return;
  }
  if (text.find(',') == std::string::npos)
    throw std::invalid_argument("--color: unknown colour '" + text + "' (known: " + ColorNames() +
                                ", the ball presets " + BallPresetNames() + ", or B,G,R)");
  const auto v = ParseNumbers(text, 3, "--color");
  for (int k = 0; k < 3; ++k) {
    if (v[static_cast<size_t>(k)] < 0 || v[static_cast<size_t>(k)] > 255)
      throw std::invalid_argument("--color: components must be 0-255");
    bgr[k] = v[static_cast<size_t>(k)];
  }
}

void AddTrackerFlags(CLI::App* cmd, TrackerConfig* config, bool* pick_window) {
  const std::string group = "Tracker";
  auto* pick = cmd->add_option_function<std::string>(
         "--pick",
         [config](const std::string& s) {
           const auto v = ParseNumbers(s, 2, "--pick");
           config->has_pick = true;
           config->pick_x = v[0];
           config->pick_y = v[1];
         },
         "Ball colour from this pixel of the first frame, X,Y in pixels")
      ->group(group);
  auto* color = cmd->add_option_function<std::string>(
         "--color",
         [config](const std::string& s) {
           config->color_name = s;
           if (s == "white" || s == "black" || s == "grey") {
             // A colourless ball: follow its brightness against the background.
             config->luma_mode = true;
             config->luma.polarity = s == "white" ? +1 : s == "black" ? -1 : 0;
             return;
           }
           ParseTrackerColor(s, config->color_bgr);
           config->has_color = true;
         },
         "Ball colour: a name (" + ColorNames() + "), a ball preset, or B,G,R 0-255; "
         "white, black or grey (brighter, darker, either; or --pick on a nearly grey ball) track its brightness against a "
         "background model instead. Without --pick or --color the tracker chooses by itself: a "
         "round blob that moves and differs from its surroundings (by colour, else brightness), "
         "kept once its track is a ballistic arc")
      ->group(group);
  cmd->add_flag("--pick-window", *pick_window,
                "Pick the ball as in the paper's Fig. 1: a window on the first frame; click the "
                "ball, drag a region of interest, check the Cb/Cr histograms and the mask, then "
                "Enter or space (Esc cancels). Needs a display")
      ->excludes(pick)->excludes(color)->group(group);
  cmd->add_option_function<std::string>(
         "--roi",
         [config](const std::string& s) {
           const auto v = ParseNumbers(s, 4, "--roi");
           if (v[0] < 0 || v[1] < 0 || v[2] < 8 || v[3] < 8)
             throw std::invalid_argument("--roi: X,Y must be >= 0 and W,H >= 8 pixels");
           config->roi_x = static_cast<int>(v[0]);
           config->roi_y = static_cast<int>(v[1]);
           config->roi_w = static_cast<int>(v[2]);
           config->roi_h = static_cast<int>(v[3]);
         },
         "Region of interest X,Y,W,H in pixels (default: whole frame)")
      ->group(group);
  cmd->add_option("--blur", config->blur_sigma_px,
                  "Gaussian blur sigma before thresholding, pixels")
      ->capture_default_str()->check(CLI::Range(0.0, 5.0))->group(group);
  cmd->add_option("--color-tolerance", config->color.tolerance_rel,
                  "Colour match radius, as a fraction of the ball's chroma/luma")
      ->capture_default_str()->check(CLI::Range(0.05, 2.0))->group(group);
  cmd->add_option("--min-box", config->segment.min_box_px,
                  "Smallest ball box side, pixels")
      ->capture_default_str()->check(CLI::Range(1.0, 10000.0))->group(group);
  cmd->add_option("--max-box", config->segment.max_box_px,
                  "Largest ball box side, pixels")
      ->capture_default_str()->check(CLI::Range(2.0, 10000.0))->group(group);
  cmd->add_option("--adapt-rate", config->adapt_rate,
                  "Colour adaptation per frame towards the ball's measured colour, fraction 0-1 (0 = off)")
      ->capture_default_str()->check(CLI::Range(0.0, 1.0))->group(group);
  cmd->add_option("--rays", config->centre.rays,
                  "Rays cast to find the ball's rim for the sub-pixel centre, count")
      ->capture_default_str()->check(CLI::Range(8, 1024))->group(group);
  cmd->add_option("--luma-contrast", config->luma.min_contrast_luma,
                  "Brightness mode: least luma difference of a ball pixel from the background, 0-255")
      ->capture_default_str()->check(CLI::Range(1.0, 35.0))->group(group);
  cmd->add_option("--auto-contrast", config->finder.min_chroma_contrast,
                  "Automatic choice: least chroma/luma between a moving ball and its surroundings to follow its colour, unitless")
      ->capture_default_str()->check(CLI::Range(0.02, 2.0))->group(group);
}

}  // namespace bouncefit::cli
