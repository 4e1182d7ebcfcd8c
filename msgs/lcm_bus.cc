#include "msgs/lcm_bus.h"

#include <poll.h>

#include <cerrno>

#include <stdexcept>

namespace bouncefit {

struct LcmBus::RawAdaptor : LcmBus::HandlerBase {
  explicit RawAdaptor(RawHandler f) : fn(std::move(f)) {}
  void Handle(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    try {
      fn(channel, rbuf->data, rbuf->data_size, rbuf->recv_utime);
    } catch (...) {
      // A logging failure must never unwind through LCM's C code.
    }
  }
  RawHandler fn;
};

LcmBus::LcmBus(const std::string& url) : lcm_(url) {
  if (!lcm_.good()) throw std::runtime_error("cannot open LCM bus '" + url + "'");
}

LcmBus::~LcmBus() = default;

void LcmBus::SubscribeRaw(const std::string& channel_regex, RawHandler handler) {
  auto adaptor = std::make_unique<RawAdaptor>(std::move(handler));
  lcm_.subscribe(channel_regex, &RawAdaptor::Handle, adaptor.get());
  handlers_.push_back(std::move(adaptor));
}

bool LcmBus::HandleOnce(int timeout_ms) {
  const int rc = lcm_.handleTimeout(timeout_ms);
  // A signal (Ctrl-C, SIGTERM) interrupts the wait: no message, and the caller's loop sees its
  // stop flag and exits as stopped, not as a failed bus.
  if (rc < 0 && errno == EINTR) return false;
  if (rc < 0) throw std::runtime_error("LCM receive failed");
  return rc > 0;
}

void LcmBus::Drain() {
  pollfd pfd{lcm_.getFileno(), POLLIN, 0};
  while (::poll(&pfd, 1, 0) > 0 && (pfd.revents & POLLIN)) {
    if (lcm_.handle() != 0) break;
  }
}

std::string LcmBus::last_error() const {
  std::lock_guard<std::mutex> lock(error_mutex_);
  return last_error_;
}

void LcmBus::RecordDecodeFailure(const std::string& channel) {
  ++decode_failures_;
  std::lock_guard<std::mutex> lock(error_mutex_);
  last_error_ = "undecodable message on " + channel;
}

void LcmBus::RecordHandlerFailure(const std::string& channel, const std::string& what) {
  ++handler_failures_;
  std::lock_guard<std::mutex> lock(error_mutex_);
  last_error_ = "handler for " + channel + " failed: " + what;
}

}  // namespace bouncefit
