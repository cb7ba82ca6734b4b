// Beast HTTP + WebSocket server for the live readout (see server.hpp; the request rules are in
// http_policy.cpp).
#include "server.hpp"

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <limits>
#include <list>
#include <optional>
#include <stdexcept>

#include "http_policy.hpp"

namespace cal::daq::web {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using Clock = std::chrono::steady_clock;

bool is_loopback(const std::string& address) {
  boost::system::error_code ec;
  const auto a = asio::ip::make_address(address, ec);
  return !ec && a.is_loopback();
}

bool is_parse_error(const beast::error_code& ec) {
  return ec.category() == make_error_code(http::error::bad_method).category() &&
         ec != http::error::end_of_stream && ec != http::error::partial_message;
}

}  // namespace

struct LiveServer::Impl : std::enable_shared_from_this<LiveServer::Impl> {
  struct WsClient {
    explicit WsClient(beast::tcp_stream s) : ws(std::move(s)) {}
    websocket::stream<beast::tcp_stream> ws;
    std::string outgoing;
    bool writing = false;
  };

  // One HTTP connection; several requests one after the other (keep-alive).
  struct Session {
    explicit Session(tcp::socket s) : stream(std::move(s)) {}
    beast::tcp_stream stream;
    beast::flat_buffer buffer;
    std::optional<http::request_parser<http::empty_body>> header;
    std::optional<http::request_parser<http::string_body>> body;
    http::response<http::string_body> response;
    std::string local_address;
    bool waiting = false;  // for a request header: such a connection may be closed for room
    Clock::time_point waiting_since;
    bool closed = false;
    std::array<char, 4096> discard{};
  };
  using SessionPtr = std::shared_ptr<Session>;

  Impl(asio::io_context& context, ServerOptions o, Api a)
      : io(context),
        acceptor(context),
        timer(context),
        retry(context),
        options(std::move(o)),
        api(std::move(a)) {
    policy.token = options.token;
    policy.allowed_hosts = options.allowed_hosts;
    policy.max_body_bytes = options.max_body_bytes;
  }

  void listen() {
    if (!is_loopback(options.address) && options.token.empty())
      throw std::invalid_argument("daq serve: binding to " + options.address +
                                  " (not loopback) needs --token");
    boost::system::error_code ec;
    const tcp::endpoint ep(asio::ip::make_address(options.address, ec), options.port);
    if (ec) throw std::invalid_argument("daq serve: bad address '" + options.address + "'");
    acceptor.open(ep.protocol(), ec);
    if (!ec) acceptor.set_option(asio::socket_base::reuse_address(true), ec);
    if (!ec) acceptor.bind(ep, ec);
    if (!ec) acceptor.listen(asio::socket_base::max_listen_connections, ec);
    if (ec)
      throw std::runtime_error("daq serve: cannot listen on " + options.address + ":" +
                               std::to_string(options.port) + ": " + ec.message());
    accept();
    tick();
  }

  void log(const std::string& text) const {
    if (options.log) options.log(text);
  }

  std::size_t connections() const { return sessions.size() + clients.size(); }

  // The accept loop is re-armed after every error. Out of descriptors (EMFILE, ENFILE) or
  // buffers, it closes the connection waiting longest for a request and retries after a
  // pause, rather than spinning on an error the kernel repeats at once.
  void accept() {
    acceptor.async_accept([self = shared_from_this()](boost::system::error_code ec, tcp::socket s) {
      if (!self->acceptor.is_open() || ec == asio::error::operation_aborted) return;
      if (ec) return self->accept_failed(ec);
      if (self->connections() >= self->options.max_connections && !self->make_room()) {
        boost::system::error_code ignored;
        s.close(ignored);  // every connection is busy: refuse this one
        ++self->refused;
      } else {
        self->start_session(std::move(s));
      }
      self->accept();
    });
  }

  void accept_failed(const boost::system::error_code& ec) {
    ++accept_errors;
    const auto now = Clock::now();
    if (now - last_accept_log > std::chrono::seconds(10)) {
      log("accept failed (" + ec.message() + "); retrying (" + std::to_string(accept_errors) +
          " accept errors so far)");
      last_accept_log = now;
    }
    make_room();
    retry.expires_after(std::chrono::milliseconds(50));
    retry.async_wait([self = shared_from_this()](boost::system::error_code e) {
      if (!e) self->accept();
    });
  }

  // Closes the connection that has waited longest for a request header; false if none waits.
  bool make_room() {
    SessionPtr oldest;
    for (const auto& s : sessions)
      if (s->waiting && (!oldest || s->waiting_since < oldest->waiting_since)) oldest = s;
    if (!oldest) return false;
    close(oldest);
    return true;
  }

  void start_session(tcp::socket socket) {
    auto s = std::make_shared<Session>(std::move(socket));
    boost::system::error_code ec;
    const auto local = s->stream.socket().local_endpoint(ec);
    if (ec) return;  // the peer is already gone
    s->local_address = local.address().to_string();
    sessions.push_back(s);
    read_header(s);
  }

