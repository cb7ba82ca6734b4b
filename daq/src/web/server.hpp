#pragma once
// The local HTTP + WebSocket service (Boost.Beast) behind `daq serve`: serves the live
// readout page, a small JSON API (runs, start, stop, status) and a WebSocket that pushes the
// live state. Bound to 127.0.0.1 by default; any other address only with a token.
//
// Safe by default against the web pages the operator visits and against hostile clients
// (the rules: http_policy.hpp; docs/web.md, "Security"): Host and Origin are checked, POST
// bodies must be JSON, the token (if any) is checked before a body is read, headers and
// bodies have size limits, a request (header and body) must arrive within request_timeout, the
// connection is closed after a refusal, and the accept loop survives every error (e.g. EMFILE:
// it waits and retries).
//
// Fair connections: at the cap (overall, or per remote address) a connection is closed to make
// room, chosen by state, then age: first one being closed after a refusal, then the HTTP
// connection that has made no progress for longest (waiting for a request, sending its body
// slowly, not reading its answer), and a WebSocket only when no HTTP connection is left (one
// that does not read its messages, then one without the page's Origin, then the newest).
// WebSockets are capped apart (half the connections, and a few per address, the stalest of the
// address closed for a new one), so they never crowd out the page's requests (its Stop).
//
// The WebSocket sends the latest state at a fixed period (default 10 Hz), never a queue of
// every reading: a 10 kHz stream can never make it fall behind, and a slow client only
// misses intermediate states (each client has at most one message in flight).
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace boost::asio {
class io_context;
}

namespace cal::daq::web {

// Content-Security-Policy of a document that must be inert (a run's report): no script, no
// frame, no form, nothing fetched; its style inline and its images data: URLs; and sandboxed
// (an origin of its own), so that even markup that got through could not call the API.
inline constexpr std::string_view inert_document_policy =
    "default-src 'none'; style-src 'unsafe-inline'; img-src data:; script-src 'none'; "
    "frame-src 'none'; object-src 'none'; base-uri 'none'; form-action 'none'; "
    "frame-ancestors 'none'; sandbox";

struct ServerOptions {
  std::string address = "127.0.0.1";
  std::uint16_t port = 8080;  // 0: an ephemeral port (see port())
  std::string token;          // required when address is not a loopback address
  std::chrono::milliseconds push_period{100};
  // The latest state is sent again after this without a change: a page that hears nothing for
  // longer knows the service is gone or hung, not idle (docs/web.md, "Updates").
  std::chrono::milliseconds keepalive_period{1000};
  std::vector<std::string> allowed_hosts;  // Host names accepted beside localhost and the address
  std::size_t max_header_bytes = 8 * 1024;
  std::size_t max_body_bytes = 64 * 1024;
  std::size_t max_connections = 256;  // HTTP and WebSocket together
  // Connections from one remote address at most (its own stalest is closed for a new one).
  std::size_t max_connections_per_client = 64;
  // WebSockets from one remote address at most (its oldest is closed for a new one); all
  // WebSockets together at most half of max_connections.
  std::size_t max_websockets_per_client = 8;
  // A request (header and body) must arrive within this after the connection opens or the
  // previous answer was sent; an idle keep-alive connection is closed after it too.
  std::chrono::milliseconds request_timeout{10'000};
  // A WebSocket client is pinged after half of this without data and closed after all of it.
  std::chrono::milliseconds websocket_idle_timeout{60'000};
  std::function<void(std::string_view)> log;  // accept errors and the like (may be empty)
};

struct Response {
  int status = 200;
  std::string body;  // JSON unless content_type says otherwise
  std::string content_type = "application/json";
  // Content-Disposition, e.g. "attachment; filename=\"report-run-3.pdf\"" (empty: none).
  std::string disposition;
  // Content-Security-Policy (empty: "frame-ancestors 'none'", which every answer has anyway).
  std::string content_security_policy;
  // Work that must not hold up the event loop (printing a PDF): the handler returns at once
  // with `deferred` set; the server calls it with a completion that may be called from any
  // thread, once, with the real answer (the connection waits for it). The work must be done
  // (or abandoned without calling it) before the io_context is destroyed.
  std::function<void(std::function<void(Response)> done)> deferred;
};

// A handler for a path (exact, or every path under a prefix ending in '/'), given the path and
// the body (empty for GET). A GET route answers HEAD too (the same header, no body).
struct Route {
  std::string method;  // "GET" or "POST"
  std::string path;    // "/api/setup/check", or "/reports/" for every path under it
  std::function<Response(std::string_view path, const std::string& body)> handle;
};

// The service's side of the API; every handler runs on the io_context's thread. A handler
// that throws gives a 500 with the exception's text; the server goes on.
struct Api {
  // GET / (and HEAD /): the page, given the nonce its script elements must carry (the page's
  // Content-Security-Policy allows no other script).
  std::function<std::string(std::string_view nonce)> page;
  std::function<Response()> runs;                          // GET /api/runs
  std::function<Response()> status;                        // GET /api/status
  std::function<Response(const std::string& body)> start;  // POST /api/runs/start (JSON body)
  std::function<Response(const std::string& body)> stop;   // POST /api/runs/stop (JSON body)
  std::vector<Route> routes;  // every other resource (the first that matches answers)
};

// An address and port as a URL writes them: "127.0.0.1:8080", "[::1]:8080".
std::string host_port(std::string_view address, std::uint16_t port);

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
  std::size_t connections() const;  // open HTTP and WebSocket connections
  std::uint64_t evicted() const;    // connections closed to make room

 private:
  struct Impl;
  std::shared_ptr<Impl> impl_;
};

}  // namespace cal::daq::web
