#pragma once
// The local HTTP + WebSocket service (Boost.Beast) behind `daq serve`: serves the live
// readout page, a small JSON API (runs, start, stop, status) and a WebSocket that pushes the
// live state. Bound to 127.0.0.1 by default; any other address only with a token, which
// every request must then carry (Authorization: Bearer TOKEN, or ?token=TOKEN for the page
// and the WebSocket, which browsers cannot give headers).
//
// The WebSocket sends the latest state at a fixed period (default 10 Hz), never a queue of
// every reading: a 10 kHz stream can never make it fall behind, and a slow client only
// misses intermediate states (each client has at most one message in flight).
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

namespace boost::asio {
class io_context;
}

namespace cal::daq::web {

struct ServerOptions {
  std::string address = "127.0.0.1";
  std::uint16_t port = 8080;  // 0: an ephemeral port (see port())
  std::string token;          // required when address is not a loopback address
  std::chrono::milliseconds push_period{100};
};

struct Response {
  int status = 200;
  std::string body;  // JSON
};

// The service's side of the API; every handler runs on the io_context's thread.
struct Api {
  std::function<std::string()> page;                       // GET /
  std::function<Response()> runs;                          // GET /api/runs
  std::function<Response()> status;                        // GET /api/status
  std::function<Response(const std::string& body)> start;  // POST /api/runs/start (JSON body)
  std::function<Response()> stop;                          // POST /api/runs/stop
};

class LiveServer {
 public:
  // Throws std::invalid_argument for a non-loopback address without a token, and
  // std::runtime_error (address and OS text) if the port cannot be bound.
  LiveServer(boost::asio::io_context& io, ServerOptions options, Api api);
  ~LiveServer();
  LiveServer(const LiveServer&) = delete;
  LiveServer& operator=(const LiveServer&) = delete;

  std::uint16_t port() const;
  // The latest live state (a JSON object as text); pushed to every WebSocket client at the
  // next period if it changed.
  void publish(std::string state_json);
  std::size_t websocket_clients() const;
  std::uint64_t messages_sent() const;

 private:
  struct Impl;
  std::shared_ptr<Impl> impl_;
};

}  // namespace cal::daq::web
