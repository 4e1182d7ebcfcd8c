#include "capture/v4l2_negotiation.h"

#include <fmt/format.h>

#include <linux/videodev2.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace bouncefit {
namespace {

bool IsMjpeg(uint32_t fourcc) {
  return fourcc == V4L2_PIX_FMT_MJPEG || fourcc == V4L2_PIX_FMT_JPEG;
}

bool Supported(uint32_t fourcc) { return fourcc == V4L2_PIX_FMT_YUYV || IsMjpeg(fourcc); }

// The fastest frame rate the format offers at the size nearest to w x h (0: unknown).
double BestFps(const V4l2FormatInfo& f, int w, int h) {
  const V4l2FrameSize* best = nullptr;
  long best_distance = std::numeric_limits<long>::max();
  for (const auto& s : f.sizes) {
    const long distance = (w > 0 && h > 0) ? std::labs(long(s.width) - w) + std::labs(long(s.height) - h) : 0;
    if (distance < best_distance) {
      best_distance = distance;
      best = &s;
    }
  }
  if (!best) return 0;
  double fps = 0;
  for (const auto& i : best->intervals) fps = std::max(fps, i.fps());
  return fps;
}

// The format config asks for among those offered; where names the device in errors, and
// *reason says why MJPEG was chosen over YUYV (empty otherwise).
uint32_t ChooseFormat(const std::vector<V4l2FormatInfo>& formats, const V4l2CameraConfig& config,
                      const std::string& where, std::string* reason) {
  const V4l2FormatInfo* yuyv = nullptr;
  const V4l2FormatInfo* mjpeg = nullptr;
  std::string offered;
  for (const auto& f : formats) {
    offered += (offered.empty() ? "" : ", ") + FourccToString(f.fourcc);
    if (f.fourcc == V4L2_PIX_FMT_YUYV && !yuyv) yuyv = &f;
    if (IsMjpeg(f.fourcc) && !mjpeg) mjpeg = &f;
  }
  if (offered.empty()) offered = "nothing";
  if (config.pixel_format == "yuyv") {
    if (!yuyv) throw std::runtime_error(where + " does not offer YUYV (offers " + offered + ")");
    return yuyv->fourcc;
  }
  if (config.pixel_format == "mjpeg") {
    if (!mjpeg) throw std::runtime_error(where + " does not offer MJPEG (offers " + offered + ")");
    return mjpeg->fourcc;
  }
  if (!yuyv && !mjpeg)
    throw std::runtime_error(where + " offers neither YUYV nor MJPEG (offers " + offered + ")");
  if (!mjpeg) return yuyv->fourcc;
  if (!yuyv) return mjpeg->fourcc;
  const double yuyv_fps = BestFps(*yuyv, config.width, config.height);
  const double mjpeg_fps = BestFps(*mjpeg, config.width, config.height);
  if (config.fps <= 0 || yuyv_fps <= 0) return yuyv->fourcc;  // unknown: prefer YUYV
  if (yuyv_fps >= config.fps * 0.99) return yuyv->fourcc;
  if (mjpeg_fps >= config.fps * 0.99 || mjpeg_fps > yuyv_fps) {
    *reason = fmt::format("YUYV reaches only {:.2f} fps at this size", yuyv_fps);
    return mjpeg->fourcc;
  }
  return yuyv->fourcc;
}

// Reads the frame interval into *n and sets the asked one where the driver can.
void SetFrameInterval(V4l2Io& io, int fd, const V4l2CameraConfig& config, V4l2Negotiated* n) {
  v4l2_streamparm parm{};
  parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (io.Ioctl(fd, VIDIOC_G_PARM, &parm) < 0) return;  // the driver does not say
  n->interval_settable = parm.parm.capture.capability & V4L2_CAP_TIMEPERFRAME;
  n->interval = {parm.parm.capture.timeperframe.numerator,
                 parm.parm.capture.timeperframe.denominator};
  if (config.fps <= 0 || !n->interval_settable) return;
  v4l2_streamparm want{};
  want.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  const double rounded = std::round(config.fps);
  if (std::fabs(rounded - config.fps) < 1e-9) {
    want.parm.capture.timeperframe = {1, static_cast<uint32_t>(rounded)};
  } else {
    want.parm.capture.timeperframe = {1000, static_cast<uint32_t>(std::lround(config.fps * 1000))};
  }
  if (io.Ioctl(fd, VIDIOC_S_PARM, &want) < 0)
    throw std::runtime_error(config.device + ": cannot set the frame interval: " +
                             V4l2ErrnoText(errno));
  // The driver writes back what it granted; read it again in case it does not.
  v4l2_streamparm granted{};
  granted.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (io.Ioctl(fd, VIDIOC_G_PARM, &granted) == 0 && granted.parm.capture.timeperframe.denominator)
    want = granted;
  n->interval = {want.parm.capture.timeperframe.numerator,
                 want.parm.capture.timeperframe.denominator};
}

}  // namespace

