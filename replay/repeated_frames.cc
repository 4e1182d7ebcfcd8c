#include "replay/repeated_frames.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <bit>

namespace bouncefit {
namespace {

// Cells of 2x2 pixels (grey) that changed between two pictures, by more than a camera's noise
// (3 levels) and by more than a codec's requantisation (10 levels). A repeat re-encoded by a
// lossy codec changes no cell by 10 and a few by 3; a camera's noise alone changes tens to
// thousands by 3, a moving ball hundreds to thousands by 10 (measured on phone files).
constexpr int kNoiseLevel = 3, kCodecLevel = 10;
constexpr int kRepeatMaxCells = 2;    // by kCodecLevel
constexpr int kRepeatFraction = 20;   // by kNoiseLevel: 1/20 of the picture before's change
constexpr int kChangedMinCells = 30;  // by kNoiseLevel: the picture before was a new one
// A file re-encoded (a phone's repeats through another encoder) requantises each repeat
// anew: tens of cells change by a few levels. Where the picture before showed something move
// (this many cells by kCodecLevel) and this one moves nothing, that much is still a repeat.
constexpr int kMovedMinCells = 10;
constexpr int kRequantisedShare = 2000;  // cells by kNoiseLevel: up to 1/2000 of the picture
// 3:2 pulldown repeats a picture twice at most; longer runs are a still scene.
constexpr int kMaxRun = 2;
// Repeats a file makes are regular: this many of the last 16 pictures.
constexpr int kPattern = 3;

cv::Mat HalfGrey(const cv::Mat& bgr) {
  cv::Mat grey, half;  // grey first: one channel to average (the cheaper order, 1 ms at 1080p)
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  cv::resize(grey, half, cv::Size((bgr.cols + 1) / 2, (bgr.rows + 1) / 2), 0, 0, cv::INTER_AREA);
  return half;
}

}  // namespace

bool RepeatedFrameFilter::IsRepeat(const cv::Mat& bgr) {
  cv::Mat grey = HalfGrey(bgr);
  if (previous_.empty() || previous_.size() != grey.size()) {
    previous_ = grey;
    changed_cells_ = 0;
    moved_cells_ = 0;
    run_ = 0;
    recent_ = 0;
    return false;
  }
  cv::Mat diff;
  cv::absdiff(grey, previous_, diff);
  const int noisy = cv::countNonZero(diff > kNoiseLevel);
  const int coded = noisy == 0 ? 0 : cv::countNonZero(diff > kCodecLevel);
  previous_ = grey;
  const int requantised = static_cast<int>(diff.total() / kRequantisedShare);
  const int allowed = std::max({kRepeatMaxCells, changed_cells_ / kRepeatFraction,
                                moved_cells_ >= kMovedMinCells ? requantised : 0});
  const bool looks_repeat = coded <= kRepeatMaxCells && changed_cells_ >= kChangedMinCells &&
                            noisy <= allowed && run_ < kMaxRun;
  recent_ = static_cast<uint16_t>((recent_ << 1) | (looks_repeat ? 1u : 0u));
  if (!looks_repeat) {
    run_ = 0;
    changed_cells_ = noisy;
    moved_cells_ = coded;
    return false;
  }
  ++run_;
  if (std::popcount(recent_) < kPattern) return false;
  ++repeats_;
  return true;
}

}  // namespace bouncefit
