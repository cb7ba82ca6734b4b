// The live push under a 10 kHz stream (a plain program; numbers in docs/benchmarks.md).
// Method: the server's event loop publishes one live state per reading of a 10 kHz stream
// (a steady timer catches up every millisecond, so every due reading is published: the worst
// case, since a run publishes about 10 Hz), each state carrying its sequence number and the
// steady-clock time of its publication. A WebSocket client on another thread reads for
// SECONDS and measures the messages per second it receives and the age of each state when it
// arrives (now minus its publication time). Falling behind would show as a growing age or a
// lag in sequence numbers; the server sends only the latest state, so neither should grow.
// Usage: live_bench [SECONDS]
#include <algorithm>
#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <cstdio>
#include <thread>
#include <vector>

#include "server.hpp"

namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using Clock = std::chrono::steady_clock;

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch())
      .count();
}

}  // namespace

int main(int argc, char** argv) {
  const double seconds = argc > 1 ? std::atof(argv[1]) : 10.0;
  asio::io_context io;
  cal::daq::web::LiveServer server(io, {.port = 0}, {});
  std::uint64_t published = 0;
  const auto start = Clock::now();
  asio::steady_timer timer(io);
  std::function<void()> produce = [&] {
    // Every reading due at 10 kHz since the start is published now.
    const auto due = static_cast<std::uint64_t>(
        std::chrono::duration<double>(Clock::now() - start).count() * 10'000.0);
    while (published < due) {
      ++published;
      server.publish("{\"seq\":" + std::to_string(published) + ",\"t_ns\":" +
                     std::to_string(now_ns()) + ",\"reading\":{\"value\":1.234,\"unit\":\"um\"}}");
    }
    timer.expires_after(std::chrono::milliseconds(1));
    timer.async_wait([&](auto ec) {
      if (!ec) produce();
    });
  };
  produce();
  std::thread loop([&] { io.run(); });

  asio::io_context cio;
  websocket::stream<tcp::socket> ws(cio);
  ws.next_layer().connect({asio::ip::address_v4::loopback(), server.port()});
  ws.handshake("localhost", "/ws");
  std::vector<double> ages_ms;
  std::uint64_t max_seq_lag = 0, messages = 0;
  const auto t0 = Clock::now();
  while (std::chrono::duration<double>(Clock::now() - t0).count() < seconds) {
    beast::flat_buffer buffer;
    ws.read(buffer);
    const auto text = beast::buffers_to_string(buffer.data());
    const auto t = now_ns();
    unsigned long long seq = 0;
    long long t_ns = 0;
    std::sscanf(text.c_str(), "{\"seq\":%llu,\"t_ns\":%lld", &seq, &t_ns);
    ages_ms.push_back(static_cast<double>(t - t_ns) * 1e-6);
    const auto expected = static_cast<std::uint64_t>(
        std::chrono::duration<double>(Clock::now() - start).count() * 10'000.0);
    max_seq_lag = std::max<std::uint64_t>(max_seq_lag, expected > seq ? expected - seq : 0);
    ++messages;
  }
  const double elapsed = std::chrono::duration<double>(Clock::now() - t0).count();
  ws.close(websocket::close_code::normal);
  asio::post(io, [&] {
    timer.cancel();
    io.stop();
  });
  loop.join();
  std::sort(ages_ms.begin(), ages_ms.end());
  const auto pct = [&](double p) {
    return ages_ms.empty()
               ? 0.0
               : ages_ms[static_cast<std::size_t>(p * static_cast<double>(ages_ms.size() - 1))];
  };
  std::printf(
      "10 kHz stream for %.1f s: %llu states published (%.0f/s)\n", elapsed,
      static_cast<unsigned long long>(published),
      static_cast<double>(published) / std::chrono::duration<double>(Clock::now() - start).count());
  std::printf("client: %llu messages, %.1f per second\n", static_cast<unsigned long long>(messages),
              static_cast<double>(messages) / elapsed);
  std::printf("age of a state on arrival: median %.2f ms, 99th percentile %.2f ms, max %.2f ms\n",
              pct(0.5), pct(0.99), pct(1.0));
  std::printf("largest lag behind the stream when a message arrived: %llu readings (%.1f ms)\n",
              static_cast<unsigned long long>(max_seq_lag),
              static_cast<double>(max_seq_lag) / 10.0);
  return 0;
}