void NegotiateV4l2Format(V4l2Io& io, int fd, const V4l2CameraConfig& config,
                         V4l2Negotiated* out) {
  V4l2Negotiated& negotiated = *out;
  const auto device = QueryV4l2Device(io, fd, config.device);
  if (!device)
    throw std::runtime_error(config.device + " is not a V4L2 device: " + V4l2ErrnoText(errno));
  const std::string& card = device->card;
  const uint32_t caps = device->capabilities;
  if (!(caps & V4L2_CAP_VIDEO_CAPTURE))
    throw std::runtime_error(config.device + " (" + card + ") is not a video capture device");
  if (caps & V4L2_CAP_STREAMING) {
    negotiated.streaming = true;
  } else if (caps & V4L2_CAP_READWRITE) {
    negotiated.streaming = false;
  } else {
    throw std::runtime_error(config.device + " supports neither streaming nor read() I/O");
  }

  std::string format_reason;
  const uint32_t fourcc = ChooseFormat(EnumerateV4l2Formats(io, fd), config,
                                       config.device + " (" + card + ")", &format_reason);

  v4l2_format fmt{};
  fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (io.Ioctl(fd, VIDIOC_G_FMT, &fmt) < 0)
    throw std::runtime_error(config.device + ": VIDIOC_G_FMT failed: " + V4l2ErrnoText(errno));
  if (config.width > 0) {
    fmt.fmt.pix.width = static_cast<uint32_t>(config.width);
    fmt.fmt.pix.height = static_cast<uint32_t>(config.height);
  }
  fmt.fmt.pix.pixelformat = fourcc;
  fmt.fmt.pix.field = V4L2_FIELD_NONE;
  fmt.fmt.pix.bytesperline = 0;  // let the driver choose the stride
  fmt.fmt.pix.sizeimage = 0;
  if (io.Ioctl(fd, VIDIOC_S_FMT, &fmt) < 0)
    throw std::runtime_error(config.device + ": cannot set format " + FourccToString(fourcc) +
                             ": " + V4l2ErrnoText(errno));
  const uint32_t got = fmt.fmt.pix.pixelformat;
  if (!Supported(got))
    throw std::runtime_error(config.device + ": asked for " + FourccToString(fourcc) +
                             ", the driver set " + FourccToString(got) +
                             ", which bouncefit cannot read");
  negotiated.fourcc = got;
  negotiated.width = static_cast<int>(fmt.fmt.pix.width);
  negotiated.height = static_cast<int>(fmt.fmt.pix.height);
  negotiated.bytes_per_line = static_cast<int>(fmt.fmt.pix.bytesperline);
  if (got == V4L2_PIX_FMT_YUYV && negotiated.bytes_per_line < 2 * negotiated.width)
    negotiated.bytes_per_line = 2 * negotiated.width;
  negotiated.size_image = fmt.fmt.pix.sizeimage;
  if (negotiated.size_image == 0)
    negotiated.size_image = static_cast<uint32_t>(negotiated.bytes_per_line) *
                            static_cast<uint32_t>(negotiated.height);
  if (negotiated.width <= 0 || negotiated.height <= 0)
    throw std::runtime_error(config.device + ": the driver set an empty frame size");

  SetFrameInterval(io, fd, config, &negotiated);

  // The one line that says plainly what was asked and what was granted.
  std::ostringstream s;
  s << config.device << " (" << card << "): " << FourccToString(got) << " "
    << negotiated.width << "x" << negotiated.height << " at "
    << (negotiated.interval.fps() > 0 ? fmt::format("{:.2f} fps", negotiated.interval.fps())
                                      : std::string("an unknown rate"));
  std::vector<std::string> notes;
  if (config.fps > 0) {
    if (!negotiated.interval_settable)
      notes.push_back(fmt::format("asked {:.2f} fps: the driver cannot set the frame rate", config.fps));
    else if (std::fabs(negotiated.interval.fps() - config.fps) > 0.005 * config.fps)
      notes.push_back(fmt::format("asked {:.2f} fps: the driver granted {:.2f}", config.fps, negotiated.interval.fps()));
  }
  if (config.width > 0 && (config.width != negotiated.width || config.height != negotiated.height))
    notes.push_back("asked " + std::to_string(config.width) + "x" + std::to_string(config.height) +
                    ": the driver gave " + std::to_string(negotiated.width) + "x" +
                    std::to_string(negotiated.height));
  if (!format_reason.empty()) notes.push_back(format_reason);
  if (!negotiated.streaming) notes.push_back("read() I/O, no driver timestamps");
  for (std::size_t i = 0; i < notes.size(); ++i) s << (i ? "; " : " (") << notes[i];
  if (!notes.empty()) s << ")";
  negotiated.summary = s.str();
}

}  // namespace bouncefit
