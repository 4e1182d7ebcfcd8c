#include "pipeline/capture_stage.h"

#include <fmt/format.h>

#include <cmath>
#include <optional>
#include <stdexcept>

#include "capture/frame_recorder.h"
#include "msgs/csv_cell.h"
#include "msgs/lcm_bus.h"
#include "msgs/node_clock.h"
#include "msgs/lcm_log_recorder.h"
#include "pipeline/message_mapping.h"
#include "pipeline/output_dir.h"
#include "pipeline/sound_listener.h"
#include "replay/container_clock.h"
#include "replay/pacer.h"
#include "replay/video_file_source.h"

namespace bouncefit {
namespace {

// Flags that need the frame size, checked before anything is written.
void ValidateAgainstFrame(const TrackerConfig& t, const SourceInfo& info) {
  if (info.width <= 0 || info.height <= 0) return;
  const std::string size = fmt::format("{}x{} px frame", info.width, info.height);
  if (t.has_pick && !(t.pick_x >= 0 && t.pick_x < info.width && t.pick_y >= 0 && t.pick_y < info.height))
    throw std::invalid_argument(fmt::format("--pick {:.0f},{:.0f} is outside the {}", t.pick_x, t.pick_y, size));
  if (t.roi_w > 0 && t.roi_h > 0 &&
      (t.roi_x < 0 || t.roi_y < 0 || t.roi_x >= info.width || t.roi_y >= info.height))
    throw std::invalid_argument("--roi starts outside the " + size);
}

}  // namespace

CaptureStage::CaptureStage(CaptureStageConfig config, LcmBus& bus, NoticeFn notice)
    : config_(std::move(config)), bus_(bus), notice_(std::move(notice)) {
  if (!notice_) notice_ = [](const std::string&) {};
  const bool is_file = config_.camera.device.empty();
  if (is_file == config_.clip.empty())
    throw std::invalid_argument("give exactly one of a clip or a camera device");
  if (!config_.audio_device.empty() && is_file)
    throw std::invalid_argument("--audio-device needs --device (a clip's own sound track is used)");
  if (!config_.record.empty() && is_file)
    throw std::invalid_argument("--record saves a camera; a replayed clip is already a file");
  pacer_ = std::make_unique<Pacer>(config_.speed);  // validates the speed
  if (is_file) {
    VideoFileSourceConfig vc = ReadAheadConfig(config_.clip);
    vc.loop = config_.loop;
    auto f = std::make_unique<VideoFileSource>(vc);
    file_ = f.get();
    source_ = std::move(f);
  } else {
    source_ = config_.camera_io ? std::make_unique<V4l2Camera>(config_.camera, *config_.camera_io)
                                : std::make_unique<V4l2Camera>(config_.camera);
  }
  const SourceInfo info = source_->Info();
  ValidateAgainstFrame(config_.tracker, info);
  tracker_ = std::make_unique<Tracker>(config_.tracker);
  look_back_ = std::make_unique<LookBackTracker>(*tracker_);
  if (!config_.audio_device.empty())
    sound_ = std::make_unique<SoundListener>(AlsaMicrophoneConfig{.device = config_.audio_device, .config_text = {}});
  else
    sound_ = std::make_unique<SoundListener>(is_file && !config_.no_audio ? config_.clip : "");

  start_.state = "start";
  start_.input = is_file ? config_.clip : config_.camera.device;
  start_.description = info.description;
  start_.is_file = is_file;
  start_.nominal_fps = info.nominal_fps;
  start_.width = info.width;
  start_.height = info.height;
  start_.announced_frames = std::max<int64_t>(info.frame_count, 0);
  if (is_file) {
    const ContainerClock clock = ReadContainerClock(config_.clip);
    start_.container_capture_fps = clock.capture_fps;
    start_.container_stored_fps = clock.stored_fps;
    start_.container_tag = clock.tag;
  }
  start_.sound = config_.no_audio && is_file ? "off (--no-audio)" : sound_->Describe();
  start_.listening = sound_->enabled();

  if (!config_.out_dir.empty()) {
    track_csv_ = std::make_unique<std::ofstream>(config_.out_dir / "track.csv", std::ios::trunc);
    if (!*track_csv_) throw std::runtime_error("cannot write '" + (config_.out_dir / "track.csv").string() + "'");
    *track_csv_ << "frame,t_s,found,cx_px,cy_px,x_px,y_px,w_px,h_px,camera_dx_px,camera_dy_px\n" << std::flush;
  }
  const std::string log_path = !config_.log_path.empty() ? config_.log_path
                               : !config_.out_dir.empty() ? (config_.out_dir / "session.lcm").string()
                                                          : std::string();
  if (!log_path.empty()) log_ = std::make_unique<LcmLogRecorder>(log_path);
  if (!config_.record.empty()) recorder_ = std::make_unique<FrameRecorder>(config_.record, info.nominal_fps);
}

CaptureStage::~CaptureStage() = default;

int64_t CaptureStage::frames() const { return frames_; }
int64_t CaptureStage::found() const { return found_; }
double CaptureStage::stream_s() const { return (last_utime_ - first_utime_) * 1e-6; }
double CaptureStage::total_s() const {
  return start_.announced_frames > 0 && start_.nominal_fps > 0 ? start_.announced_frames / start_.nominal_fps : 0;
}

template <class Msg>
static void PublishAndLog(LcmBus& bus, LcmLogRecorder* log, const std::string& channel, const Msg& m) {
  bus.Publish(channel, m);
  if (!log) return;
  std::vector<uint8_t> buf(static_cast<size_t>(m.getEncodedSize()));
  m.encode(buf.data(), 0, static_cast<int>(buf.size()));
  log->Record(channel, buf.data(), buf.size(), WallMicros());
}

void CaptureStage::Send(const impact_t& m) { PublishAndLog(bus_, log_.get(), config_.channels.impact, m); }

void CaptureStage::OnFrame(const Frame& frame, const BallObservation& obs) {
  if (t0_utime_ < 0) {
    t0_utime_ = frame.utime;
    start_.utime = frame.utime;
    PublishAndLog(bus_, log_.get(), config_.channels.stream, start_);
  }
  if (obs.found) ++found_;
  const ball_box_t box = ToBallBox(obs);
  PublishAndLog(bus_, log_.get(), config_.channels.ball_box, box);
  if (track_csv_) {
    auto& f = *track_csv_;
    f << box.frame << ',' << CsvCell((box.utime - t0_utime_) * 1e-6, 6) << ',' << (box.found ? 1 : 0);
    if (box.found)
      f << ',' << CsvCell(box.cx, 3) << ',' << CsvCell(box.cy, 3) << ',' << CsvCell(box.x, 0) << ','
        << CsvCell(box.y, 0) << ',' << CsvCell(box.w, 0) << ',' << CsvCell(box.h, 0);
    else
      f << ",,,,,,";
    f << ',' << CsvCell(box.camera_dx, 2) << ',' << CsvCell(box.camera_dy, 2) << '\n';
    f.flush();
  }
  for (const impact_t& m : sound_->AdvanceTo((frame.utime - t0_utime_) * 1e-6, t0_utime_)) Send(m);
  if (on_frame_) on_frame_(frame, obs);
}

bool CaptureStage::Step() {
  if (ended_ || !failure_.empty()) return false;
  try {
    return ReadAndTrack();
  } catch (const std::exception& e) {
    failure_ = e.what();  // what was recorded stays; End() says why it stopped
    return false;
  }
}

bool CaptureStage::ReadAndTrack() {
  if (flushed_) return false;
  if (config_.max_frames > 0 && frames_ >= config_.max_frames) {
    Flush();
    return false;
  }
  const int64_t t0 = SteadyMicros();
  if (start_wall_us_ < 0) start_wall_us_ = t0;
  std::optional<Frame> frame;
  try {
    frame = source_->Next();
  } catch (...) {
    dropped_ = source_->dropped_frames();
    Flush();  // the frames read before the failure still go out
    throw;
  }
  read_s_ += (SteadyMicros() - t0) * 1e-6;
  dropped_ = source_->dropped_frames();
  if (!frame) {
    Flush();
    return false;
  }
  // A clip replayed at a pace waits for each frame's time; a camera sets its own.
  if (file_ && config_.speed > 0) pacer_->WaitFor(frame->utime);
  if (recorder_) recorder_->Write(*frame);
  if (frames_ == 0) first_utime_ = frame->utime;
  last_utime_ = frame->utime;
  ++frames_;
  const int64_t t1 = SteadyMicros();
  std::vector<TrackedFrame> settled;
  try {
    settled = look_back_->Track(*frame);
  } catch (...) {
    Flush();
    throw;
  }
  track_s_ += (SteadyMicros() - t1) * 1e-6;
  for (const TrackedFrame& f : settled) OnFrame(f.frame, f.obs);
  wall_s_ = (SteadyMicros() - start_wall_us_) * 1e-6;
  return true;
}

void CaptureStage::Flush() {
  if (flushed_) return;
  flushed_ = true;
  for (const TrackedFrame& f : look_back_->Flush()) OnFrame(f.frame, f.obs);
  if (start_wall_us_ >= 0) wall_s_ = (SteadyMicros() - start_wall_us_) * 1e-6;
}

void CaptureStage::End(bool stopped) {
  if (ended_) return;
  ended_ = true;
  try {
    Flush();
  } catch (const std::exception& e) {
    if (failure_.empty()) failure_ = e.what();
  }
  if (t0_utime_ >= 0) {
    try {
      for (const impact_t& m : sound_->Finish(t0_utime_)) Send(m);
    } catch (const std::exception& e) {
      if (failure_.empty()) failure_ = e.what();
    }
  }
  const std::string what = config_.clip.empty() ? config_.camera.device : config_.clip;
  if (file_ && file_->ended_short() && failure_.empty())
    notice_(fmt::format("capture: warning: {} ended after {} of the {} frames it announces (truncated or damaged?)",
                        what, frames_, start_.announced_frames));
  if (file_ && file_->undecodable_frames() > 0)
    notice_(fmt::format("capture: warning: {}: {} frames could not be decoded (damaged data) and were skipped; "
                        "the stream went on after them, with a gap in the track",
                        what, file_->undecodable_frames()));
  if (file_ && file_->repeated_frames() > 0)
    notice_(fmt::format("capture: {} of {} pictures repeat the one before (content of a lower frame rate on this "
                        "file's timeline): skipped, each picture tracked once at the time it was first shown",
                        file_->repeated_frames(), file_->repeated_frames() + frames_));
  end_ = start_;
  end_.state = "end";
  end_.utime = frames_ > 0 ? last_utime_ : start_.utime;
  end_.frames = frames_;
  end_.found = found_;
  end_.dropped = dropped_;
  end_.repeated = file_ ? file_->repeated_frames() : 0;
  end_.undecodable = file_ ? file_->undecodable_frames() : 0;
  end_.ended_short = file_ && file_->ended_short();
  end_.stopped = stopped;
  end_.failure = failure_;
  end_.wall_s = wall_s_;
  end_.read_s = read_s_;
  end_.track_s = track_s_;
  end_.sound_cpu_s = sound_->cpu_s();
  end_.tracker = tracker_->Describe();
  const TrackerConfig& t = config_.tracker;
  end_.tracker_named = t.has_color || t.has_chroma || t.has_pick || t.luma_mode;
  PublishAndLog(bus_, log_.get(), config_.channels.stream, end_);
  if (recorder_) recorder_->Close();
  if (log_) log_->Close();
  if (track_csv_) track_csv_->close();
  if (!config_.out_dir.empty()) sound_->WriteWaveformCsv(config_.out_dir);
}

}  // namespace bouncefit
