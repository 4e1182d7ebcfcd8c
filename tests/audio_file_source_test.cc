// A clip's sound track decoded to mono in the video's clock: synth clips with clicks at known
// impact times (and a known offset), the shared real clips, and clear errors.
#include <gtest/gtest.h>

#include <cmath>

#include "detect/impact_detector.h"
#include "replay/audio_file_source.h"
#include "synth/synth_clip.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

SynthClipResult SmallClipWithSound(const std::filesystem::path& dir, const std::string& name,
                                   double offset_s, int rate) {
  SynthClipConfig c;
  c.fps = 30;
  c.width = 160;
  c.height = 120;
  c.duration_s = 3;
  c.hold_s = 0.2;
  c.out = dir / name;
  SynthAudioConfig a;
  a.offset_s = offset_s;
  a.sample_rate = rate;
  c.sound = a;
  return RenderSynthClip(c);
}

TEST(AudioFileSource, SynthClicksComeBackAtTheirTimesInTheVideoClock) {
  const auto dir = testing::ScratchDir("synth");
  for (const auto& [name, offset, rate] :
       {std::tuple{"a.avi", 0.0, 44100}, std::tuple{"b.avi", 0.03, 48000},
        std::tuple{"c.avi", -0.02, 22050}}) {
    SCOPED_TRACE(name);
    const SynthClipResult r = SmallClipWithSound(dir, name, offset, rate);
    ASSERT_TRUE(r.truth.has_sound);
    ASSERT_GE(r.truth.impact_times_s.size(), 3u);
    AudioFileSource source(r.clip_path.string());
    ASSERT_TRUE(source.has_audio());
    EXPECT_EQ(source.sample_rate(), rate);
    const AudioChunk track = ReadAudioTrack(r.clip_path.string());
    EXPECT_NEAR(track.t0_s, 0.0, 1e-6);
    EXPECT_NEAR(static_cast<double>(track.samples.size()) / rate, 3.0, 0.05);
    const auto found = DetectImpacts(track.samples, track.sample_rate, track.t0_s);
    std::vector<double> heard;  // clicks the offset does not push past the end
    for (double t : r.truth.impact_times_s)
      if (t + offset < 3.0 - 0.01) heard.push_back(t + offset);
    ASSERT_EQ(found.size(), heard.size());
    for (size_t k = 0; k < found.size(); ++k)
      EXPECT_NEAR(found[k].t_s, heard[k], 0.0003) << "impact " << k;
  }
}

TEST(AudioFileSource, ClipWithoutSoundAndMissingFile) {
  const auto dir = testing::ScratchDir("silent");
  SynthClipConfig c;
  c.fps = 30, c.width = 64, c.height = 48, c.duration_s = 0.5;
  c.out = dir / "silent.avi";
  RenderSynthClip(c);
  AudioFileSource silent(c.out.string());
  EXPECT_FALSE(silent.has_audio());
  EXPECT_EQ(ReadAudioTrack(c.out.string()).sample_rate, 0);
  EXPECT_EQ(silent.Describe(), "no sound track");
  try {
    AudioFileSource missing((dir / "nope.mp4").string());
    FAIL() << "no error for a missing file";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("nope.mp4"), std::string::npos) << e.what();
  }
}

TEST(AudioFileSource, DecodesEveryRealClipsTrack) {
  const auto dir = testing::RealClipsDir();
  if (dir.empty()) GTEST_SKIP() << "shared real clips not found";
  int clips = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const auto ext = entry.path().extension();
    if (ext != ".mp4" && ext != ".mov" && ext != ".avi") continue;
    SCOPED_TRACE(entry.path().filename().string());
    const AudioChunk track = ReadAudioTrack(entry.path().string());
    EXPECT_TRUE(track.sample_rate == 44100 || track.sample_rate == 48000);
    const double seconds = static_cast<double>(track.samples.size()) / track.sample_rate;
    EXPECT_GT(seconds, 1.5);
    EXPECT_LT(std::abs(track.t0_s), 0.05);
    ++clips;
  }
  EXPECT_GE(clips, 1);
}

}  // namespace
}  // namespace bouncefit
