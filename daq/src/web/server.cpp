// Beast HTTP + WebSocket server for the live readout (see server.hpp).
#include "server.hpp"

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <list>
#include <stdexcept>

namespace cal::daq::web {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;

// Beast 1.74 speaks boost::string_view; the rest of the code std::string_view.
std::string_view sv(beast::string_view s) { return {s.data(), s.size()}; }

bool is_loopback(const std::string& address) {
  boost::system::error_code ec;
  const auto a = asio::ip::make_address(address, ec);
  return !ec && a.is_loopback();
}

// Constant-time comparison: the token must not leak through response timing.
bool same_token(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  unsigned char diff = 0;
  for (std::size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ b[i]);
  return diff == 0;
}

std::string query_token(std::string_view target) {
  const auto q = target.find("token=");
  if (q == std::string_view::npos) return {};
  const auto end = target.find('&', q);
  return std::string(target.substr(q + 6, end == std::string_view::npos ? end : end - q - 6));
}

}  // namespace

struct LiveServer::Impl : std::enable_shared_from_this<LiveServer::Impl> {
  struct WsClient {
    explicit WsClient(tcp::socket s) : ws(std::move(s)) {}
    websocket::stream<tcp::socket> ws;
    std::string outgoing;
    bool writing = false;
  };

  Impl(asio::io_context& io, ServerOptions o, Api a)
      : acceptor(io), timer(io), options(std::move(o)), api(std::move(a)) {}

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

  void accept() {
    acceptor.async_accept([self = shared_from_this()](boost::system::error_code ec, tcp::socket s) {
      if (ec) return;
      self->read_request(std::make_shared<tcp::socket>(std::move(s)));
      self->accept();
    });
  }

  struct HttpSession {
    explicit HttpSession(std::shared_ptr<tcp::socket> s) : socket(std::move(s)) {}
    std::shared_ptr<tcp::socket> socket;
    beast::flat_buffer buffer;
    http::request<http::string_body> request;
    http::response<http::string_body> response;
  };

  void read_request(std::shared_ptr<tcp::socket> socket) {
    auto session = std::make_shared<HttpSession>(std::move(socket));
    http::async_read(*session->socket, session->buffer, session->request,
                     [self = shared_from_this(), session](beast::error_code ec, std::size_t) {
                       if (ec) return;
                       self->handle(session);
                     });
  }

  bool authorised(const http::request<http::string_body>& req) const {
    if (options.token.empty()) return true;
    const std::string_view auth = sv(req[http::field::authorization]);
    if (auth.starts_with("Bearer ") && same_token(auth.substr(7), options.token)) return true;
    return same_token(query_token(sv(req.target())), options.token);
  }

  void handle(const std::shared_ptr<HttpSession>& s) {
    auto& req = s->request;
    if (!authorised(req))
      return reply(s, 401, R"({"error": "missing or wrong token"})", "application/json");
    const std::string_view target = sv(req.target());
    const std::string_view path = target.substr(0, target.find('?'));
    if (websocket::is_upgrade(req) && path == "/ws") return upgrade(s);
    const bool get = req.method() == http::verb::get, post = req.method() == http::verb::post;
    auto json = [&](const Response& r) { reply(s, r.status, r.body, "application/json"); };
    if (get && path == "/" && api.page)
      return reply(s, 200, api.page(), "text/html; charset=utf-8");
    if (get && path == "/api/runs" && api.runs) return json(api.runs());
    if (get && path == "/api/status" && api.status) return json(api.status());
    if (post && path == "/api/runs/start" && api.start) return json(api.start(req.body()));
    if (post && path == "/api/runs/stop" && api.stop) return json(api.stop());
    reply(s, 404, R"({"error": "no such resource"})", "application/json");
  }

  void reply(const std::shared_ptr<HttpSession>& s, int status, std::string body,
             std::string_view type) {
    auto& res = s->response;
    res.version(s->request.version());
    res.result(static_cast<http::status>(status));
    res.set(http::field::content_type, beast::string_view(type.data(), type.size()));
    res.set(http::field::cache_control, "no-store");
    res.keep_alive(s->request.keep_alive());
    res.body() = std::move(body);
    res.prepare_payload();
    http::async_write(*s->socket, res,
                      [self = shared_from_this(), s](beast::error_code ec, std::size_t) {
                        if (ec || !s->response.keep_alive()) {
                          boost::system::error_code ignored;
                          s->socket->shutdown(tcp::socket::shutdown_send, ignored);
                          return;
                        }
                        self->read_request(s->socket);
                      });
  }

  void upgrade(const std::shared_ptr<HttpSession>& s) {
    auto client = std::make_shared<WsClient>(std::move(*s->socket));
    client->ws.async_accept(s->request,
                            [self = shared_from_this(), client, s](beast::error_code ec) {
                              if (ec) return;
                              self->clients.push_back(client);
                              self->drain(client);
                              if (!self->latest.empty()) self->send(client);
                            });
  }

  // Reads (and ignores) client messages, so closes and pings are processed; a read error
  // removes the client.
  void drain(const std::shared_ptr<WsClient>& c) {
    auto buffer = std::make_shared<beast::flat_buffer>();
    c->ws.async_read(*buffer,
                     [self = shared_from_this(), c, buffer](beast::error_code ec, std::size_t) {
                       if (ec) return self->clients.remove(c), void();
                       self->drain(c);
                     });
  }

  void send(const std::shared_ptr<WsClient>& c) {
    if (c->writing) return;  // at most one message in flight per client
    c->writing = true;
    c->outgoing = latest;
    c->ws.text(true);
    c->ws.async_write(asio::buffer(c->outgoing),
                      [self = shared_from_this(), c](beast::error_code ec, std::size_t) {
                        c->writing = false;
                        if (ec) return self->clients.remove(c), void();
                        ++self->sent;
                      });
  }

  void tick() {
    timer.expires_after(options.push_period);
    timer.async_wait([self = shared_from_this()](boost::system::error_code ec) {
      if (ec) return;
      if (self->changed) {
        self->changed = false;
        for (auto& c : self->clients) self->send(c);
      }
      self->tick();
    });
  }

  void shutdown() {
    boost::system::error_code ignored;
    acceptor.close(ignored);
    timer.cancel();
    for (auto& c : clients) beast::get_lowest_layer(c->ws).close(ignored);
    clients.clear();
  }

  tcp::acceptor acceptor;
  asio::steady_timer timer;
  ServerOptions options;
  Api api;
  std::list<std::shared_ptr<WsClient>> clients;
  std::string latest;
  bool changed = false;
  std::uint64_t sent = 0;
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

}  // namespace cal::daq::web
