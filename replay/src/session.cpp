// Replay bus and transports (see session.hpp).
#include "cal/replay/session.hpp"

#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <map>

namespace cal::replay {

namespace t = drivers::transport;

struct ReplayBus::Impl : std::enable_shared_from_this<ReplayBus::Impl> {
  struct Port {
    t::Transport::Handlers handlers;
    bool open = false;
  };

  Impl(boost::asio::io_context& i, const std::filesystem::path& p, double s)
      : io(i), timer(i), reader(p), speed(s) {}

  boost::asio::io_context& io;
  boost::asio::steady_timer timer;
  CaptureReader reader;
  double speed;
  std::int64_t now_ns = 0;
  std::map<std::uint16_t, Port> ports;
  std::function<void(const ReplayEnd&)> done;
  std::optional<std::int64_t> wall_start_ns, first_ns;
  std::optional<RecordView> pending;  // valid until the next reader.next_view()

  void deliver(const RecordView& r) {
    now_ns = r.time_ns;
    auto it = ports.find(r.device);
    if (it == ports.end()) return;  // a device nobody replays
    Port& p = it->second;
    switch (r.kind) {
      case RecordKind::received:
        if (p.open && p.handlers.data) p.handlers.data(r.bytes);
        return;
      case RecordKind::sent:
        if (p.open && p.handlers.sent) p.handlers.sent(r.bytes);
        return;
      case RecordKind::event: {
        const auto text = r.text();
        if (text == "opened") {
          p.open = true;
          if (p.handlers.opened) p.handlers.opened();
        } else if (text.starts_with("error: ")) {
          p.open = false;
          if (auto h = p.handlers.error)
            h(t::Error{t::ErrorKind::read_failed, std::string(text.substr(7))});
        }
        return;
      }
    }
  }

  static std::int64_t wall_ns() {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(
               std::chrono::steady_clock::now().time_since_epoch())
        .count();
  }

  // Delivers a batch, then yields to the loop (so handlers the records trigger run in order
  // with them, and a paced replay sleeps on a timer rather than blocking the loop).
  void pump() {
    for (int n = 0; n < 512; ++n) {
      if (!pending) pending = reader.next_view();
      if (!pending) return finish();
      if (speed > 0) {
        if (!wall_start_ns) wall_start_ns = wall_ns(), first_ns = pending->time_ns;
        const auto due =
            *wall_start_ns +
            static_cast<std::int64_t>(static_cast<double>(pending->time_ns - *first_ns) / speed);
        if (wall_ns() < due) {
          timer.expires_after(std::chrono::nanoseconds(due - wall_ns()));
          timer.async_wait([self = shared_from_this()](const boost::system::error_code& ec) {
            if (!ec) self->pump();
          });
          return;
        }
      }
      deliver(*pending);
      pending.reset();
    }
    boost::asio::post(io, [self = shared_from_this()] { self->pump(); });
  }

  void finish() {
    if (!done) return;
    auto d = std::move(done);
    d(ReplayEnd{reader.records_read(), reader.damage()});
  }
};

namespace {

class ReplayTransport final : public t::Transport {
 public:
  ReplayTransport(std::weak_ptr<ReplayBus::Impl> bus, std::uint16_t device, std::string d)
      : bus_(std::move(bus)), device_(device), description_(std::move(d)) {}
  void open(Handlers h) override {
    if (auto b = bus_.lock()) {
      auto& port = b->ports[device_];
      // Re-opening after a recorded error keeps waiting for the recorded "opened".
      port.handlers = std::move(h);
    }
    open_ = true;
  }
  void write(std::span<const std::byte>) override {}  // the recording holds what was sent
  void close() override {
    // The handlers stay (one may be running: the instrument can close from inside it); the
    // port just stops delivering until the instrument opens it again.
    if (auto b = bus_.lock()) b->ports[device_].open = false;
    open_ = false;
  }
  bool is_open() const override { return open_; }
  std::string describe() const override { return "replay of " + description_; }

 private:
  std::weak_ptr<ReplayBus::Impl> bus_;
  std::uint16_t device_;
  std::string description_;
  bool open_ = false;
};

}  // namespace

ReplayEnd ReplayBus::read_to_end() {
  impl_->pending.reset();
  while (impl_->reader.next()) {
  }
  impl_->done = nullptr;  // the end is told here, not again from the loop
  return ReplayEnd{impl_->reader.records_read(), impl_->reader.damage()};
}

ReplayBus::ReplayBus(boost::asio::io_context& io, const std::filesystem::path& capture,
                     double speed)
    : impl_(std::make_shared<Impl>(io, capture, speed)) {}
ReplayBus::~ReplayBus() { impl_->timer.cancel(); }
const std::string& ReplayBus::header_json() const { return impl_->reader.header_json(); }

std::unique_ptr<t::Transport> ReplayBus::transport(std::uint16_t device, std::string description) {
  impl_->ports[device];
  return std::make_unique<ReplayTransport>(impl_, device, std::move(description));
}

drivers::Clock ReplayBus::clock() const {
  return [impl = impl_.get()] { return impl->now_ns; };
}

void ReplayBus::start(std::function<void(const ReplayEnd&)> done) {
  impl_->done = std::move(done);
  boost::asio::post(impl_->io, [self = impl_] { self->pump(); });
}

}  // namespace cal::replay
