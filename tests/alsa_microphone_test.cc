// The ALSA microphone against a scripted source: ALSA's file plugin plays a recording with
// clicks at known times as the capture device (a "virtual mic" over the null device), so
// the whole ALSA path (open, hw params, reads, timestamps) runs without a sound card.
#include <gtest/gtest.h>
#include <time.h>

#include <cmath>
#include <fstream>

#include "capture/alsa_microphone.h"
#include "detect/impact_detector.h"
#include "synth/synth_audio.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

std::string FileMicConfig(const std::filesystem::path& raw) {
  return "pcm.scripted_mic { type file slave { pcm { type null } } file \"/dev/null\" infile \"" +
         raw.string() + "\" format \"raw\" }";
}

double MonotonicNow() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

TEST(AlsaMicrophone, ScriptedClicksAreHeardWithinAMillisecond) {
  const auto dir = testing::ScratchDir("mic");
  const std::vector<double> clicks = {0.25, 0.61, 0.9, 1.13, 1.31, 1.45};
  const std::vector<double> speeds = {3, 2.5, 2, 1.6, 1.2, 0.9};
  SynthAudioConfig sc;
  sc.sample_rate = 48000;
  sc.hum = true;
  const std::vector<float> sound = RenderSynthAudio(sc, 1.6, clicks, speeds);
  const auto raw = dir / "mic.raw";
  {
    std::ofstream f(raw, std::ios::binary);
    for (float s : sound) {
      const int16_t v = static_cast<int16_t>(std::lround(s * 32767));
      f.write(reinterpret_cast<const char*>(&v), sizeof v);
    }
  }
  AlsaMicrophoneConfig mc;
  mc.device = "scripted_mic";
  mc.sample_rate = 48000;
  mc.config_text = FileMicConfig(raw);
  const double opened = MonotonicNow();
  AlsaMicrophone mic(mc);
  ASSERT_EQ(mic.sample_rate(), 48000);
  ImpactDetector detector({}, mic.sample_rate());
  std::vector<AudioImpact> heard;
  AudioChunk chunk;
  double first_t0 = NAN;
  size_t samples = 0;
  while (samples < sound.size() && mic.Next(&chunk)) {
    if (std::isnan(first_t0)) first_t0 = chunk.t0_s;
    for (const auto& i : detector.Push(chunk.t0_s, chunk.samples.data(), chunk.samples.size()))
      heard.push_back(i);
    samples += chunk.samples.size();
  }
  for (const auto& i : detector.Finish()) heard.push_back(i);
  EXPECT_NEAR(first_t0, opened, 1.0);  // CLOCK_MONOTONIC, the camera's clock
  ASSERT_EQ(heard.size(), clicks.size());
  for (size_t k = 0; k < clicks.size(); ++k)
    EXPECT_NEAR(heard[k].t_s - first_t0, clicks[k], 0.001) << "click " << k;
  EXPECT_EQ(mic.overruns(), 0);
}

TEST(AlsaMicrophone, MissingDeviceIsAOneLineError) {
  AlsaMicrophoneConfig mc;
  mc.device = "hw:97,0";
  try {
    AlsaMicrophone mic(mc);
    FAIL() << "opened a device that does not exist";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("hw:97,0"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace bouncefit
