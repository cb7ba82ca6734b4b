// Beast HTTP + WebSocket server for the live readout (see server.hpp; the request rules are in
// http_policy.cpp).
#include "server.hpp"

#include <algorithm>
#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <limits>
#include <list>
#include <optional>
#include <stdexcept>
#include <tuple>

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
    WsClient(beast::tcp_stream s, std::string from, bool origin)
        : ws(std::move(s)), remote(std::move(from)), page_origin(origin) {}
    websocket::stream<beast::tcp_stream> ws;
    std::string outgoing;
    bool writing = false;
    std::string remote;        // the peer's address
    bool page_origin = false;  // the handshake carried the page's Origin (as browsers send)
    Clock::time_point opened = Clock::now(), write_started;
  };
  using ClientPtr = std::shared_ptr<WsClient>;

  // One HTTP connection; several requests one after the other (keep-alive).
  struct Session {
    Session(tcp::socket s, std::string from) : stream(std::move(s)), remote(std::move(from)) {}
    beast::tcp_stream stream;
    beast::flat_buffer buffer;
    std::optional<http::request_parser<http::empty_body>> header;
    std::optional<http::request_parser<http::string_body>> body;
    http::response<http::string_body> response;
    std::string local_address;
    std::string remote;  // the peer's address
    // What it waits for, and since when: the order in which connections are closed for room.
    enum class Phase { request, answer, closing } phase = Phase::request;
    Clock::time_point since = Clock::now();
    bool closed = false;
    std::array<char, 4096> discard{};
  };
  using SessionPtr = std::shared_ptr<Session>;

  // A connection that may be closed to make room, ranked: the lowest rank goes first, and
  // within a rank the lowest order (the time since which it has made no progress; for a
  // WebSocket that reads and has the page's Origin, the newest first, so an established page
  // keeps its live view).
  struct Victim {
    int rank = 0;
    Clock::rep order = 0;
    SessionPtr session;
    ClientPtr client;
  };

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
      throw std::invalid_argument("binding to " + options.address +
                                  " (not loopback) needs --token");
    boost::system::error_code ec;
    const tcp::endpoint ep(asio::ip::make_address(options.address, ec), options.port);
    if (ec) throw std::invalid_argument("bad address '" + options.address + "'");
    acceptor.open(ep.protocol(), ec);
    if (!ec) acceptor.set_option(asio::socket_base::reuse_address(true), ec);
    if (!ec) acceptor.bind(ep, ec);
    if (!ec) acceptor.listen(asio::socket_base::max_listen_connections, ec);
    if (ec)
      throw std::runtime_error("cannot listen on " + host_port(options.address, options.port) +
                               ": " + ec.message());
    accept();
    tick();
  }

  void log(const std::string& text) const {
    if (options.log) options.log(text);
  }

  std::size_t connections() const { return sessions.size() + clients.size(); }

  // Connections (HTTP and WebSocket) and WebSockets from one address.
  std::size_t connections_from(std::string_view remote) const {
    return static_cast<std::size_t>(
               std::count_if(sessions.begin(), sessions.end(),
                             [&](const SessionPtr& s) { return s->remote == remote; })) +
           websockets_from(remote);
  }
  std::size_t websockets_from(std::string_view remote) const {
    return static_cast<std::size_t>(std::count_if(
        clients.begin(), clients.end(), [&](const ClientPtr& c) { return c->remote == remote; }));
  }
  std::size_t max_websockets() const {
    return std::max<std::size_t>(1, options.max_connections / 2);
  }

  // The accept loop is re-armed after every error. Out of descriptors (EMFILE, ENFILE) or
  // buffers, it closes the stalest connection and retries after a pause, rather than spinning
  // on an error the kernel repeats at once.
  void accept() {
    acceptor.async_accept([self = shared_from_this()](boost::system::error_code ec, tcp::socket s) {
      if (!self->acceptor.is_open() || ec == asio::error::operation_aborted) return;
      if (ec) return self->accept_failed(ec);
      self->admit(std::move(s));
      self->accept();
    });
  }

  // A new connection gets room: its address' stalest connection is closed when the address
  // is at its own cap, and the stalest of all at the overall cap.
  void admit(tcp::socket s) {
    boost::system::error_code ec;
    const auto peer = s.remote_endpoint(ec);
    if (ec) return;  // the peer is already gone
    const auto remote = peer.address().to_string();
    bool room = true;
    if (connections_from(remote) >= options.max_connections_per_client)
      room = make_room(remote, false);
    if (room && connections() >= options.max_connections) room = make_room({}, false);
    if (!room) {
      s.close(ec);  // nothing can be closed for it (cannot happen with the caps above 0)
      ++refused;
      return;
    }
    start_session(std::move(s), remote);
  }

  void accept_failed(const boost::system::error_code& ec) {
    ++accept_errors;
    const auto now = Clock::now();
    if (now - last_accept_log > std::chrono::seconds(10)) {
      log("accept failed (" + ec.message() + "); retrying (" + std::to_string(accept_errors) +
          " accept errors so far)");
      last_accept_log = now;
    }
    make_room({}, false);
    retry.expires_after(std::chrono::milliseconds(50));
    retry.async_wait([self = shared_from_this()](boost::system::error_code e) {
      if (!e) self->accept();
    });
  }

  // Closes the stalest connection (of `from`, if given; WebSockets only, if asked); false if
  // there is none. The order (server.hpp): being closed after a refusal; an HTTP connection
  // waiting for (the rest of) a request; one whose answer is pending or not read; then a
  // WebSocket that does not read its messages, one without the page's Origin, the newest.
  bool make_room(std::string_view from, bool websockets_only) {
    std::optional<Victim> worst;
    const auto consider = [&](Victim v) {
      if (!worst || std::tie(v.rank, v.order) < std::tie(worst->rank, worst->order)) worst = v;
    };
    const auto ticks = [](Clock::time_point t) { return t.time_since_epoch().count(); };
    if (!websockets_only)
      for (const auto& s : sessions)
        if (from.empty() || s->remote == from) consider({rank_of(*s), ticks(s->since), s, {}});
    const auto now = Clock::now();
    for (const auto& c : clients) {
      if (!from.empty() && c->remote != from) continue;
      if (c->writing && now - c->write_started > stall_after)
        consider({3, ticks(c->write_started), {}, c});
      else
        consider(
            {c->page_origin ? 5 : 4, c->page_origin ? -ticks(c->opened) : ticks(c->opened), {}, c});
    }
    if (!worst) return false;
    if (worst->session) close(worst->session);
    if (worst->client) drop(worst->client);
    ++evicted;
    return true;
  }

  static int rank_of(const Session& s) {
    switch (s.phase) {
      case Session::Phase::closing:
        return 0;
      case Session::Phase::request:
        return 1;
      case Session::Phase::answer:
        return 2;
    }
    return 2;
  }

  void start_session(tcp::socket socket, std::string remote) {
    auto s = std::make_shared<Session>(std::move(socket), std::move(remote));
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
    s->phase = Session::Phase::request;
    s->since = Clock::now();
    // The header and the body together must arrive within this: a slow body is cut off as a
    // slow header is (the body is read under the same expiry).
    s->stream.expires_after(options.request_timeout);
    http::async_read_header(s->stream, s->buffer, *s->header,
                            [self = shared_from_this(), s](beast::error_code ec, std::size_t) {
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
                       s->phase = Session::Phase::answer;
                       auto r = route(req, self->api);
                       if (r.deferred) return self->defer(s, std::move(r), req.keep_alive());
                       self->reply(s, std::move(r), req.keep_alive(),
                                   req.method() == http::verb::head);
                     });
  }

  // The answer comes later, maybe from another thread: it is posted to the event loop, and
  // dropped if the connection was closed meanwhile (the server shutting down, or the
  // connection closed for room).
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
  // whose body, if any, was not read). head: the header alone (its Content-Length as GET's).
  void reply(const SessionPtr& s, Response r, bool keep_alive, bool head = false) {
    s->phase = Session::Phase::answer;
    auto& res = s->response;
    res = {};
    res.version(11);
    res.result(static_cast<http::status>(r.status));
    res.set(http::field::content_type, r.content_type);
    res.set(http::field::cache_control, "no-store");
    res.set("X-Content-Type-Options", "nosniff");
    res.set("Content-Security-Policy", r.content_security_policy.empty()
                                           ? std::string("frame-ancestors 'none'")
                                           : r.content_security_policy);
    res.set("X-Frame-Options", "DENY");
    res.set("Referrer-Policy", "no-referrer");
    if (!r.disposition.empty()) res.set(http::field::content_disposition, r.disposition);
    res.keep_alive(keep_alive);
    res.body() = std::move(r.body);
    res.prepare_payload();
    if (head) {
      const auto length = res.body().size();
      res.body().clear();
      res.content_length(length);
    }
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
  // client still sends (at most 2 s, or the request timeout if shorter) before closing. Such
  // a connection is the first closed for room.
  void linger(const SessionPtr& s) {
    s->phase = Session::Phase::closing;
    s->since = Clock::now();
    s->stream.expires_after(std::min<Clock::duration>(options.request_timeout, max_linger));
    boost::system::error_code ignored;
    s->stream.socket().shutdown(tcp::socket::shutdown_send, ignored);
    linger_more(s);
  }
  // Reads and drops one piece of what the client still sends, until the client closes, an
  // error, or the time-out set by linger.
  void linger_more(const SessionPtr& s) {
    s->stream.async_read_some(asio::buffer(s->discard),
                              [self = shared_from_this(), s](beast::error_code ec, std::size_t) {
                                if (s->closed) return;
                                if (ec) return self->close(s);
                                self->linger_more(s);
                              });
  }

  // A WebSocket from an address at its WebSocket cap replaces that address' stalest one, and
  // at the overall WebSocket cap the stalest of all: WebSockets never take more than half of
  // the connections, and a new page always gets its live view.
  void upgrade(const SessionPtr& s) {
    sessions.remove(s);
    s->closed = true;  // the connection now belongs to the WebSocket client
    if (websockets_from(s->remote) >= options.max_websockets_per_client) make_room(s->remote, true);
    if (clients.size() >= max_websockets()) make_room({}, true);
    const auto& h = s->header->get();
    auto client = std::make_shared<WsClient>(std::move(s->stream), s->remote,
                                             h.find(http::field::origin) != h.end());
    beast::get_lowest_layer(client->ws).expires_never();  // the WebSocket times out by itself
    client->ws.set_option(
        websocket::stream_base::timeout{.handshake_timeout = options.request_timeout,
                                        .idle_timeout = options.websocket_idle_timeout,
                                        .keep_alive_pings = true});
    client->ws.read_message_max(4096);  // the page sends nothing; a client gets little room
    clients.push_back(client);
    client->ws.async_accept(s->header->get(),
                            [self = shared_from_this(), client, s](beast::error_code ec) {
                              if (ec) return self->drop(client);
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
    c->write_started = Clock::now();
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
      const auto now = Clock::now();
      const bool keepalive =
          !self->latest.empty() && now - self->last_push >= self->options.keepalive_period;
      if (self->changed || keepalive) {
        self->changed = false;
        self->last_push = now;
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
  Clock::time_point last_push{};  // the latest state's last push to the clients
  std::uint64_t sent = 0, refused = 0, accept_errors = 0, evicted = 0;
  // A WebSocket whose message has been in flight this long does not read: the first closed.
  static constexpr auto stall_after = std::chrono::seconds(1);
  static constexpr auto max_linger = std::chrono::seconds(2);
  Clock::time_point last_accept_log{};
};

std::string host_port(std::string_view address, std::uint16_t port) {
  const std::string a(address);
  return (a.find(':') != std::string::npos ? "[" + a + "]" : a) + ":" + std::to_string(port);
}

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
std::uint64_t LiveServer::evicted() const { return impl_->evicted; }

}  // namespace cal::daq::web
