#pragma once
// Private to drivers/: the channels the simulated twins speak over (a loopback TCP line server,
// a pseudo-terminal) and the ordered writer they share. Includes Boost.Asio: only twin .cpp
// files include it.
#include <array>
#include <boost/asio.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <cstdint>
#include <deque>
#include <functional>
#include <list>
#include <memory>
#include <string>
#include <string_view>

#include "cal/drivers/loop_time.hpp"
#include "cal/drivers/sim/twin.hpp"
#include "reader_bytes.hpp"

namespace cal::drivers::sim::detail {

namespace asio = boost::asio;
using asio::ip::tcp;

// Writes queued strings to an Asio stream in order.
template <class Stream>
struct LineWriter {
  // A device sends whether or not anyone listens; with nobody reading the pty, its buffer
  // fills and a real device's output is lost. Beyond this much queued, new output is dropped
  // (and counted) instead of growing without bound.
  static constexpr std::size_t max_queued = 1 << 16;
  std::deque<std::string> queue;
  std::uint64_t dropped = 0;
  // Simulated mode: the bytes count as in flight until the driver reads them, while it is open
  // (reader_bytes.hpp); the driver named by `reader`: the pseudo-terminal's path, or
  // "tcp:PORT" by the client's port.
  ::cal::drivers::detail::ReaderBytes* time = nullptr;
  bool looked_up = false;
  std::string reader;
  void send(Stream& s, std::string line, std::shared_ptr<void> keep_alive) {
    if (queue.size() >= max_queued) {
      ++dropped;
      return;
    }
    if (!looked_up) time = ::cal::drivers::detail::ReaderBytes::of(s.get_executor().context());
    looked_up = true;
    if (time) time->written(line.size(), reader);
    queue.push_back(std::move(line));
    if (queue.size() == 1) next(s, std::move(keep_alive));
  }
  void next(Stream& s, std::shared_ptr<void> keep_alive) {
    asio::async_write(s, asio::buffer(queue.front()),
                      [this, &s, keep_alive](const boost::system::error_code& ec, std::size_t) {
                        if (ec) {  // what was not written never arrives
                          if (time)
                            for (const auto& q : queue) time->read(q.size(), reader);
                          return queue.clear();
                        }
                        queue.pop_front();
                        if (!queue.empty()) next(s, keep_alive);
                      });
  }
};

// A TCP server on 127.0.0.1 that hands every request a client sends to on_line (by default a
// line, its CR LF or LF removed; a twin whose device takes unterminated requests sets its own
// framing), and lets the twin answer that client or write to all of them.
class LineServer : public std::enable_shared_from_this<LineServer> {
 public:
  struct Client {
    explicit Client(tcp::socket s) : socket(std::move(s)) {}
    tcp::socket socket;
    std::string input;  // received, not yet a whole request
    std::array<char, 4096> chunk{};
    LineWriter<tcp::socket> writer;
  };
  using ClientPtr = std::shared_ptr<Client>;
  // Where the first whole request of `buffered` ends (one past its last byte), or 0 while none
  // is whole yet. The request is handed on with trailing CR and LF removed.
  using Framing = std::function<std::size_t(std::string_view buffered)>;
  // A client that sends this much without one whole request is dropped (a device's input
  // buffer is finite too).
  static constexpr std::size_t max_request_bytes = 1 << 20;

  // port 0: an ephemeral port. on_line(client, line); on_connect(client) when one arrives.
  LineServer(asio::io_context& io, std::uint16_t port);
  void start(std::function<void(const ClientPtr&, const std::string&)> on_line,
             std::function<void(const ClientPtr&)> on_connect = {});
  void set_framing(Framing framing) { framing_ = std::move(framing); }  // before start()
  std::uint16_t port() const { return acceptor_.local_endpoint().port(); }
  void send(const ClientPtr& client, std::string text);
  // To every connected client but `except` (nullptr: every one).
  void broadcast(const std::string& text, const ClientPtr& except = nullptr);
  bool has_clients() const { return !clients_.empty(); }
  std::size_t clients() const { return clients_.size(); }
  void drop_clients();
  void close();  // stops accepting and drops every client

