// The live sound side of `bouncefit run --device ... --audio-device ...` (pipeline/sound_listener) against
// a scripted microphone: ALSA's file plugin plays clicks at known times as the capture
// device, the frame loop's clock is CLOCK_MONOTONIC (as V4L2 stamps frames), and each click
// comes out as an IMPACT message in the video's clock while the stream runs (a wall-clock
// bound: realtime).
#include <gtest/gtest.h>
#include <time.h>

#include <chrono>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <thread>

#include "pipeline/sound_fusion.h"
#include "pipeline/sound_listener.h"
#include "model/ball_preset.h"
#include "synth/synth_audio.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

int64_t MonotonicUtime() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return int64_t(ts.tv_sec) * 1000000 + ts.tv_nsec / 1000;
}

TEST(SoundListenerMicrophone, ScriptedClicksArePublishedInTheVideoClockWithinAMillisecond) {
  const auto dir = testing::ScratchDir("run_mic");
  const std::vector<double> clicks = {0.3, 0.66, 0.95, 1.18, 1.36, 1.5};
  const std::vector<double> speeds = {3, 2.5, 2, 1.6, 1.2, 0.9};
  SynthAudioConfig sc;
  sc.sample_rate = 44100;
  sc.hum = true;
  const std::vector<float> recording = RenderSynthAudio(sc, 1.7, clicks, speeds);
  const auto raw = dir / "mic.raw";
  {
    std::ofstream f(raw, std::ios::binary);
    for (float s : recording) {
      const int16_t v = static_cast<int16_t>(std::lround(s * 32767));
      f.write(reinterpret_cast<const char*>(&v), sizeof v);
    }
  }
  AlsaMicrophoneConfig mc;
  mc.device = "scripted_mic";
  mc.sample_rate = 44100;
  mc.pace = true;  // as a sound card would
  mc.config_text = "pcm.scripted_mic { type file slave { pcm { type null } } file \"/dev/null\" "
                   "infile \"" + raw.string() + "\" format \"raw\" }";
  // The first frame arrives as the microphone opens.
  const int64_t t0_utime = MonotonicUtime();
  SoundListener sound(mc);
  ASSERT_TRUE(sound.enabled());
  EXPECT_NE(sound.Describe().find("44100 Hz"), std::string::npos) << sound.Describe();

  // The frame loop: 30 frames a second for as long as the recording lasts.
  std::vector<impact_t> published;
  std::vector<double> published_at_s;  // video clock when each message came out
  const auto wall0 = std::chrono::steady_clock::now();
  for (int frame = 0; frame < 75 && published.size() < clicks.size(); ++frame) {
    std::this_thread::sleep_until(wall0 + std::chrono::microseconds(frame * 33333));
    const int64_t now = MonotonicUtime();
    for (const auto& m : sound.AdvanceTo((now - t0_utime) * 1e-6, t0_utime)) {
      published.push_back(m);
      published_at_s.push_back((now - t0_utime) * 1e-6);
    }
  }
  for (const auto& m : sound.Finish(t0_utime)) {
    published.push_back(m);
    published_at_s.push_back((MonotonicUtime() - t0_utime) * 1e-6);
  }
  ASSERT_TRUE(std::isfinite(sound.first_sample_t_s()));
  const double first = sound.first_sample_t_s();  // the recording's start, video clock
  EXPECT_NEAR(first, 0, 1.0);                         // the same clock as the frames
  ASSERT_EQ(published.size(), clicks.size());
  double worst = 0;
  for (size_t k = 0; k < clicks.size(); ++k) {
    worst = std::max(worst, std::abs((published[k].utime - t0_utime) * 1e-6 - first - clicks[k]));
    const impact_t& m = published[k];
    EXPECT_EQ(m.source, "audio");
    EXPECT_EQ(m.index, static_cast<int>(k));
    EXPECT_NEAR((m.utime - t0_utime) * 1e-6, first + clicks[k], 0.001) << "click " << k;
    // Out while the stream runs, a few frames after the click (not at the end).
    EXPECT_LT(published_at_s[k], first + clicks[k] + 0.25) << "click " << k;
  }
  EXPECT_EQ(sound.overruns(), 0);
  std::printf("clicks heard live: worst time error %.3f ms (video clock)\n", worst * 1e3);
}

TEST(SoundListenerMicrophone, MissingDeviceIsAOneLineError) {
  AlsaMicrophoneConfig mc;
  mc.device = "hw:97,0";
  try {
    SoundListener sound(mc);
    FAIL() << "opened a microphone that does not exist";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("hw:97,0"), std::string::npos) << e.what();
  }
}

// The picture may revise an impact it sent (two frames at the floor first taken for two
// impacts, then merged): the revision goes out with the index of the impact it replaces.
TEST(SoundFusionSeen, AnImpactTheDetectorRevisesKeepsItsMessageIndex) {
  SoundFusion sound(ResolveBallPreset("pingpong"));
  const impact_t first = sound.Seen(1.0, 0, {0, 1});
  const impact_t second = sound.Seen(1.4, 0, {0, 2});
  const impact_t revised = sound.Seen(1.03, 0, {0, 1});
  EXPECT_NE(first.index, second.index);
  EXPECT_EQ(revised.index, first.index);
  EXPECT_EQ(revised.utime, 1030000);
  EXPECT_EQ(revised.source, "video");
  const impact_t next_drop = sound.Seen(3.0, 0, {1, 1});  // the same impact number, another drop
  EXPECT_NE(next_drop.index, first.index);
  EXPECT_NE(next_drop.index, second.index);
}

}  // namespace
}  // namespace bouncefit
