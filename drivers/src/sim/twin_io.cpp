// The simulated World and the channels the twins speak over (see twin_io.hpp, sim/world.hpp).
#include "sim/twin_io.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <pty.h>
#include <termios.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "cal/drivers/sim/world.hpp"

namespace cal::drivers::sim {

World::World(MachineConfig machine, AirConfig air, double step_s)
    : machine_(std::move(machine)), air_(std::move(air)), step_s_(step_s) {}

void World::advance_to(double t_s) { machine_.advance_to(t_s, step_s_); }

Clock steady_clock(double speed) {
  const auto start = std::chrono::steady_clock::now();
  return [start, speed] {
    return speed * std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
}

namespace detail {

using ::cal::drivers::detail::ReaderBytes;

LineServer::LineServer(asio::io_context& io, std::uint16_t port)
    : acceptor_(io, tcp::endpoint(asio::ip::address_v4::loopback(), port)) {}

void LineServer::start(std::function<void(const ClientPtr&, const std::string&)> on_line,
                       std::function<void(const ClientPtr&)> on_connect) {
  on_line_ = std::move(on_line);
  on_connect_ = std::move(on_connect);
  accept();
}

void LineServer::accept() {
  acceptor_.async_accept([self = shared_from_this()](const boost::system::error_code& ec,
                                                     tcp::socket socket) {
    if (ec || self->closed_) return;  // acceptor closed
    auto client = std::make_shared<Client>(std::move(socket));
    boost::system::error_code ignored;
    client->writer.reader = fmt::format("tcp:{}", client->socket.remote_endpoint(ignored).port());
    // The driver's bytes to us count as its own from now on (reader_bytes.hpp): a port used
    // again by another connection counts again.
    if (auto* readers = ReaderBytes::of(client->socket.get_executor().context()))
      readers->opened(ReaderBytes::to_twin(client->writer.reader));
    self->clients_.push_back(client);
    if (self->on_connect_) self->on_connect_(client);
    self->read(client);
    self->accept();
  });
}

void LineServer::read(const ClientPtr& client) {
  client->socket.async_read_some(
      asio::buffer(client->chunk),
      [self = shared_from_this(), client](const boost::system::error_code& ec, std::size_t n) {
        auto* readers = ReaderBytes::of(client->socket.get_executor().context());
        const auto from = ReaderBytes::to_twin(client->writer.reader);
        if (readers) readers->read(n, from);
        if (ec || self->closed_) {
          if (readers) readers->closed(from);  // what the driver sends now nobody reads
          self->clients_.remove(client);
          return;
        }
        client->input.append(client->chunk.data(), n);
        self->hand_on_requests(client);
        if (self->closed_) return;
        if (client->input.size() > max_request_bytes) {
          if (readers) readers->closed(from);
          boost::system::error_code ignored;
          client->socket.close(ignored);
          self->clients_.remove(client);
          return;
        }
        self->read(client);
      });
}

void LineServer::hand_on_requests(const ClientPtr& client) {
  while (!closed_) {
    std::size_t end = 0;
    if (framing_) {
      end = framing_(client->input);
    } else if (const auto eol = client->input.find('\n'); eol != std::string::npos) {
      end = eol + 1;
    }
    if (end == 0) return;
    std::string request = client->input.substr(0, end);
    client->input.erase(0, end);
    while (!request.empty() && (request.back() == '\n' || request.back() == '\r'))
      request.pop_back();
    if (on_line_) on_line_(client, request);
  }
}

void LineServer::send(const ClientPtr& client, std::string text) {
  client->writer.send(client->socket, std::move(text), client);
}

void LineServer::broadcast(const std::string& text, const ClientPtr& except) {
  for (const auto& c : clients_)
    if (c != except) send(c, text);
}

void LineServer::drop_clients() {
  for (auto& c : clients_) {
    if (auto* readers = ReaderBytes::of(c->socket.get_executor().context()))
      readers->closed(ReaderBytes::to_twin(c->writer.reader));
    boost::system::error_code ignored;
    c->socket.shutdown(tcp::socket::shutdown_both, ignored);
    c->socket.close(ignored);
  }
  clients_.clear();
}

void LineServer::close() {
  closed_ = true;
  boost::system::error_code ignored;
  acceptor_.close(ignored);
  drop_clients();
}

PtyDevice::PtyDevice(asio::io_context& io) : master(io) {
  int m = -1;
  std::array<char, 128> name{};
  if (openpty(&m, &slave_fd, name.data(), nullptr, nullptr) != 0)
    throw std::runtime_error(
        fmt::format("simulated twin: openpty failed: {}", std::strerror(errno)));
  termios raw{};
  tcgetattr(m, &raw);
  cfmakeraw(&raw);
  tcsetattr(m, TCSANOW, &raw);
  master.assign(m);
  path = name.data();
  writer.reader = path;
}

PtyDevice::~PtyDevice() { unplug(); }

void PtyDevice::unplug() {
  // What a driver sent us and we did not read is read by nobody now (reader_bytes.hpp).
  if (master.is_open())
    if (auto* readers = ReaderBytes::of(master.get_executor().context()))
      readers->closed(ReaderBytes::to_twin(path));
  boost::system::error_code ignored;
  master.close(ignored);
  if (slave_fd >= 0) ::close(slave_fd);
  slave_fd = -1;
}

void PtyDevice::send(std::string line, std::shared_ptr<void> keep_alive, std::uint64_t count) {
  if (!master.is_open()) return;
  lines += count;
  writer.send(master, std::move(line), std::move(keep_alive));
}

}  // namespace detail

PtyTwin::PtyTwin(std::shared_ptr<detail::PtyChannel> channel, std::string settings)
    : channel_(std::move(channel)), settings_(std::move(settings)) {}
PtyTwin::~PtyTwin() { unplug(); }
const std::string& PtyTwin::device_path() const { return channel_->pty.path; }
std::string PtyTwin::transport() const { return "serial " + device_path() + " " + settings_; }
void PtyTwin::unplug() {
  channel_->timer.cancel();
  channel_->pty.unplug();
}
std::uint64_t PtyTwin::lines_sent() const { return channel_->pty.lines; }

TcpTwin::TcpTwin(std::shared_ptr<detail::TcpChannel> channel) : channel_(std::move(channel)) {}
TcpTwin::~TcpTwin() {
  channel_->timer.cancel();
  channel_->server->close();
}
std::uint16_t TcpTwin::port() const { return channel_->server->port(); }
std::string TcpTwin::transport() const { return fmt::format("tcp 127.0.0.1:{}", port()); }
void TcpTwin::unplug() { channel_->server->drop_clients(); }

}  // namespace cal::drivers::sim