 private:
  void accept();
  void read(const ClientPtr& client);
  void hand_on_requests(const ClientPtr& client);  // every whole request of client->input

  tcp::acceptor acceptor_;
  std::list<ClientPtr> clients_;
  std::function<void(const ClientPtr&, const std::string&)> on_line_;
  std::function<void(const ClientPtr&)> on_connect_;
  Framing framing_;
  bool closed_ = false;  // after close() no handler calls back into the twin
};

// A pseudo-terminal: the twin holds the master side (and keeps the slave open so the master
// does not see EIO before the driver opens it); the driver opens path like a /dev/ttyUSB0.
struct PtyDevice {
  asio::posix::stream_descriptor master;
  int slave_fd = -1;
  std::string path;
  asio::streambuf input;
  LineWriter<asio::posix::stream_descriptor> writer;
  std::uint64_t lines = 0;

  explicit PtyDevice(asio::io_context& io);
  ~PtyDevice();
  PtyDevice(const PtyDevice&) = delete;
  PtyDevice& operator=(const PtyDevice&) = delete;
  void unplug();
  void send(std::string line, std::shared_ptr<void> keep_alive, std::uint64_t count = 1);
};

// What a PtyTwin's Impl is built on: the pty and the timer that paces the twin's output.
struct PtyChannel {
  explicit PtyChannel(asio::io_context& io)
      : pty(io), timer(io), simulated_time(VirtualTime::of(io) != nullptr) {}
  PtyDevice pty;
  Timer timer;  // on the loop's time (loop_time.hpp)
  // On simulated time (the twin's clock is then the loop's): the twin may sleep until its next
  // output is due instead of waking every few milliseconds to look, and batches a stream more
  // coarsely, since each wake-up costs CPU instead of wall time.
  bool simulated_time;
};

// What a TcpTwin's Impl is built on: the line server and the timer that paces what the twin
// sends unasked (idle in a twin that only answers).
struct TcpChannel {
  TcpChannel(asio::io_context& io, std::uint16_t port)
      : server(std::make_shared<LineServer>(io, port)), timer(io) {}
  std::shared_ptr<LineServer> server;
  Timer timer;  // on the loop's time (loop_time.hpp)
};

// Where a command line ends: at its CR or its LF, whichever comes first (a terminal, or a
// program, may end commands with CR, LF or CR LF; the LF of a CR LF is then an empty line).
struct EndOfCommand {
  template <class Iterator>
  std::pair<Iterator, bool> operator()(Iterator begin, Iterator end) const {
    for (Iterator i = begin; i != end; ++i)
      if (*i == '\r' || *i == '\n') return {std::next(i), true};
    return {end, false};
  }
};

// Reads command lines ended by CR, LF or CR LF from self->pty's master and hands each non-empty
// one (without its terminator) to self->on_command.
template <class Self>
void read_commands(const std::shared_ptr<Self>& self) {
  const std::size_t buffered = self->pty.input.size();
  asio::async_read_until(
      self->pty.master, self->pty.input, EndOfCommand{},
      [self, buffered](const boost::system::error_code& ec, std::size_t n) {
        // The driver's bytes to this twin, counted as that driver's (reader_bytes.hpp).
        if (auto* readers =
                ::cal::drivers::detail::ReaderBytes::of(self->pty.master.get_executor().context()))
          readers->read(self->pty.input.size() - buffered,
                        ::cal::drivers::detail::ReaderBytes::to_twin(self->pty.path));
        if (ec) return;
        std::string line(asio::buffers_begin(self->pty.input.data()),
                         asio::buffers_begin(self->pty.input.data()) + static_cast<long>(n) - 1);
        self->pty.input.consume(n);
        if (!line.empty()) self->on_command(line);
        read_commands(self);
      });
}

}  // namespace cal::drivers::sim::detail

namespace boost::asio {
template <>
struct is_match_condition<cal::drivers::sim::detail::EndOfCommand> : std::true_type {};
}  // namespace boost::asio
