// A video file as a fake camera: container times (not nominal fps), looping, clear errors.
#include <gtest/gtest.h>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>
#include <utility>
#include <vector>

#include "replay/video_file_source.h"
#include "tests/test_support.h"

namespace bouncefit {
namespace {

// A small MJPEG .avi whose frame i shows a white bar at row 2*i.
std::string WriteClip(const std::filesystem::path& dir, int frames, double fps) {
  const std::string path = (dir / "clip.avi").string();
  cv::VideoWriter w(path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), fps, cv::Size(160, 120));
  EXPECT_TRUE(w.isOpened());
  for (int i = 0; i < frames; ++i) {
    cv::Mat img(120, 160, CV_8UC3, cv::Scalar(40, 40, 40));
    cv::rectangle(img, cv::Rect(0, 2 * i, 160, 2), cv::Scalar(255, 255, 255), cv::FILLED);
    w.write(img);
  }
  return path;
}

int BarRow(const cv::Mat& bgr) {
  cv::Mat grey;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  cv::Mat col;
  cv::reduce(grey, col, 1, cv::REDUCE_AVG, CV_32F);
  cv::Point max;
  cv::minMaxLoc(col, nullptr, nullptr, nullptr, &max);
  return max.y;
}

std::string ErrorOf(const std::string& path) {
  try {
    VideoFileSource s({path, false});
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(VideoFileSource, ReadsEveryFrameInOrderWithItsTime) {
  const auto dir = testing::ScratchDir("video_file_source_order");
  VideoFileSource source({WriteClip(dir, 40, 120), false});
  const SourceInfo info = source.Info();
  EXPECT_EQ(info.width, 160);
  EXPECT_EQ(info.height, 120);
  EXPECT_DOUBLE_EQ(info.nominal_fps, 120);
  EXPECT_EQ(info.frame_count, 40);
  EXPECT_EQ(info.description, "file clip.avi (MJPG 160x120)");
  int n = 0;
  while (auto f = source.Next()) {
    EXPECT_EQ(f->index, n);
    EXPECT_EQ(f->sequence, n);
    EXPECT_EQ(f->format, PixelFormat::kBgr24);
    EXPECT_EQ(f->image.type(), CV_8UC3);
    EXPECT_NEAR(double(f->utime), n * 1e6 / 120, 1.0) << n;
    EXPECT_NEAR(BarRow(f->image), 2 * n, 1) << n;
    ++n;
  }
  EXPECT_EQ(n, 40);
  EXPECT_FALSE(source.ended_short());
  EXPECT_FALSE(source.Next().has_value());
  EXPECT_EQ(source.dropped_frames(), 0);
}

TEST(VideoFileSource, UsesContainerTimesWhereTheyDifferFromTheNominalRate) {
  // 60 frames at 30 fps with a 0.5 s pause after frame 29, as a variable-rate camera would
  // produce: the times must show the pause, which the nominal rate knows nothing of.
  const auto dir = testing::ScratchDir("video_file_source_vfr");
  const std::string path = (dir / "vfr.mp4").string();
  std::string out;
  const int rc = testing::RunCommand(
      "ffmpeg -v error -y -f lavfi -i testsrc=size=160x120:rate=30:duration=2 -vf "
      "\"setpts='(N/30+if(gte(N\\,30)\\,0.5\\,0))/TB'\" -fps_mode vfr -c:v mpeg4 -q:v 3 '" +
          path + "'",
      &out);
  if (rc != 0) GTEST_SKIP() << "ffmpeg cannot write the test clip: " << out;
  VideoFileSource source({path, false});
  std::vector<int64_t> t;
  while (auto f = source.Next()) t.push_back(f->utime);
  ASSERT_EQ(t.size(), 60u);
  EXPECT_EQ(t[0], 0);
  EXPECT_NEAR(t[29], 29e6 / 30, 1000);
  EXPECT_NEAR(t[30], 30e6 / 30 + 0.5e6, 1000);  // the pause
  EXPECT_NEAR(t[59], 59e6 / 30 + 0.5e6, 1000);
  EXPECT_EQ(source.repaired_times(), 0);
}

TEST(VideoFileSource, RealVariableRateClipKeepsItsContainerTimes) {
  const auto dir = testing::RealClipsDir();
  if (dir.empty()) GTEST_SKIP() << "shared real clips not found (../shared/real-clips)";
  // ffprobe: 188 frames; the second at 15.000 ms (nominal 60 fps would say 16.667), the last
  // at 3115.000 ms (nominal: 3116.667). The last two pictures come out of the H.264 decoder
  // only when it is flushed at the end: they keep their own presentation times too (OpenCV's
  // reader gave them none, and they had to be repaired).
  // Every picture, the ones it repeats included (see PicturesTheFileRepeatsComeOutOnce).
  VideoFileSource source({(dir / "pingpong_ruler_60fps.mov").string(), false, false});
  std::vector<int64_t> t;
  while (auto f = source.Next()) t.push_back(f->utime);
  ASSERT_EQ(t.size(), 188u);
  EXPECT_NEAR(t[1], 15000, 50);
  EXPECT_NEAR(t[2], 31667, 50);
  EXPECT_NEAR(t[186], 3098333, 50);
  EXPECT_NEAR(t.back(), 3115000, 50);
  EXPECT_EQ(source.repaired_times(), 0);
}

// The first frame as ffmpeg's own player logic shows it (it honours the rotation tag).
cv::Mat FfmpegFirstFrame(const std::string& path, const std::filesystem::path& dir) {
  const std::string png = (dir / "ffmpeg_first.png").string();
  std::string out;
  if (testing::RunCommand("ffmpeg -v error -y -i '" + path + "' -frames:v 1 '" + png + "'", &out) != 0)
    return {};
  return cv::imread(png);
}

double MeanAbsDiff(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size()) return 1e9;
  return cv::mean(cv::abs(cv::Mat_<cv::Vec3f>(a) - cv::Mat_<cv::Vec3f>(b)))[0];
}

// A copy of `plain` (its packets as they are) whose rotation tag asks a player to turn it `tag`
// degrees clockwise, as phones write it; empty (ffmpeg's words in *out) if it cannot be made.
std::string TaggedToTurn(const std::string& plain, int tag, const std::filesystem::path& dir, std::string* out) {
  const std::string turned = (dir / ("turned" + std::to_string(tag) + ".mov")).string();
  if (testing::RunCommand("ffmpeg -v error -y -i '" + plain + "' -c copy -metadata:s:v:0 rotate=" +
                              std::to_string(tag) + " '" + turned + "'", out) != 0)
    return {};
  return turned;
}

TEST(VideoFileSource, FileStoredTurnedComesOutUprightAsAPlayerShowsIt) {
  // An asymmetric picture stored with a rotation tag, as phones write it: every frame must
  // match what ffmpeg shows (turned by the tag), not the stored pixels, and not OpenCV 4.6's
  // own automatic turn, which goes the wrong way.
  const auto dir = testing::ScratchDir("video_file_source_rotated");
  const std::string plain = (dir / "plain.mp4").string();
  std::string out;
  if (testing::RunCommand("ffmpeg -v error -y -f lavfi -i testsrc=size=160x120:rate=30:duration=0.5 "
                          "-c:v mpeg4 -q:v 2 '" + plain + "'", &out) != 0)
    GTEST_SKIP() << "ffmpeg cannot write the test clip: " << out;
  for (int tag : {90, 180, 270}) {
    const std::string turned = TaggedToTurn(plain, tag, dir, &out);
    ASSERT_FALSE(turned.empty()) << out;
    const cv::Mat expect = FfmpegFirstFrame(turned, dir);
    ASSERT_FALSE(expect.empty());
    VideoFileSource source({turned, false});
    const auto first = source.Next();
    ASSERT_TRUE(first);
    EXPECT_EQ(source.Info().width, expect.cols) << tag;
    EXPECT_EQ(source.Info().height, expect.rows) << tag;
    EXPECT_LT(MeanAbsDiff(first->image, expect), 3.0) << "tag " << tag;
    EXPECT_NE(source.rotation_deg(), 0);
    EXPECT_NE(source.Info().description.find("rotated"), std::string::npos) << source.Info().description;
    int n = 1;
    while (auto f = source.Next()) EXPECT_EQ(f->image.size(), expect.size()) << n++;
  }
}

// The decoder's own luma, as a consumer of brightness reads it instead of converting the
// picture back: upright with the picture, in the range the file says, and still there after
// the source (and the decoder with it) is gone.
double MeanAbsDiffToGrey(const Frame& f) {
  // Turned into memory of its own: turning into a header of f.luma would write the
  // decoder's picture (180 keeps the size), which the next pictures are decoded from.
  cv::Mat grey, y, luma;
  cv::cvtColor(f.image, grey, cv::COLOR_BGR2GRAY);
  if (f.luma_turn_cw_deg == 0) luma = f.luma;
  if (f.luma_turn_cw_deg == 90) cv::rotate(f.luma, luma, cv::ROTATE_90_CLOCKWISE);
  if (f.luma_turn_cw_deg == 180) cv::rotate(f.luma, luma, cv::ROTATE_180);
  if (f.luma_turn_cw_deg == 270) cv::rotate(f.luma, luma, cv::ROTATE_90_COUNTERCLOCKWISE);
  if (luma.size() != grey.size()) return 255;
  luma.convertTo(y, CV_32F, f.luma_limited_range ? 255.0 / 219.0 : 1.0,
                   f.luma_limited_range ? -16.0 * 255.0 / 219.0 : 0.0);
  grey.convertTo(grey, CV_32F);
  return cv::mean(cv::abs(y - grey))[0];
}

TEST(VideoFileSource, FramesCarryTheDecodersOwnLumaUprightAndKeptAlive) {
  const auto dir = testing::ScratchDir("video_file_source_luma");
  const std::string plain = (dir / "plain.mp4").string();
  std::string out;
  if (testing::RunCommand("ffmpeg -v error -y -f lavfi -i testsrc=size=160x120:rate=30:duration=0.5 "
                          "-c:v mpeg4 -q:v 2 -pix_fmt yuv420p '" + plain + "'", &out) != 0)
    GTEST_SKIP() << "ffmpeg cannot write the test clip: " << out;
  for (int tag : {0, 90, 180, 270}) {
    const std::string path = tag == 0 ? plain : TaggedToTurn(plain, tag, dir, &out);
    ASSERT_FALSE(path.empty()) << out;
    std::vector<Frame> kept;
    std::vector<cv::Mat> copies;
    {
      VideoFileSource source({path, false});
      while (auto f = source.Next()) {
        ASSERT_EQ(f->luma.type(), CV_8U) << tag;
        EXPECT_EQ(f->luma_turn_cw_deg, source.rotation_deg());
        EXPECT_EQ(f->luma_turn_cw_deg != 0, tag != 0);
        EXPECT_TRUE(f->luma_limited_range) << "mpeg4 stores 16-235";
        EXPECT_LT(MeanAbsDiffToGrey(*f), 2.0) << "tag " << tag << ", frame " << f->index;
        kept.push_back(*f);
        copies.push_back(f->luma.clone());
      }
    }
    ASSERT_EQ(kept.size(), 15u) << tag;
    for (size_t i = 0; i < kept.size(); ++i)
      EXPECT_EQ(cv::norm(kept[i].luma, copies[i], cv::NORM_INF), 0) << "tag " << tag << ", frame " << i;
  }
  // An MJPEG file keeps its luma in 0-255.
  VideoFileSource mjpeg({WriteClip(dir, 5, 30), false});
  const auto f = mjpeg.Next();
  ASSERT_TRUE(f);
  ASSERT_FALSE(f->luma.empty());
  EXPECT_FALSE(f->luma_limited_range);
  EXPECT_LT(MeanAbsDiffToGrey(*f), 2.0);
}

TEST(VideoFileSource, RealPhoneClipsStoredTurnedComeOutUpright) {
  const auto dir = testing::RealClipsDir();
  if (dir.empty()) GTEST_SKIP() << "shared real clips not found (../shared/real-clips)";
  const auto scratch = testing::ScratchDir("video_file_source_real_rotated");
  for (const char* name : {"pingpong_ruler_60fps.mov", "pingpong_white_blackcloth_24fps.mov"}) {
    const std::string path = (dir / name).string();
    const cv::Mat expect = FfmpegFirstFrame(path, scratch);
    ASSERT_FALSE(expect.empty()) << name;
    VideoFileSource source({path, false});
    const auto first = source.Next();
    ASSERT_TRUE(first);
    EXPECT_LT(MeanAbsDiff(first->image, expect), 3.0) << name;
  }
}

// Pictures written twice (a 30 fps scene on a 60 fps timeline) come out once each, at the time
// each was first shown, numbered as in the file; a scene that stands still after moving (a
// ball at rest, the camera's noise alone) is not taken for repeats.
TEST(VideoFileSource, PicturesTheFileRepeatsComeOutOnce) {
  const auto dir = testing::ScratchDir("video_file_source_repeats");
  const std::string path = (dir / "doubled.avi").string();
  {
    cv::VideoWriter w(path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 60, cv::Size(160, 120));
    ASSERT_TRUE(w.isOpened());
    for (int i = 0; i < 20; ++i) {
      cv::Mat img(120, 160, CV_8UC3, cv::Scalar(40, 40, 40));
      cv::circle(img, cv::Point(30 + 3 * i, 10 + 5 * i), 8, cv::Scalar(255, 255, 255), cv::FILLED);
      w.write(img);
      w.write(img);
    }
  }
  VideoFileSource source({path, false});
  int n = 0;
  while (auto f = source.Next()) {
    // The first two repeats are delivered while the pattern is not yet established.
    if (f->index >= 6) {
      EXPECT_EQ(f->index % 2, 0) << n;
      EXPECT_NEAR(BarRow(f->image), 10 + 5 * f->index / 2, 1) << f->index;
      EXPECT_NEAR(f->utime, f->index * 1e6 / 60, 1000) << f->index;
    }
    ++n;
  }
  EXPECT_GE(source.repeated_frames(), 17);
  EXPECT_EQ(n + source.repeated_frames(), 40);

  const std::string still = (dir / "still.avi").string();
  {
    cv::VideoWriter w(still, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 60, cv::Size(160, 120));
    cv::RNG rng(7);
    for (int i = 0; i < 40; ++i) {
      cv::Mat img(120, 160, CV_8UC3, cv::Scalar(90, 90, 90));
      const int at = 10 + 5 * std::min(i, 10);  // moves for 10 frames, then stays
      cv::circle(img, cv::Point(at, at), 8, cv::Scalar(255, 255, 255), cv::FILLED);
      cv::Mat noisy(img.size(), CV_16SC3), noise(img.size(), CV_16SC3);
      img.convertTo(noisy, CV_16SC3);
      rng.fill(noise, cv::RNG::NORMAL, 0, 2);
      cv::Mat(noisy + noise).convertTo(img, CV_8UC3);
      w.write(img);
    }
  }
  VideoFileSource quiet({still, false});
  int m = 0;
  while (quiet.Next()) ++m;
  EXPECT_EQ(m, 40);
  EXPECT_EQ(quiet.repeated_frames(), 0);
}

TEST(VideoFileSource, LoopsWithTimesThatKeepIncreasing) {
  const auto dir = testing::ScratchDir("video_file_source_loop");
  VideoFileSource source({WriteClip(dir, 10, 100), true});
  std::vector<Frame> frames;
  for (int i = 0; i < 35; ++i) {
    auto f = source.Next();
    ASSERT_TRUE(f) << i;
    frames.push_back(*f);
  }
  EXPECT_EQ(source.loops_done(), 3);
  for (int i = 0; i < 35; ++i) {
    EXPECT_EQ(frames[i].index, i);
    EXPECT_NEAR(double(frames[i].utime), i * 10000.0, 2.0) << i;  // 100 fps, no gap at the seam
    EXPECT_NEAR(BarRow(frames[i].image), 2 * (i % 10), 1) << i;
  }
}

TEST(VideoFileSource, MissingCorruptOrEmptyFilesAreOneLineErrors) {
  const auto dir = testing::ScratchDir("video_file_source_errors");
  EXPECT_EQ(ErrorOf((dir / "nope.avi").string()),
            "cannot open video '" + (dir / "nope.avi").string() + "': no such file");
  EXPECT_EQ(ErrorOf(dir.string()), "cannot open video '" + dir.string() + "': it is a directory");

  const auto garbage = (dir / "garbage.avi").string();
  {
    std::ofstream f(garbage, std::ios::binary);
    for (int i = 0; i < 100000; ++i) f.put(static_cast<char>((i * 7919) % 251));
  }
  const std::string e = ErrorOf(garbage);
  EXPECT_FALSE(e.empty());
  EXPECT_EQ(e.find('\n'), std::string::npos);
  EXPECT_NE(e.find(garbage), std::string::npos) << e;

  // A real clip cut to its first 3 kB: the header is there, the frames are not.
  const std::string good = WriteClip(dir, 20, 120);
  const auto cut = (dir / "cut.avi").string();
  {
    std::ifstream in(good, std::ios::binary);
    std::string bytes(3000, '\0');
    in.read(bytes.data(), 3000);
    std::ofstream(cut, std::ios::binary).write(bytes.data(), in.gcount());
  }
  const std::string e2 = ErrorOf(cut);
  EXPECT_FALSE(e2.empty()) << "a clip with no frame left must be refused";
  EXPECT_EQ(e2.find('\n'), std::string::npos);
}

// A copy of `path` with only its first `percent` of bytes (a download or a copy cut short).
std::string CutCopy(const std::string& path, const std::filesystem::path& out, int percent) {
  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), {});
  std::ofstream(out, std::ios::binary)
      .write(bytes.data(), static_cast<std::streamsize>(bytes.size() * static_cast<size_t>(percent) / 100));
  return out.string();
}

