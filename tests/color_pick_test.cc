// The paper's picking without its window (track/color_pick.h, track/pick_view.h): the colour,
// histograms, thresholds and mask that --pick-window shows, on rendered frames with known truth
// and on first frames of the shared real clips.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "tests/test_support.h"
#include "tests/tracker_test_util.h"
#include "track/color_pick.h"
#include "track/pick_view.h"

namespace bouncefit {
namespace {

SynthClipResult Render(const std::string& name, bool distractor) {
  SynthClipConfig c;
  c.ball = *FindBallPreset("pingpong");
  c.noise_sigma = 3;
  c.hold_s = 0.1;
  c.duration_s = 0.6;
  c.distractor = distractor;
  c.out = testing::ScratchDir(name) / "clip.avi";
  return RenderSynthClip(c);
}

Frame FirstFrame(const std::filesystem::path& clip) {
  VideoFileSource source(VideoFileSourceConfig{clip.string(), false});
  std::optional<Frame> f = source.Next();
  if (!f) throw std::runtime_error("no first frame in " + clip.string());
  f->image = f->image.clone();
  return *f;
}

PickPreview Preview(const Frame& f, cv::Point2d click, cv::Rect roi = {}) {
  const TrackerConfig t;  // the tracker's defaults, as --pick-window uses them
  return ComputePickPreview(f, click, roi, t.color, t.segment, t.blur_sigma_px);
}

int Sum(const std::array<int, ChromaHistogram::kBins>& h) { return std::accumulate(h.begin(), h.end(), 0); }

// The colour from a click is the colour --pick gives: tracking with it as a given chroma and
// tracking with --pick at the same pixel see the same ball in every frame.
TEST(ColorPick, ClickGivesTheColourOfPick) {
  const SynthClipResult clip = Render("pick_same", false);
  const SynthTruthFrame& t0 = clip.truth.frames[0];
  TrackerConfig pick;
  pick.has_pick = true, pick.pick_x = t0.cx, pick.pick_y = t0.cy;
  const PickedColor picked = PickColor(FirstFrame(clip.clip_path), t0.cx, t0.cy, pick.color,
                                       pick.blur_sigma_px);
  ASSERT_FALSE(picked.grey);
  TrackerConfig chroma;
  chroma.has_chroma = true, chroma.chroma_nu = picked.color.nu(), chroma.chroma_nv = picked.color.nv();
  const auto a = testing::TrackClip(clip.clip_path, pick, &clip.truth);
  const auto b = testing::TrackClip(clip.clip_path, chroma, &clip.truth);
  ASSERT_EQ(a.obs.size(), b.obs.size());
  for (size_t i = 0; i < a.obs.size(); ++i) {
    EXPECT_EQ(a.obs[i].found, b.obs[i].found) << "frame " << i;
    EXPECT_DOUBLE_EQ(a.obs[i].cx, b.obs[i].cx) << "frame " << i;
    EXPECT_DOUBLE_EQ(a.obs[i].cy, b.obs[i].cy) << "frame " << i;
  }
  EXPECT_EQ(b.lost, 0);
  EXPECT_LE(b.rms, 0.3);
  EXPECT_THROW(PickColor(FirstFrame(clip.clip_path), 640, 10, pick.color, 1), std::invalid_argument);
}

// The preview of a click on the ball: the ball's blob where the truth puts it, the thresholds
// around its colour, a mask that holds the ball and little else, histograms of the region.
TEST(ColorPick, PreviewFindsTheBallAndItsThresholds) {
  const SynthClipResult clip = Render("pick_preview", true);
  const Frame f = FirstFrame(clip.clip_path);
  const SynthTruthFrame& t0 = clip.truth.frames[0];
  const PickPreview p = Preview(f, {t0.cx + 2, t0.cy - 2});
  ASSERT_GE(p.ball_blob, 0) << DescribePick(p);
  const Blob& ball = p.blobs[static_cast<size_t>(p.ball_blob)];
  EXPECT_NEAR(ball.centroid.x, t0.cx, 1.0);
  EXPECT_NEAR(ball.centroid.y, t0.cy, 1.0);
  EXPECT_NEAR(ball.box.width, 2 * clip.truth.radius_px, 3.0);
  // The distractor of the same hue on the floor is a second blob, not the ball.
  EXPECT_GE(p.blobs.size(), 2u) << DescribePick(p);
  EXPECT_LT(p.match_share, 0.02);
  const double nu = p.picked.color.nu(), nv = p.picked.color.nv();
  EXPECT_LT(p.cb_low, nu);
  EXPECT_GT(p.cb_high, nu);
  EXPECT_LT(p.cr_low, nv);
  EXPECT_GT(p.cr_high, nv);
  // Every matching pixel of the mask is in both histograms, and inside the thresholds.
  const int matching = cv::countNonZero(p.mask);
  EXPECT_EQ(Sum(p.cb.matching), matching);
  EXPECT_EQ(Sum(p.cr.matching), matching);
  EXPECT_GT(Sum(p.cb.all), 100 * matching);
  for (int b = 0; b < ChromaHistogram::kBins; ++b)
    if (p.cb.matching[b]) {
      EXPECT_GT(ChromaHistogram::BinCentre(b), p.cb_low - 0.05);
      EXPECT_LT(ChromaHistogram::BinCentre(b), p.cb_high + 0.05);
    }

  // A region that leaves the floor out: the distractor is gone, the ball stays.
  const cv::Rect roi(static_cast<int>(t0.cx) - 60, 0, 120, static_cast<int>(t0.cy) + 80);
  const PickPreview q = Preview(f, {t0.cx, t0.cy}, roi);
  EXPECT_EQ(q.roi, roi);
  EXPECT_EQ(q.mask.size(), roi.size());
  ASSERT_EQ(q.blobs.size(), 1u) << DescribePick(q);
  EXPECT_EQ(q.ball_blob, 0);
  EXPECT_LT(Sum(q.cb.all), Sum(p.cb.all) / 4);
}

// A camera's YUYV frame (the live camera's first frame) gives the same pick as its BGR.
TEST(ColorPick, YuyvFrameAsACameraGivesIt) {
  const SynthClipResult clip = Render("pick_yuyv", false);
  const Frame bgr = FirstFrame(clip.clip_path);
  Frame yuyv = bgr;
  yuyv.image = testing::BgrToYuyv(bgr.image);
  yuyv.format = PixelFormat::kYuyv;
  const SynthTruthFrame& t0 = clip.truth.frames[0];
  const PickPreview a = Preview(bgr, {t0.cx, t0.cy}), b = Preview(yuyv, {t0.cx, t0.cy});
  EXPECT_NEAR(a.picked.color.nu(), b.picked.color.nu(), 0.03);
  EXPECT_NEAR(a.picked.color.nv(), b.picked.color.nv(), 0.03);
  ASSERT_GE(b.ball_blob, 0) << DescribePick(b);
  EXPECT_NEAR(b.blobs[static_cast<size_t>(b.ball_blob)].centroid.x, t0.cx, 1.0);
  EXPECT_NEAR(b.blobs[static_cast<size_t>(b.ball_blob)].centroid.y, t0.cy, 1.0);
  const PickLayout l = LayoutPickView(FramePixelSize(yuyv), PickViewParams{});
  const cv::Mat view = ComposePickView(yuyv, l, &b, {}, {});
  ASSERT_EQ(view.size(), l.size);
  // The frame part is the picture, not the raw YUYV bytes: close to the BGR frame's.
  const cv::Vec3b v = view.at<cv::Vec3b>(300, 20), f = bgr.image.at<cv::Vec3b>(300, 20);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(v[c], f[c], 12) << "channel " << c;
}

// The view: the frame 1:1 (or shrunk to fit), the ball's box in bright green, clicks mapped
// back to frame pixels.
TEST(ColorPick, ViewDrawsTheFrameAndMapsClicksBack) {
  const SynthClipResult clip = Render("pick_view", false);
  const Frame f = FirstFrame(clip.clip_path);
  const SynthTruthFrame& t0 = clip.truth.frames[0];
  const PickLayout l = LayoutPickView(f.image.size(), PickViewParams{});
  EXPECT_EQ(l.scale, 1.0);
  EXPECT_EQ(l.ToFrame(l.ToView({t0.cx, t0.cy})), cv::Point2d(std::round(t0.cx), std::round(t0.cy)));
  const PickPreview p = Preview(f, {t0.cx, t0.cy});
  const cv::Mat view = ComposePickView(f, l, &p, {}, {"a line"});
  ASSERT_EQ(view.size(), l.size);
  ASSERT_GE(p.ball_blob, 0);
  const cv::Rect2f& box = p.blobs[static_cast<size_t>(p.ball_blob)].box;
  const cv::Point corner = l.ToView({box.x - 1, box.y - 1});
  EXPECT_EQ(view.at<cv::Vec3b>(corner), cv::Vec3b(0, 255, 0));
  // Away from the box, the frame is shown as it is.
  EXPECT_EQ(view.at<cv::Vec3b>(300, 20), f.image.at<cv::Vec3b>(300, 20));
  // Nothing clicked yet: frame and text only.
  EXPECT_EQ(ComposePickView(f, l, nullptr, {}, {}).size(), l.size);

  // A 1080p frame shrinks to fit; view pixels map back to within a frame pixel of the scale.
  const PickLayout big = LayoutPickView({1920, 1080}, PickViewParams{});
  EXPECT_LE(big.size.width, 1280);
  EXPECT_LE(big.size.height, 720);
  const cv::Point2d back = big.ToFrame(big.ToView({1000, 500}));
  EXPECT_NEAR(back.x, 1000, 1 / big.scale);
  EXPECT_NEAR(back.y, 500, 1 / big.scale);
}

// First frames of clips filmed by others: the yellow tennis ball in a hand, the orange
// basketball before an ochre wall (as saturated as the ball), and a white ping-pong ball (grey:
// brightness). The click positions are where the ball is in each first frame, read by eye.
TEST(ColorPick, RealFirstFrames) {
  const auto dir = testing::RealClipsDir();
  if (dir.empty()) GTEST_SKIP() << "shared real clips absent (../shared/real-clips)";

  const Frame tennis = FirstFrame(dir / "tennis_ruler_25fps.mp4");
  const PickPreview t = Preview(tennis, {202, 68});
  EXPECT_FALSE(t.picked.grey);
  ASSERT_GE(t.ball_blob, 0) << DescribePick(t);
  const Blob& tb = t.blobs[static_cast<size_t>(t.ball_blob)];
  EXPECT_NEAR(tb.centroid.x, 202, 5);
  EXPECT_NEAR(tb.centroid.y, 68, 5);
  EXPECT_GT(tb.box.width, 12);
  EXPECT_LT(tb.box.width, 30);
  EXPECT_LT(t.match_share, 0.02) << DescribePick(t);

  const Frame basket = FirstFrame(dir / "basketball_tile_ochre_24fps.mp4");
  const PickPreview b = Preview(basket, {280, 170});
  EXPECT_FALSE(b.picked.grey);
  ASSERT_GE(b.ball_blob, 0) << DescribePick(b);
  // The ball (about 236-350 x 121-235 px) without the wall: its white stripe cuts the blob.
  const cv::Rect2f& bb = b.blobs[static_cast<size_t>(b.ball_blob)].box;
  EXPECT_TRUE(cv::Rect2f(228, 113, 130, 130).contains(bb.tl()) &&
              cv::Rect2f(228, 113, 130, 130).contains(bb.br()))
      << DescribePick(b);
  EXPECT_GT(bb.width, 70);
  EXPECT_EQ(b.blobs.size(), 1u) << DescribePick(b);
  EXPECT_LT(b.match_share, 0.05) << DescribePick(b);

  const Frame white = FirstFrame(dir / "pingpong_ruler_60fps.mov");
  ASSERT_EQ(white.image.cols, 1034);
  const PickPreview w = Preview(white, {530, 85});
  EXPECT_TRUE(w.picked.grey) << DescribePick(w);
  EXPECT_EQ(w.picked.polarity, +1) << DescribePick(w);
  EXPECT_EQ(w.step, 2);  // a 1034x864 region is previewed at half resolution

  // What a drag costs on a 1080p frame (the window redraws at most once per 20 ms wait).
  const Frame hd = FirstFrame(dir / "green_ball_poster_30fps.avi");
  ASSERT_EQ(hd.image.cols, 1920);
  const PickLayout l = LayoutPickView(hd.image.size(), PickViewParams{});
  const auto start = std::chrono::steady_clock::now();
  const int n = 5;
  for (int i = 0; i < n; ++i) {
    const PickPreview p = Preview(hd, {960, 540});
    ASSERT_EQ(ComposePickView(hd, l, &p, {}, {}).size(), l.size);
  }
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count() / n;
  std::printf("1920x1080 whole-frame preview and view: %.1f ms each (view %dx%d px, scale %.2f)\n", ms,
              l.size.width, l.size.height, l.scale);
}

}  // namespace
}  // namespace bouncefit
