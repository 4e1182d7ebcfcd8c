#pragma once
// A thin, exception-safe wrapper around lcm::LCM for the nodes.
//
// LCM 1.3.1 calls handlers from C code: an exception thrown through it is undefined
// behaviour. Handlers registered here are wrapped: a throw is caught, counted and kept as
// the bus's last error, and the node decides what to do with it.
#include <lcm/lcm-cpp.hpp>

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace bouncefit {

class LcmBus {
 public:
  // Throws std::runtime_error with a one-line reason if the URL cannot be opened.
  explicit LcmBus(const std::string& url);
  ~LcmBus();
  LcmBus(const LcmBus&) = delete;
  LcmBus& operator=(const LcmBus&) = delete;

  template <class Msg>
  void Publish(const std::string& channel, const Msg& msg) {
    if (lcm_.publish(channel, &msg) != 0) ++publish_failures_;
    if (mirror_) mirror_->Publish(channel, msg);
  }
  // Every message published here is also published on `mirror` (a process hosting every
  // node on memq:// shows its traffic on the network bus too); null: none.
  void set_mirror(LcmBus* mirror) { mirror_ = mirror; }

  // Decoded messages; a packet that fails to decode is counted, never delivered.
  template <class Msg>
  void Subscribe(const std::string& channel, std::function<void(const Msg&)> handler) {
    auto adaptor = std::make_unique<TypedHandler<Msg>>(this, std::move(handler));
    lcm_.subscribe(channel, &TypedHandler<Msg>::Handle, adaptor.get());
    handlers_.push_back(std::move(adaptor));
  }

  // Raw bytes of every message on channels matching a regex (for logging).
  using RawHandler = std::function<void(const std::string& channel, const void* data,
                                        std::size_t size, int64_t recv_utime)>;
  void SubscribeRaw(const std::string& channel_regex, RawHandler handler);

  // Waits up to timeout_ms for one message and dispatches it. Returns false on timeout or when
  // a signal interrupts the wait. Throws std::runtime_error if LCM reports an error.
  bool HandleOnce(int timeout_ms);
  // Dispatches everything already queued, without waiting.
  void Drain();

  int64_t decode_failures() const { return decode_failures_; }
  int64_t handler_failures() const { return handler_failures_; }
  int64_t publish_failures() const { return publish_failures_; }
  std::string last_error() const;

  lcm::LCM& raw() { return lcm_; }

 private:
  struct HandlerBase {
    virtual ~HandlerBase() = default;
  };
  template <class Msg>
  struct TypedHandler : HandlerBase {
    TypedHandler(LcmBus* b, std::function<void(const Msg&)> f) : bus(b), fn(std::move(f)) {}
    void Handle(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
      Msg msg;
      if (msg.decode(rbuf->data, 0, rbuf->data_size) < 0) {
        bus->RecordDecodeFailure(channel);
        return;
      }
      try {
        fn(msg);
      } catch (const std::exception& e) {
        bus->RecordHandlerFailure(channel, e.what());
      } catch (...) {
        bus->RecordHandlerFailure(channel, "unknown exception");
      }
    }
    LcmBus* bus;
    std::function<void(const Msg&)> fn;
  };
  struct RawAdaptor;

  void RecordDecodeFailure(const std::string& channel);
  void RecordHandlerFailure(const std::string& channel, const std::string& what);

  lcm::LCM lcm_;
  LcmBus* mirror_ = nullptr;
  std::vector<std::unique_ptr<HandlerBase>> handlers_;
  std::atomic<int64_t> decode_failures_{0};
  std::atomic<int64_t> handler_failures_{0};
  std::atomic<int64_t> publish_failures_{0};
  mutable std::mutex error_mutex_;
  std::string last_error_;
};

}  // namespace bouncefit