TEST(VideoFileSource, TruncatedClipGivesTheFramesThatAreThere) {
  const auto dir = testing::ScratchDir("video_file_source_truncated");
  const std::string cut = CutCopy(WriteClip(dir, 60, 120), dir / "half.avi", 50);
  VideoFileSource source({cut, false});
  int n = 0;
  while (auto f = source.Next()) {
    EXPECT_NEAR(BarRow(f->image), 2 * n, 1);
    ++n;
  }
  EXPECT_GT(n, 20);
  EXPECT_LT(n, 40);
  EXPECT_TRUE(source.ended_short());  // the header announced 60
}

// Cut a little short (its last 8% of bytes and the index after them gone): a few frames
// missing of the 60 announced is no container's rounding, and is said (it was taken for one
// below 5%: a 1080p AVI cut 10 frames short of 216 ended "done").
TEST(VideoFileSource, ClipCutALittleShortIsSaidToHaveEndedShort) {
  const auto dir = testing::ScratchDir("video_file_source_cut_short");
  VideoFileSource source({CutCopy(WriteClip(dir, 60, 120), dir / "cut.avi", 92), false});
  int n = 0;
  while (source.Next()) ++n;
  std::printf("cut to 92%% of its bytes: %d of 60 frames read\n", n);
  EXPECT_GE(n, 50);
  EXPECT_LE(n, 57);
  EXPECT_TRUE(source.ended_short());
}