  void close(const SessionPtr& s) {
    if (s->closed) return;
    s->closed = true;
    s->waiting = false;
    boost::system::error_code ignored;
    s->stream.socket().shutdown(tcp::socket::shutdown_both, ignored);
    s->stream.close();
    sessions.remove(s);
  }

  void read_header(const SessionPtr& s) {
    s->header.emplace();
    s->header->header_limit(static_cast<std::uint32_t>(options.max_header_bytes));
    // The body's size is judged by screen(), after the Host and the token: not by the
    // parser's own default limit while it reads the header. (Not boost::none: Beast 1.74
    // compares the length with the optional itself, and any length is "over" an empty one.)
    s->header->body_limit(std::numeric_limits<std::uint64_t>::max());
    s->body.reset();
    s->waiting = true;
    s->waiting_since = Clock::now();
    s->stream.expires_after(options.request_timeout);
    http::async_read_header(s->stream, s->buffer, *s->header,
                            [self = shared_from_this(), s](beast::error_code ec, std::size_t) {
                              s->waiting = false;
                              if (s->closed) return;
                              if (ec) return self->read_failed(s, ec);
                              self->on_header(s);
                            });
  }

  void read_failed(const SessionPtr& s, const beast::error_code& ec) {
    if (ec == http::error::header_limit)
      return reply(s,
                   {431, json_error("request header over the " +
                                    std::to_string(options.max_header_bytes) + " byte limit")},
                   false);
    if (ec == http::error::body_limit)
      return reply(s,
                   {413, json_error("request body over the " +
                                    std::to_string(options.max_body_bytes) + " byte limit")},
                   false);
    if (is_parse_error(ec))
      return reply(s, {400, json_error("malformed HTTP request: " + ec.message())}, false);
    close(s);  // end of stream, timeout, reset: nothing to answer
  }

  void on_header(const SessionPtr& s) {
    const auto& h = s->header->get();
    if (auto refusal = screen(h, s->local_address, policy)) return reply(s, *refusal, false);
    if (is_websocket_request(h)) return upgrade(s);
    const bool expect_continue = beast::iequals(h[http::field::expect], "100-continue");
    s->body.emplace(std::move(*s->header));
    s->body->body_limit(options.max_body_bytes);
    if (!expect_continue) return read_body(s);
    // A client announcing its body waits for this before sending it (curl does above 1 KiB).
    auto cont = std::make_shared<http::response<http::empty_body>>(http::status::continue_, 11);
    http::async_write(s->stream, *cont,
                      [self = shared_from_this(), s, cont](beast::error_code ec, std::size_t) {
                        if (s->closed) return;
                        if (ec) return self->close(s);
                        self->read_body(s);
                      });
  }

  void read_body(const SessionPtr& s) {
    http::async_read(s->stream, s->buffer, *s->body,
                     [self = shared_from_this(), s](beast::error_code ec, std::size_t) {
                       if (s->closed) return;
                       if (ec) return self->read_failed(s, ec);
                       const auto req = s->body->release();
                       auto r = route(req, self->api);
                       if (r.deferred) return self->defer(s, std::move(r), req.keep_alive());
                       self->reply(s, std::move(r), req.keep_alive());
                     });
  }

  // The answer comes later, maybe from another thread: it is posted to the event loop, and
  // dropped if the connection was closed meanwhile (the server shutting down, make_room never
  // picks it: it waits for no request).
  void defer(const SessionPtr& s, Response r, bool keep_alive) {
    auto work = std::move(r.deferred);
    try {
      work([self = shared_from_this(), s, keep_alive](Response answer) {
        asio::post(self->io, [self, s, keep_alive, answer = std::move(answer)]() mutable {
          if (!s->closed) self->reply(s, std::move(answer), keep_alive);
        });
      });
    } catch (const std::exception& e) {
      reply(s, {500, json_error(e.what())}, false);
    }
  }

  // keep_alive false: the connection is closed after the answer (always so for a refusal,
  // whose body, if any, was not read).
  void reply(const SessionPtr& s, Response r, bool keep_alive) {
    auto& res = s->response;
    res = {};
    res.version(11);
    res.result(static_cast<http::status>(r.status));
    res.set(http::field::content_type, r.content_type);
    res.set(http::field::cache_control, "no-store");
    res.set("X-Content-Type-Options", "nosniff");
    res.set("Content-Security-Policy", "frame-ancestors 'none'");
    res.set("X-Frame-Options", "DENY");
    res.set("Referrer-Policy", "no-referrer");
    if (!r.disposition.empty()) res.set(http::field::content_disposition, r.disposition);
    res.keep_alive(keep_alive);
    res.body() = std::move(r.body);
    res.prepare_payload();
    s->stream.expires_after(options.request_timeout);  // a client that does not read
    http::async_write(s->stream, res,
                      [self = shared_from_this(), s](beast::error_code ec, std::size_t) {
                        if (s->closed) return;
                        if (ec) return self->close(s);
                        if (!s->response.keep_alive()) return self->linger(s);
                        self->read_header(s);
                      });
  }

