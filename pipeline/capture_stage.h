#pragma once
// The capture node: a camera or a clip replayed at its recorded pace -> the tracker ->
// BALL_BOX per frame; the sound beside it -> IMPACT (heard); STREAM when the first frame is
// read and after the last. With an output directory it writes what it owns: track.csv,
// session.lcm (every message it sent: what `replay-log` needs to run detect and fit again
// without the video) and waveform.csv.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <string>

#include "bouncefit/impact_t.hpp"
#include "bouncefit/stream_t.hpp"
#include "capture/alsa_microphone.h"
#include "capture/v4l2_camera.h"
#include "msgs/channels.h"
#include "track/look_back_tracker.h"
#include "track/tracker.h"

namespace bouncefit {

class FrameRecorder;
class FrameSource;
class LcmBus;
class LcmLogRecorder;
class Pacer;
class SoundListener;
class VideoFileSource;
struct Frame;
struct BallObservation;

struct CaptureStageConfig {
  std::string clip;          // a clip to replay, or
  V4l2CameraConfig camera;   // a camera (camera.device not empty)
  V4l2Io* camera_io = nullptr;  // the camera's system calls (null: the system's; a scripted device in tests)
  bool loop = false;         // replay: start the clip again at its end
  double speed = 1.0;        // replay: multiple of real time (0: as fast as possible)
  int64_t max_frames = 0;    // stop after this many frames (0: none)
  bool no_audio = false;     // ignore a clip's sound track
  std::string audio_device;  // camera: an ALSA microphone beside it
  std::string record;        // camera: save the frames to this .avi
  TrackerConfig tracker;
  Channels channels;
  std::filesystem::path out_dir;  // empty: nothing written
  std::string log_path;           // session.lcm elsewhere (empty: out_dir's, or none)
};

class CaptureStage {
 public:
  using NoticeFn = std::function<void(const std::string&)>;
  // Called after every frame with its stream time and the counts so far (progress).
  using FrameFn = std::function<void(const Frame&, const BallObservation&)>;

  // Opens the source (and the sound, the output files); throws std::invalid_argument for a
  // bad configuration, std::runtime_error for a source that cannot be opened. `bus`
  // receives every message.
  CaptureStage(CaptureStageConfig config, LcmBus& bus, NoticeFn notice = {});
  ~CaptureStage();

  void set_frame_observer(FrameFn fn) { on_frame_ = std::move(fn); }
  const stream_t& stream() const { return start_; }  // what STREAM start says (before the first frame: its fields but utime)

  // One frame: read, pace, track, publish (and the sound heard up to its time). False at the
  // end of the stream (or max_frames, or a failure: failure() says why).
  bool Step();
  // The end: the rest of the sound, STREAM end, the files closed. stopped: by the user.
  void End(bool stopped);

  int64_t frames() const;
  int64_t found() const;
  double stream_s() const;
  double total_s() const;  // the clip's length, s (0: unknown)
  const std::string& failure() const { return failure_; }
  const stream_t& end_message() const { return end_; }

 private:
  // Reads, paces, records and tracks one frame; publishes the frames it settles.
  bool ReadAndTrack();
  // The frames still waiting for the look back, published; ReadAndTrack() is false after it.
  void Flush();
  void OnFrame(const Frame& frame, const BallObservation& obs);
  void Send(const impact_t& m);

  CaptureStageConfig config_;
  LcmBus& bus_;
  NoticeFn notice_;
  FrameFn on_frame_;
  std::unique_ptr<FrameSource> source_;
  VideoFileSource* file_ = nullptr;
  std::unique_ptr<Tracker> tracker_;
  std::unique_ptr<LookBackTracker> look_back_;
  std::unique_ptr<Pacer> pacer_;
  std::unique_ptr<SoundListener> sound_;
  std::unique_ptr<LcmLogRecorder> log_;
  std::unique_ptr<FrameRecorder> recorder_;
  std::unique_ptr<std::ofstream> track_csv_;
  stream_t start_{}, end_{};
  // What went through: frames read and tracked, found, lost by the source; the first and
  // last capture times; wall time since the first read, and in reading and tracking.
  int64_t frames_ = 0, found_ = 0, dropped_ = 0, first_utime_ = 0, last_utime_ = 0;
  double wall_s_ = 0, read_s_ = 0, track_s_ = 0;
  int64_t start_wall_us_ = -1;
  bool flushed_ = false;
  int64_t t0_utime_ = -1;
  std::string failure_;
  bool ended_ = false;
};

}  // namespace bouncefit