// A file with damaged bytes in its middle (an H.264 .mp4, every frame a key frame, 400 B
// overwritten a third of the way in): the damaged frames cannot be decoded, the ones after
// them can. They all come out, each with its own time, and the lost ones are counted.
// Before, the reading stopped at the first damaged frame and the rest of the file was lost.
TEST(VideoFileSource, DamagedStretchIsSkippedAndTheFramesAfterItAreRead) {
  const auto dir = testing::ScratchDir("video_file_source_damaged");
  const std::string avi = WriteClip(dir, 60, 30);
  const auto mp4 = (dir / "clip.mp4").string(), bad = (dir / "damaged.mp4").string();
  std::string out;
  ASSERT_EQ(testing::RunCommand("ffmpeg -v error -y -i '" + avi + "' -c:v libx264 -g 1 -pix_fmt yuv420p '" +
                                    mp4 + "'",
                                &out),
            0)
      << out;
  {
    std::ifstream in(mp4, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), {});
    ASSERT_GT(bytes.size(), 4000u);
    for (size_t i = bytes.size() / 3; i < bytes.size() / 3 + 400; ++i) bytes[i] = "\xde\xad\xbe\xef"[i % 4];
    std::ofstream(bad, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }
  VideoFileSource source({bad, false});
  int n = 0, last_index = -1;
  while (auto f = source.Next()) {
    const int index = static_cast<int>(std::lround(static_cast<double>(f->utime) * 30e-6));
    EXPECT_NEAR(BarRow(f->image), 2 * index, 1) << "frame at " << f->utime << " us";
    EXPECT_GT(index, last_index);
    last_index = index;
    ++n;
  }
  EXPECT_GT(source.undecodable_frames(), 0);
  EXPECT_EQ(n + source.undecodable_frames(), 60);
  EXPECT_EQ(last_index, 59);  // the file's last frame, after the damage
  EXPECT_FALSE(source.ended_short());
}