  // Closing a socket with unread data makes the kernel reset the connection, which can
  // destroy the answer before the client reads it: stop sending, then read and drop what the
  // client still sends (at most until the request timeout) before closing.
  void linger(const SessionPtr& s) {
    boost::system::error_code ignored;
    s->stream.socket().shutdown(tcp::socket::shutdown_send, ignored);
    s->stream.async_read_some(asio::buffer(s->discard),
                              [self = shared_from_this(), s](beast::error_code ec, std::size_t) {
                                if (s->closed) return;
                                if (ec) return self->close(s);
                                self->linger_more(s);
                              });
  }
  void linger_more(const SessionPtr& s) {
    s->stream.async_read_some(asio::buffer(s->discard),
                              [self = shared_from_this(), s](beast::error_code ec, std::size_t) {
                                if (s->closed) return;
                                if (ec) return self->close(s);
                                self->linger_more(s);
                              });
  }

  void upgrade(const SessionPtr& s) {
    sessions.remove(s);
    s->closed = true;  // the connection now belongs to the WebSocket client
    auto client = std::make_shared<WsClient>(std::move(s->stream));
    beast::get_lowest_layer(client->ws).expires_never();  // the WebSocket times out by itself
    client->ws.set_option(
        websocket::stream_base::timeout{.handshake_timeout = options.request_timeout,
                                        .idle_timeout = options.websocket_idle_timeout,
                                        .keep_alive_pings = true});
    client->ws.read_message_max(4096);  // the page sends nothing; a client gets little room
    clients.push_back(client);
    client->ws.async_accept(s->header->get(),
                            [self = shared_from_this(), client, s](beast::error_code ec) {
                              if (ec) return self->clients.remove(client), void();
                              self->drain(client);
                              if (!self->latest.empty()) self->send(client);
                            });
  }

  // Reads (and ignores) client messages, so closes and pings are processed; a read error
  // (a close, a protocol violation, garbage, the idle timeout) removes the client.
  void drain(const std::shared_ptr<WsClient>& c) {
    auto buffer = std::make_shared<beast::flat_buffer>();
    c->ws.async_read(*buffer,
                     [self = shared_from_this(), c, buffer](beast::error_code ec, std::size_t) {
                       if (ec) return self->drop(c);
                       self->drain(c);
                     });
  }

  void drop(const std::shared_ptr<WsClient>& c) {
    clients.remove(c);
    boost::system::error_code ignored;
    beast::get_lowest_layer(c->ws).socket().close(ignored);
  }

  void send(const std::shared_ptr<WsClient>& c) {
    if (c->writing) return;  // at most one message in flight per client
    c->writing = true;
    c->outgoing = latest;
    c->ws.text(true);
    c->ws.async_write(asio::buffer(c->outgoing),
                      [self = shared_from_this(), c](beast::error_code ec, std::size_t) {
                        c->writing = false;
                        if (ec) return self->drop(c);
                        ++self->sent;
                      });
  }

  void tick() {
    timer.expires_after(options.push_period);
    timer.async_wait([self = shared_from_this()](boost::system::error_code ec) {
      if (ec) return;
      if (self->changed) {
        self->changed = false;
        for (auto& c : self->clients)
          if (c->ws.is_open()) self->send(c);
      }
      self->tick();
    });
  }

  void shutdown() {
    boost::system::error_code ignored;
    acceptor.close(ignored);
    timer.cancel();
    retry.cancel();
    while (!sessions.empty()) close(sessions.front());
    for (auto& c : clients) beast::get_lowest_layer(c->ws).close();
    clients.clear();
  }

  asio::io_context& io;
  tcp::acceptor acceptor;
  asio::steady_timer timer, retry;
  ServerOptions options;
  Policy policy;
  Api api;
  std::list<SessionPtr> sessions;
  std::list<std::shared_ptr<WsClient>> clients;
  std::string latest;
  bool changed = false;
  std::uint64_t sent = 0, refused = 0, accept_errors = 0;
  Clock::time_point last_accept_log{};
};

LiveServer::LiveServer(asio::io_context& io, ServerOptions options, Api api)
    : impl_(std::make_shared<Impl>(io, std::move(options), std::move(api))) {
  impl_->listen();
}
LiveServer::~LiveServer() { impl_->shutdown(); }
std::uint16_t LiveServer::port() const { return impl_->acceptor.local_endpoint().port(); }
void LiveServer::publish(std::string state_json) {
  if (state_json == impl_->latest) return;
  impl_->latest = std::move(state_json);
  impl_->changed = true;
}
std::size_t LiveServer::websocket_clients() const { return impl_->clients.size(); }
std::uint64_t LiveServer::messages_sent() const { return impl_->sent; }
std::size_t LiveServer::connections() const { return impl_->connections(); }

}  // namespace cal::daq::web
