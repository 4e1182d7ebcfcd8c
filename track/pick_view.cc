#include "track/pick_view.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

#include "track/ycc_planes.h"

namespace bouncefit {

namespace {

const cv::Scalar kGreen(0, 255, 0), kYellow(0, 220, 255), kMagenta(255, 0, 255),
    kOrange(0, 140, 255), kWhite(255, 255, 255), kGrey(150, 150, 150), kDark(30, 30, 30);
constexpr int kLineHeight = 18;  // view pixels per text line
constexpr int kGap = 4;          // between the frame and the panel, view pixels

void Label(cv::Mat& view, const std::string& text, cv::Point at, const cv::Scalar& colour) {
  cv::putText(view, text, at, cv::FONT_HERSHEY_SIMPLEX, 0.42, cv::Scalar(0, 0, 0), 3, cv::LINE_AA);
  cv::putText(view, text, at, cv::FONT_HERSHEY_SIMPLEX, 0.42, colour, 1, cv::LINE_AA);
}

cv::Rect ToViewRect(const PickLayout& l, const cv::Rect2f& r) {
  const cv::Point a = l.ToView({r.x, r.y}), b = l.ToView({r.x + r.width, r.y + r.height});
  return cv::Rect(a, b);
}

cv::Mat FrameBgr(const Frame& frame) {
  if (frame.format == PixelFormat::kBgr24) return frame.image;
  cv::Mat bgr;
  cv::cvtColor(frame.image, bgr, cv::COLOR_YUV2BGR_YUYV);
  return bgr;
}

void DrawFrame(cv::Mat& view, const Frame& frame, const PickLayout& l, const PickPreview* p,
               cv::Rect roi) {
  cv::Mat small;
  cv::resize(FrameBgr(frame), small, l.frame_area.size(), 0, 0, cv::INTER_AREA);
  // Outside the region is dimmed: the tracker will not look there.
  const cv::Rect r = roi.area() > 0 ? ToViewRect(l, cv::Rect2f(roi)) & cv::Rect({}, small.size())
                                    : cv::Rect({}, small.size());
  cv::Mat dim = small * 0.45;
  small(r).copyTo(dim(r));
  dim.copyTo(view(l.frame_area));
  cv::Mat f = view(l.frame_area);
  if (roi.area() > 0) cv::rectangle(f, r, kYellow, 1);
  if (!p) return;
  for (size_t k = 0; k < p->blobs.size(); ++k) {
    const bool ball = static_cast<int>(k) == p->ball_blob;
    const cv::Rect b = ToViewRect(l, p->blobs[k].box);
    cv::rectangle(f, b - cv::Point(1, 1) + cv::Size(2, 2), ball ? kGreen : kOrange, ball ? 2 : 1);
  }
  cv::drawMarker(f, l.ToView(p->click), kMagenta, cv::MARKER_CROSS, 12, 1);
}

void DrawMask(cv::Mat& view, const PickLayout& l, const PickPreview* p) {
  cv::Mat area = view(l.mask_area);
  area.setTo(kDark);
  if (!p) {
    Label(view, "mask: click the ball", l.mask_area.tl() + cv::Point(6, 16), kGrey);
    return;
  }
  // Fit the mask into its box, keeping its aspect.
  const double s = std::min(static_cast<double>(area.cols) / p->mask.cols,
                            static_cast<double>(area.rows - 20) / p->mask.rows);
  const cv::Size sz(std::max(1, static_cast<int>(p->mask.cols * s)),
                    std::max(1, static_cast<int>(p->mask.rows * s)));
  cv::Mat m, bgr;
  cv::resize(p->mask, m, sz, 0, 0, cv::INTER_AREA);
  cv::cvtColor(m, bgr, cv::COLOR_GRAY2BGR);
  const cv::Rect at(cv::Point((area.cols - sz.width) / 2, 20), sz);
  bgr.copyTo(area(at));
  if (p->ball_blob >= 0) {
    const cv::Rect2f& b = p->blobs[static_cast<size_t>(p->ball_blob)].box;
    const double k = s / p->step;
    const cv::Rect box(at.x + static_cast<int>((b.x - p->roi.x) * k) - 1,
                       at.y + static_cast<int>((b.y - p->roi.y) * k) - 1,
                       static_cast<int>(b.width * k) + 2, static_cast<int>(b.height * k) + 2);
    cv::rectangle(area, box, kGreen, 1);
  }
  Label(view, p->picked.grey ? "grey ball: brightness, no colour mask" : "mask of the thresholds",
        l.mask_area.tl() + cv::Point(6, 14), kWhite);
}

void DrawHistogram(cv::Mat& view, const cv::Rect& box, const ChromaHistogram& h, double low,
                   double high, bool band, const std::string& title) {
  cv::Mat area = view(box);
  area.setTo(kDark);
  const int top = 20, bottom = 16, plot_h = box.height - top - bottom;
  const double bin_w = static_cast<double>(box.width) / ChromaHistogram::kBins;
  int peak = 1;
  for (int c : h.all) peak = std::max(peak, c);
  // Logarithmic counts: the ball's few hundred pixels stay visible beside the wall's 10^5.
  const double k = plot_h / std::log1p(static_cast<double>(peak));
  auto x_of = [&](double value) {
    return static_cast<int>((value + ChromaHistogram::kRange) / (2 * ChromaHistogram::kRange) * box.width);
  };
  if (band) {
    cv::Mat shade = area(cv::Rect(cv::Point(std::clamp(x_of(low), 0, box.width - 1), top),
                                  cv::Point(std::clamp(x_of(high), 1, box.width), top + plot_h)));
    shade += cv::Scalar(0, 45, 60);
  }
  for (int b = 0; b < ChromaHistogram::kBins; ++b) {
    const int x0 = static_cast<int>(b * bin_w), x1 = std::max(x0 + 1, static_cast<int>((b + 1) * bin_w));
    const int all = static_cast<int>(std::lround(k * std::log1p(static_cast<double>(h.all[b]))));
    const int match = static_cast<int>(std::lround(k * std::log1p(static_cast<double>(h.matching[b]))));
    if (all > 0) cv::rectangle(area, cv::Point(x0, top + plot_h - all), cv::Point(x1 - 1, top + plot_h - 1), kGrey, cv::FILLED);
    if (match > 0) cv::rectangle(area, cv::Point(x0, top + plot_h - match), cv::Point(x1 - 1, top + plot_h - 1), kGreen, cv::FILLED);
  }
  if (band) {
    cv::line(area, {x_of(low), top}, {x_of(low), top + plot_h}, kYellow, 1);
    cv::line(area, {x_of(high), top}, {x_of(high), top + plot_h}, kYellow, 1);
  }
  cv::line(area, {x_of(0), top + plot_h}, {x_of(0), top + plot_h + 3}, kWhite, 1);
  Label(view, title, box.tl() + cv::Point(6, 14), kWhite);
  Label(view, "-2", box.tl() + cv::Point(2, box.height - 3), kGrey);
  Label(view, "0", box.tl() + cv::Point(x_of(0) - 4, box.height - 3), kGrey);
  Label(view, "+2", box.tl() + cv::Point(box.width - 20, box.height - 3), kGrey);
}

}  // namespace

cv::Point PickLayout::ToView(cv::Point2d p) const {
  return {frame_area.x + static_cast<int>(std::lround((p.x + 0.5) * scale - 0.5)),
          frame_area.y + static_cast<int>(std::lround((p.y + 0.5) * scale - 0.5))};
}

cv::Point2d PickLayout::ToFrame(cv::Point v) const {
  const double x = (v.x - frame_area.x + 0.5) / scale - 0.5, y = (v.y - frame_area.y + 0.5) / scale - 0.5;
  return {std::clamp(x, 0.0, frame_size.width - 1.0), std::clamp(y, 0.0, frame_size.height - 1.0)};
}

PickLayout LayoutPickView(cv::Size frame_size, const PickViewParams& params) {
  PickLayout l;
  l.frame_size = frame_size;
  const int text_h = params.text_lines * kLineHeight + 8;
  const int min_panel_h = 360;
  l.scale = std::min({1.0, static_cast<double>(params.max_width - params.panel_width - kGap) / frame_size.width,
                      static_cast<double>(params.max_height - text_h) / frame_size.height});
  const int fw = std::max(1, static_cast<int>(frame_size.width * l.scale));
  const int fh = std::max(1, static_cast<int>(frame_size.height * l.scale));
  const int h = std::max(fh, min_panel_h);
  l.frame_area = cv::Rect(0, 0, fw, fh);
  const int hist_h = std::max(100, h / 4);
  const int px = fw + kGap, pw = params.panel_width;
  l.mask_area = cv::Rect(px, 0, pw, h - 2 * hist_h - 8);
  l.cb_area = cv::Rect(px, h - 2 * hist_h - 4, pw, hist_h);
  l.cr_area = cv::Rect(px, h - hist_h, pw, hist_h);
  l.text_area = cv::Rect(0, h + 4, px + pw, text_h - 4);
  l.size = cv::Size(px + pw, h + text_h);
  return l;
}

cv::Mat ComposePickView(const Frame& frame, const PickLayout& l, const PickPreview* p,
                        cv::Rect roi, const std::vector<std::string>& lines) {
  cv::Mat view(l.size, CV_8UC3, cv::Scalar(0, 0, 0));
  DrawFrame(view, frame, l, p, roi);
  DrawMask(view, l, p);
  ChromaHistogram empty;
  const bool band = p && !p->picked.grey;
  DrawHistogram(view, l.cb_area, p ? p->cb : empty, p ? p->cb_low : 0, p ? p->cb_high : 0, band,
                "Cb/Y of the region (log count)");
  DrawHistogram(view, l.cr_area, p ? p->cr : empty, p ? p->cr_low : 0, p ? p->cr_high : 0, band,
                "Cr/Y of the region (log count)");
  for (size_t i = 0; i < lines.size(); ++i)
    Label(view, lines[i], l.text_area.tl() + cv::Point(6, 14 + static_cast<int>(i) * kLineHeight), kWhite);
  return view;
}

}  // namespace bouncefit