// Reading ahead on a thread of its own (as `run` reads a file; here with one decoder thread
// too) gives the same frames with the same times and counts as decoding in Next(): a real
// phone clip with pictures it repeats, and a truncated file; and a source destroyed while its
// thread waits with a full queue ends at once.
std::vector<std::pair<int64_t, double>> FramesOf(VideoFileSource& source) {
  std::vector<std::pair<int64_t, double>> out;
  while (auto f = source.Next()) out.emplace_back(f->utime, cv::sum(f->image)[0] + 7 * cv::sum(f->image)[2]);
  return out;
}

TEST(VideoFileSource, ReadingAheadGivesTheSameFramesTimesAndCounts) {
  const auto scratch = testing::ScratchDir("video_file_source_ahead");
  std::vector<std::string> clips = {CutCopy(WriteClip(scratch, 60, 120), scratch / "half.avi", 50)};
  if (const auto dir = testing::RealClipsDir(); !dir.empty())
    clips.push_back((dir / "pingpong_ruler_60fps.mov").string());
  for (const std::string& clip : clips) {
    VideoFileSourceConfig plain{clip, false};
    VideoFileSourceConfig ahead = plain;
    ahead.read_ahead = 3;
    ahead.decoder_threads = 1;
    VideoFileSource a(plain), b(ahead);
    const auto fa = FramesOf(a), fb = FramesOf(b);
    EXPECT_EQ(fa, fb) << clip;
    EXPECT_GT(fa.size(), 20u);
    EXPECT_EQ(a.ended_short(), b.ended_short()) << clip;
    EXPECT_EQ(a.repeated_frames(), b.repeated_frames()) << clip;
    EXPECT_EQ(a.undecodable_frames(), b.undecodable_frames()) << clip;
    EXPECT_FALSE(b.Next()) << "the end stays the end";
  }
  VideoFileSourceConfig ahead{WriteClip(scratch, 60, 120), false};
  ahead.read_ahead = 2;
  const auto t0 = std::chrono::steady_clock::now();
  {
    VideoFileSource c(ahead);
    ASSERT_TRUE(c.Next());
    std::this_thread::sleep_for(std::chrono::milliseconds(50));  // its queue fills, it waits
  }
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(2));
}

