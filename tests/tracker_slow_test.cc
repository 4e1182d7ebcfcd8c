// The tracker on real footage (../shared/real-clips, skipped when absent) and on longer synth
// clips. Real clips have no truth: the checks are that the ball is found through the drop
// and that its track has the shape of bounces.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <vector>

#include "tests/test_support.h"
#include "tests/tracker_test_util.h"

namespace bouncefit {
namespace {

using testing::TrackClip;
using testing::TrackScore;

struct Bounces {
  int first = -1, last = -1;  // first and last frame with a ball
  int found_between = 0;      // frames found between them
  int impacts = 0;            // local maxima of image y (lowest points), well separated
};

// Impacts: found samples whose y is the largest (lowest in the image) among the +-w found
// samples around them, with the ball at least `rise` px higher on both sides in that span.
Bounces AnalyseTrack(const std::vector<BallObservation>& obs, int w, double rise) {
  Bounces b;
  std::vector<double> y;
  for (size_t i = 0; i < obs.size(); ++i)
    if (obs[i].found) {
      if (b.first < 0) b.first = static_cast<int>(i);
      b.last = static_cast<int>(i);
      ++b.found_between;
      y.push_back(obs[i].cy);
    }
  const int n = static_cast<int>(y.size());
  for (int i = w; i < n - w; ++i) {
    bool is_max = true;
    double min_before = y[static_cast<size_t>(i)], min_after = min_before;
    for (int k = i - w; k <= i + w; ++k) {
      const double v = y[static_cast<size_t>(k)];
      if (v > y[static_cast<size_t>(i)] || (v == y[static_cast<size_t>(i)] && k < i)) is_max = false;
      if (k < i) min_before = std::min(min_before, v);
      if (k > i) min_after = std::min(min_after, v);
    }
    if (is_max && y[static_cast<size_t>(i)] - min_before >= rise &&
        y[static_cast<size_t>(i)] - min_after >= rise)
      ++b.impacts;
  }
  return b;
}

void PrintTrack(const std::string& name, const TrackScore& s, const Bounces& b) {
  std::printf("%s: %zu frames, ball from frame %d to %d, found on %d of those %d frames, "
              "%d impacts\n  %s\n",
              name.c_str(), s.obs.size(), b.first, b.last, b.found_between,
              b.last - b.first + 1, b.impacts, s.describe.c_str());
}

std::filesystem::path RealClip(const std::string& name) {
  const auto dir = testing::RealClipsDir();
  if (dir.empty() || !std::filesystem::exists(dir / name)) return {};
  return dir / name;
}

TEST(TrackerRealClips, GreenBallOnPoster) {
  const auto clip = RealClip("green_ball_poster_30fps.avi");
  if (clip.empty()) GTEST_SKIP() << "real clips not found (../shared/real-clips)";
  const TrackScore s = TrackClip(clip, TrackerConfig{}, nullptr);
  const Bounces b = AnalyseTrack(s.obs, 3, 20);
  PrintTrack("green ball", s, b);
  // It chose green (Cr below grey), not the hand or the warm poster.
  EXPECT_LT(s.color_nv, -0.2) << s.describe;
  // Found on most frames from release on; the 30 fps smear of the first fall loses a few.
  EXPECT_GE(b.found_between, 0.85 * (b.last - b.first + 1));
  // Four bounces are visible; at least three impacts stand out of the track.
  EXPECT_GE(b.impacts, 3);
}

TEST(TrackerRealClips, TennisBallBesideRuler) {
  const auto clip = RealClip("tennis_ruler_25fps.mp4");
  if (clip.empty()) GTEST_SKIP() << "real clips not found (../shared/real-clips)";
  const TrackScore s = TrackClip(clip, TrackerConfig{}, nullptr);
  const Bounces b = AnalyseTrack(s.obs, 2, 5);
  PrintTrack("tennis ball", s, b);
  EXPECT_GE(b.found_between, 0.9 * (b.last - b.first + 1));
  EXPECT_GE(b.impacts, 3);
}

TEST(TrackerRealClips, WhitePingPongBall) {
  const auto clip = RealClip("pingpong_ruler_60fps.mov");
  if (clip.empty()) GTEST_SKIP() << "real clips not found (../shared/real-clips)";
  const TrackScore s = TrackClip(clip, TrackerConfig{}, nullptr);
  const Bounces b = AnalyseTrack(s.obs, 3, 10);
  PrintTrack("white ping-pong ball", s, b);
  // A white ball on a light wall has no colour to follow: the automatic choice switches to
  // its brightness by itself, and follows it (not the orange worktop or the green ruler)
  // through its bounces.
  EXPECT_NE(s.describe.find("brightness"), std::string::npos) << s.describe;
  EXPECT_GE(b.found_between, 0.8 * (b.last - b.first + 1));
  EXPECT_GE(b.impacts, 4);
}

// Clips whose ball a choice by saturation alone (the saturated blob that moves) never finds or
// loses to the background: each must give a track with the bounces a person sees.
struct RealTrackCase {
  const char* clip;
  int impacts_at_least;  // lowest points that stand out of the track (README count, minus the small ones)
  double rise_px;        // how far the ball must rise on both sides of one
  const char* mode;      // "colour" or "brightness": what the choice must say
};

class TrackerRealClipChoice : public ::testing::TestWithParam<RealTrackCase> {};

TEST_P(TrackerRealClipChoice, FindsTheBallAndFollowsItsBounces) {
  const RealTrackCase& c = GetParam();
  const auto clip = RealClip(c.clip);
  if (clip.empty()) GTEST_SKIP() << "real clips not found (../shared/real-clips)";
  const TrackScore s = TrackClip(clip, TrackerConfig{}, nullptr);
  const Bounces b = AnalyseTrack(s.obs, 2, c.rise_px);
  PrintTrack(c.clip, s, b);
  EXPECT_NE(s.describe.find(std::string(c.mode) == "colour" ? "its colour" : "brightness"),
            std::string::npos) << s.describe;
  EXPECT_NE(s.describe.find("ballistic"), std::string::npos) << s.describe;
  EXPECT_GE(b.found_between, 0.8 * (b.last - b.first + 1));
  EXPECT_GE(b.impacts, c.impacts_at_least);
}

INSTANTIATE_TEST_SUITE_P(
    SharedClips, TrackerRealClipChoice,
    ::testing::Values(
        // Orange basketball already bouncing before an ochre wall (saturated background).
        RealTrackCase{"basketball_tile_ochre_24fps.mp4", 2, 8, "colour"},
        // White ping-pong ball before a black cloth, file stored rotated.
        RealTrackCase{"pingpong_white_blackcloth_24fps.mov", 3, 8, "brightness"},
        // Yellow tennis ball before a dark wooden door: its hue is the wood's, its brightness
        // far above it (113 luma against 0.23 chroma/luma): followed by its brightness.
        RealTrackCase{"tennis_door_wood_20fps.mp4", 2, 8, "brightness"},
        // Red ball before a white wall, phone slow motion stored rotated.
        RealTrackCase{"red_ball_ceiling_drop_slomo120_30fps.mp4", 1, 20, "colour"}),
    [](const ::testing::TestParamInfo<RealTrackCase>& i) {
      std::string n = i.param.clip;
      return n.substr(0, n.find('_', n.find('_') + 1));
    });

// The full default synth drop (5 s: release, bounces, the ball settling) for every preset,
// noise 3, roll 1 deg, MJPEG; with and without a similar-hue distractor. These are the
// figures in docs/ACCURACY.md.
class TrackerFullDrop : public ::testing::TestWithParam<std::tuple<std::string, bool>> {};

TEST_P(TrackerFullDrop, MeetsTheAccuracyTargets) {
  const auto& [ball, distractor] = GetParam();
  SynthClipConfig c;
  c.ball = *FindBallPreset(ball);
  c.noise_sigma = 3;
  c.roll_deg = 1;
  c.distractor = distractor;
  c.out = testing::ScratchDir("tracker_full_" + ball + (distractor ? "_distractor" : "")) /
          (ball + ".avi");
  const SynthClipResult clip = RenderSynthClip(c);
  const TrackScore s = TrackClip(clip.clip_path,
                                 testing::ConfigForColor(clip.truth.ball_color_bgr, ball),
                                 &clip.truth);
  std::printf("%-9s%s frames %zu in view %d lost %d wrong %d | centre error rms %.3f p99 %.3f "
              "max %.3f px\n",
              ball.c_str(), distractor ? "+distr" : "      ", s.obs.size(), s.in_view, s.lost,
              s.wrong, s.rms, s.p99, s.max);
  EXPECT_EQ(s.lost, 0);
  EXPECT_EQ(s.wrong, 0);
  EXPECT_LE(s.rms, 0.3);
  EXPECT_LE(s.p99, 1.0);
}

INSTANTIATE_TEST_SUITE_P(
    AllPresets, TrackerFullDrop,
    ::testing::Combine(::testing::Values("pingpong", "wiffle", "softball", "airball"),
                       ::testing::Bool()));

}  // namespace
}  // namespace bouncefit
