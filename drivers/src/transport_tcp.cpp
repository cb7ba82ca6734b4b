// TCP client transport (networked instruments such as the IDS3010 on port 9090).
#include <fmt/format.h>

#include "asio_session.hpp"
#include "cal/drivers/loop_time.hpp"

namespace cal::drivers::transport {
namespace {

namespace asio = boost::asio;
using asio::ip::tcp;

// Resolution and connection with one deadline. The connect state is shared with the handlers
// so that a transport closed mid-connect is never called back.
struct Connect : std::enable_shared_from_this<Connect> {
  Connect(asio::io_context& io, std::shared_ptr<detail::Session<tcp::socket>> s,
          Transport::Handlers h)
      : resolver(io),
        timer(io),
        session(std::move(s)),
        handlers(std::move(h)),
        time(VirtualTime::of(io)) {}
  ~Connect() { settle(); }

  void start(const TcpSettings& settings) {
    // In simulated time a connection is made at once: the clock waits for it (the resolver
    // runs on a thread of its own, the loop would otherwise see nothing to do).
    if (time) time->begin_operation();
    timer.expires_after(settings.connect_timeout);
    timer.async_wait([self = shared_from_this(),
                      ms = settings.connect_timeout.count()](const boost::system::error_code& ec) {
      if (ec || self->done) return;
      self->finish(ErrorKind::timeout, fmt::format("no connection within {} ms", ms));
    });
    resolver.async_resolve(
        settings.host, std::to_string(settings.port),
        [self = shared_from_this()](const boost::system::error_code& ec,
                                    const tcp::resolver::results_type& endpoints) {
          if (self->done) return;
          if (ec) return self->finish(ErrorKind::open_failed, "cannot resolve: " + ec.message());
          asio::async_connect(self->session->stream(), endpoints,
                              [self](const boost::system::error_code& e, const tcp::endpoint&) {
                                self->connected(e);
                              });
        });
  }

  void settle() {
    if (time && !settled) time->end_operation();
    settled = true;
  }

  void connected(const boost::system::error_code& ec) {
    settle();
    if (done) return;
    if (ec) return finish(ErrorKind::open_failed, "cannot connect: " + ec.message());
    done = true;
    timer.cancel();
    boost::system::error_code ignored;
    // Requests are small and latency-bound (one JSON-RPC line per poll): no Nagle delay.
    session->stream().set_option(tcp::no_delay(true), ignored);
    const auto port = session->stream().local_endpoint(ignored).port();
    session->start(std::move(handlers), fmt::format("tcp:{}", port));
  }

  void finish(ErrorKind kind, const std::string& what) {
    settle();
    done = true;
    timer.cancel();
    resolver.cancel();
    session->close();
    if (cancelled) return;
    if (handlers.error) handlers.error(Error{kind, session->description() + ": " + what});
  }

  tcp::resolver resolver;
  Timer timer;  // the connect timeout, on the loop's time
  std::shared_ptr<detail::Session<tcp::socket>> session;
  Transport::Handlers handlers;
  bool done = false;
  bool cancelled = false;
  VirtualTime* time;
  bool settled = false;
};

class TcpTransport final : public Transport {
 public:
  TcpTransport(asio::io_context& io, TcpSettings settings)
      : io_(io), settings_(std::move(settings)) {}
  ~TcpTransport() override { close(); }

  void open(Handlers handlers) override {
    close();
    session_ = std::make_shared<detail::Session<tcp::socket>>(tcp::socket(io_), describe());
    connect_ = std::make_shared<Connect>(io_, session_, std::move(handlers));
    connect_->start(settings_);
  }
  void write(std::span<const std::byte> bytes) override {
    if (session_) session_->write(bytes);
  }
  void close() override {
    if (connect_ && !connect_->done) {
      connect_->cancelled = true;
      connect_->finish(ErrorKind::open_failed, "closed while connecting");
    }
    connect_.reset();
    if (session_) session_->close();
    session_.reset();
  }
  bool is_open() const override { return session_ && session_->active(); }
  std::string describe() const override {
    return fmt::format("tcp {}:{}", settings_.host, settings_.port);
  }

 private:
  asio::io_context& io_;
  TcpSettings settings_;
  std::shared_ptr<detail::Session<tcp::socket>> session_;
  std::shared_ptr<Connect> connect_;
};

}  // namespace

std::unique_ptr<Transport> make_tcp(asio::io_context& io, TcpSettings settings) {
  return std::make_unique<TcpTransport>(io, std::move(settings));
}

}  // namespace cal::drivers::transport