// The time each side of the queue waited for the other: a consumer slower than decoding
// leaves the reading thread waiting for room (about its own time a frame, less the
// decoding's); one that asks at once waits for the frames; without reading ahead, neither.
TEST(VideoFileSource, QueueWaitsSayWhichSideIsBehind) {
  const auto scratch = testing::ScratchDir("video_file_source_waits");
  const std::string clip = WriteClip(scratch, 40, 120);
  VideoFileSourceConfig ahead{clip, false};
  ahead.read_ahead = 2;
  {
    VideoFileSource slow_consumer(ahead);
    int n = 0;
    while (slow_consumer.Next() && ++n < 12) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    const auto w = slow_consumer.queue_waits();
    EXPECT_GT(w.reader_s, 0.05) << "12 frames at 10 ms, decoding a small frame takes far less";
    EXPECT_LT(w.consumer_s, w.reader_s);
  }
  {
    VideoFileSource eager(ahead);
    while (eager.Next()) {
    }
    const auto w = eager.queue_waits();
    EXPECT_GT(w.consumer_s, w.reader_s) << "decoding is the slower side";
    EXPECT_LT(w.reader_s, 0.05);
  }
  VideoFileSource in_next({clip, false});
  while (in_next.Next()) {
  }
  EXPECT_EQ(in_next.queue_waits().consumer_s, 0.0);
  EXPECT_EQ(in_next.queue_waits().reader_s, 0.0);
}

}  // namespace
}  // namespace bouncefit
