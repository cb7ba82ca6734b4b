// The live server with a real HTTP/WebSocket client on loopback: routes, the token rule, and
// the WebSocket pushing only the latest state at its period.
#include "server.hpp"

#include <gtest/gtest.h>

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <functional>
#include <thread>

#include "assets.hpp"
#include "http_policy.hpp"

namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using cal::daq::web::LiveServer;
using namespace std::chrono_literals;

// The server runs on its own thread; the test is the client (synchronous Beast calls).
struct Running {
  asio::io_context io;
  std::unique_ptr<LiveServer> server;
  std::thread thread;
  asio::executor_work_guard<asio::io_context::executor_type> work = asio::make_work_guard(io);
  explicit Running(cal::daq::web::ServerOptions options, cal::daq::web::Api api = {}) {
    if (!api.runs) api.runs = [] { return cal::daq::web::Response{200, R"({"runs": [1, 2]})"}; };
    if (!api.page)
      api.page = [](std::string_view nonce) {
        return "<html><script nonce=\"" + std::string(nonce) + "\">live</script></html>";
      };
    if (!api.start)
      api.start = [](const std::string& body) {
        return cal::daq::web::Response{202, R"({"started": )" + body + "}"};
      };
    server = std::make_unique<LiveServer>(io, options, api);
    thread = std::thread([this] { io.run(); });
  }
  ~Running() {
    asio::post(io, [this] { server.reset(); });
    work.reset();
    io.stop();
    thread.join();
  }
  void publish(std::string s) {
    asio::post(io, [this, s = std::move(s)]() mutable { server->publish(std::move(s)); });
  }
};

http::response<http::string_body> request(std::uint16_t port, http::verb verb, std::string target,
                                          std::string auth = {}, std::string body = {}) {
  asio::io_context io;
  tcp::socket socket(io);
  socket.connect({asio::ip::address_v4::loopback(), port});
  http::request<http::string_body> req{verb, target, 11};
  req.set(http::field::host, "localhost");
  if (verb == http::verb::post) req.set(http::field::content_type, "application/json");
  if (!auth.empty()) req.set(http::field::authorization, auth);
  req.body() = std::move(body);
  req.prepare_payload();
  http::write(socket, req);
  beast::flat_buffer buffer;
  http::response<http::string_body> res;
  http::read(socket, buffer, res);
  return res;
}

TEST(LiveServer, ServesThePageAndTheApi) {
  Running r({.port = 0});
  const auto port = r.server->port();
  auto page = request(port, http::verb::get, "/");
  EXPECT_EQ(page.result_int(), 200);
  EXPECT_TRUE(page.body().starts_with("<html><script nonce=\"")) << page.body();
  EXPECT_EQ(page[http::field::content_type], "text/html; charset=utf-8");
  EXPECT_EQ(request(port, http::verb::get, "/api/runs").body(), R"({"runs": [1, 2]})");
  auto started = request(port, http::verb::post, "/api/runs/start", {}, R"({"kind": "linear"})");
  EXPECT_EQ(started.result_int(), 202);
  EXPECT_EQ(started.body(), R"({"started": {"kind": "linear"}})");
  EXPECT_EQ(request(port, http::verb::get, "/nope").result_int(), 404);
  EXPECT_EQ(request(port, http::verb::get, "/api/runs/start").result_int(), 404);  // GET != POST
}

// The page's policy allows its own script by a nonce that is new for every answer; the nonce
// in the policy is the one the page's script elements carry.
TEST(LiveServer, ThePageRunsOnlyItsOwnScript) {
  Running r({.port = 0});
  const auto port = r.server->port();
  const auto nonce_of = [&] {
    const auto page = request(port, http::verb::get, "/");
    const std::string csp(page["Content-Security-Policy"]);
    EXPECT_NE(csp.find("default-src 'none'"), std::string::npos) << csp;
    EXPECT_NE(csp.find("frame-ancestors 'none'"), std::string::npos) << csp;
    EXPECT_EQ(csp.find("unsafe-eval"), std::string::npos) << csp;
    const auto at = csp.find("script-src 'nonce-");
    EXPECT_NE(at, std::string::npos) << csp;
    const auto start = at + std::string_view("script-src 'nonce-").size();
    const auto nonce = csp.substr(start, csp.find('\'', start) - start);
    EXPECT_GE(nonce.size(), 22u);
    EXPECT_NE(page.body().find("<script nonce=\"" + nonce + "\">"), std::string::npos);
    return nonce;
  };
  EXPECT_NE(nonce_of(), nonce_of());
  // The page itself: every script element carries it.
  const auto page = cal::daq::web::operator_page("N0NCE");
  EXPECT_EQ(page.find("<script>"), std::string::npos);
  EXPECT_NE(page.find("<script nonce=\"N0NCE\">"), std::string::npos);
}

// HEAD answers as GET without the body: the same status and Content-Length.
TEST(LiveServer, HeadIsGetWithoutTheBody) {
  Running r({.port = 0});
  const auto port = r.server->port();
  asio::io_context io;
  tcp::socket socket(io);
  socket.connect({asio::ip::address_v4::loopback(), port});
  http::request<http::empty_body> req{http::verb::head, "/api/runs", 11};
  req.set(http::field::host, "localhost");
  http::write(socket, req);
  beast::flat_buffer buffer;
  http::response_parser<http::string_body> parser;
  parser.skip(true);  // a HEAD answer has no body whatever its Content-Length says
  http::read(socket, buffer, parser);
  EXPECT_EQ(parser.get().result_int(), 200);
  EXPECT_EQ(parser.get()[http::field::content_length], "16");  // {"runs": [1, 2]}
  EXPECT_TRUE(parser.get().body().empty());
  // The connection goes on: the next request is answered whole.
  http::request<http::empty_body> get{http::verb::get, "/api/runs", 11};
  get.set(http::field::host, "localhost");
  http::write(socket, get);
  http::response<http::string_body> res;
  http::read(socket, buffer, res);
  EXPECT_EQ(res.body(), R"({"runs": [1, 2]})");
}

TEST(LiveServer, AnotherAddressNeedsAToken) {
  asio::io_context io;
  EXPECT_THROW(LiveServer(io, {.address = "0.0.0.0", .port = 0}, {}), std::invalid_argument);
  try {
    LiveServer(io, {.address = "0.0.0.0", .port = 0}, {});
  } catch (const std::invalid_argument& e) {
    // The command adds its own name; the server does not (no "daq serve: daq serve:").
    EXPECT_EQ(std::string(e.what()).find("daq serve"), std::string::npos) << e.what();
  }
  EXPECT_EQ(cal::daq::web::host_port("::1", 8080), "[::1]:8080");
  EXPECT_EQ(cal::daq::web::host_port("127.0.0.1", 8080), "127.0.0.1:8080");
}

TEST(LiveServer, TokenIsRequiredWhenSet) {
  Running r({.port = 0, .token = "s3cret"});
  const auto port = r.server->port();
  EXPECT_EQ(request(port, http::verb::get, "/api/runs").result_int(), 401);
  EXPECT_EQ(request(port, http::verb::get, "/api/runs", "Bearer wrong!").result_int(), 401);
  EXPECT_EQ(request(port, http::verb::get, "/api/runs", "Bearer s3cret").result_int(), 200);
  EXPECT_EQ(request(port, http::verb::get, "/?token=s3cret").result_int(), 200);
}

TEST(LiveServer, WebSocketGetsTheLatestStateNotAQueue) {
  Running r({.port = 0, .push_period = 50ms});
  asio::io_context io;
  websocket::stream<tcp::socket> ws(io);
  ws.next_layer().connect({asio::ip::address_v4::loopback(), r.server->port()});
  ws.handshake("localhost", "/ws");
  // 1000 states published faster than the period: the client sees the last, and only a few
  // messages in all (one per period at most), never 1000.
  for (int i = 0; i < 1000; ++i) r.publish(R"({"reading_um": )" + std::to_string(i) + "}");
  std::this_thread::sleep_for(150ms);
  r.publish(R"({"reading_um": 1000})");
  std::string last;
  int messages = 0;
  while (last != R"({"reading_um": 1000})") {
    beast::flat_buffer buffer;
    ws.read(buffer);
    last = beast::buffers_to_string(buffer.data());
    ++messages;
    ASSERT_LT(messages, 10) << last;
  }
  EXPECT_LE(messages, 4);
  ws.close(websocket::close_code::normal);
}

// A state that does not change is sent again at the keep-alive period: the page turns its values
// into dashes after 2 s without a message, so silence must mean a dead or hung service, never
// an idle one.
TEST(LiveServer, UnchangedStateIsResentAtTheKeepAlivePeriod) {
  Running r({.port = 0, .push_period = 20ms, .keepalive_period = 200ms});
  asio::io_context io;
  websocket::stream<tcp::socket> ws(io);
  ws.next_layer().connect({asio::ip::address_v4::loopback(), r.server->port()});
  ws.handshake("localhost", "/ws");
  r.publish(R"({"same": 1})");
  int messages = 0;
  std::string last;
  const auto start = std::chrono::steady_clock::now();
  beast::flat_buffer buffer;
  std::function<void(beast::error_code, std::size_t)> on_read = [&](beast::error_code ec,
                                                                    std::size_t) {
    if (ec) return;
    last = beast::buffers_to_string(buffer.data());
    buffer.consume(buffer.size());
    if (++messages < 3) ws.async_read(buffer, on_read);
  };
  ws.async_read(buffer, on_read);
  io.run_for(2s);  // three messages at 200 ms need about 0.4 s; none after the first before
  const auto took = std::chrono::steady_clock::now() - start;
  EXPECT_EQ(messages, 3) << "the unchanged state was not sent again";
  EXPECT_EQ(last, R"({"same": 1})");
  EXPECT_LT(took, 1500ms);
}

TEST(OperatorPage, IsOneSelfContainedDocument) {
  // The chart library, its style and the page's strings are inlined: no external script,
  // style or font, so the page works on a machine-shop PC without internet.
  const std::string page = cal::daq::web::operator_page();
  EXPECT_EQ(page.find("/*UPLOT_JS*/"), std::string::npos);
  EXPECT_EQ(page.find("/*UPLOT_CSS*/"), std::string::npos);
  EXPECT_EQ(page.find("/*STRINGS*/"), std::string::npos);
  EXPECT_NE(page.find(R"("tab.setup": "Set-up")"), std::string::npos);
  EXPECT_NE(page.find("uPlot"), std::string::npos);
  EXPECT_GT(page.size(), 50'000u);  // uPlot.iife.min.js alone is 51 kB
  EXPECT_EQ(page.find("<script src="), std::string::npos);
  EXPECT_EQ(page.find("<link"), std::string::npos);
  EXPECT_NE(page.find("new WebSocket"), std::string::npos);
  EXPECT_EQ(page.find("/*PRESENT_JS*/"), std::string::npos);
  EXPECT_EQ(page.find("/*UNIT_SIGNS*/"), std::string::npos);
}

// The units' signs given by the service reach both pages with the presentation they share
// (daq/web/present.js), which is in each page once.
TEST(OperatorPage, BothPagesShareThePresentationAndItsUnits) {
  const std::string signs = R"([["urad","µrad"]])";
  for (const std::string& page :
       {cal::daq::web::operator_page("N", signs), cal::daq::web::fleet_page("N", signs)}) {
    EXPECT_NE(page.find("const UNIT_SIGNS = " + signs + ";"), std::string::npos);
    const auto at = page.find("const present = ");
    ASSERT_NE(at, std::string::npos);
    EXPECT_EQ(page.find("const present = ", at + 1), std::string::npos);
    EXPECT_EQ(page.find("/*PRESENT_JS*/"), std::string::npos);
    EXPECT_EQ(page.find("<script>"), std::string::npos);  // every script with its nonce
  }
}

// The request rules (http_policy.hpp) apart from the sockets; the hostile-client suite
// (hostile_serve_test.py) checks them again against a real daq serve.
namespace web = cal::daq::web;

web::Header header(http::verb verb, const std::string& target,
                   std::initializer_list<std::pair<http::field, std::string>> fields) {
  web::Header h;
  h.method(verb);
  h.target(target);
  h.version(11);
  for (const auto& [f, v] : fields) h.set(f, v);
  return h;
}

int screened(const web::Header& h, const web::Policy& p = {}) {
  const auto r = web::screen(h, "127.0.0.1", p);
  return r ? r->status : 0;
}

TEST(HttpPolicy, TokensCompareWhateverTheirLengths) {
  EXPECT_TRUE(web::same_token("s3cret", "s3cret"));
  EXPECT_FALSE(web::same_token("s3creT", "s3cret"));
  EXPECT_FALSE(web::same_token("s3cre", "s3cret"));         // a prefix
  EXPECT_FALSE(web::same_token("s3crets3cret", "s3cret"));  // the token twice
  EXPECT_FALSE(web::same_token("", "s3cret"));
  EXPECT_FALSE(web::same_token("", ""));  // an empty token never authorises
  EXPECT_FALSE(web::same_token(std::string("s3cret\0", 7), "s3cret"));
}

TEST(HttpPolicy, QueryParameterIsTheWholeNameAndDecoded) {
  EXPECT_EQ(web::query_parameter("/ws?token=a%2Bb%20c", "token"), "a+b c");
  EXPECT_EQ(web::query_parameter("/?x=1&token=t&y=2", "token"), "t");
  EXPECT_EQ(web::query_parameter("/?xtoken=t", "token"), std::nullopt);
  EXPECT_EQ(web::query_parameter("/?token", "token"), "");
  EXPECT_EQ(web::query_parameter("/token=t", "token"), std::nullopt);  // no query at all
  EXPECT_EQ(web::query_parameter("/?token=%zz%4", "token"), "%zz%4");  // bad escapes kept
}

// A path segment (the fleet view's site, encodeURIComponent'd): '+' is itself there, not a space.
TEST(HttpPolicy, PercentDecodedPathKeepsPlus) {
  EXPECT_EQ(web::percent_decoded("Plant%20North%2FHall+B", false), "Plant North/Hall+B");
  EXPECT_EQ(web::percent_decoded("Plant%20North%2FHall+B", true), "Plant North/Hall B");
  EXPECT_EQ(web::percent_decoded("%C3%A9%zz%4", false), "\xc3\xa9%zz%4");  // é; bad escapes kept
  EXPECT_EQ(web::percent_decoded("", false), "");
}

TEST(HttpPolicy, HostMustBeThisServer) {
  const web::Policy p{.allowed_hosts = {"Machine.Local"}};
  for (const char* ok :
       {"127.0.0.1", "127.0.0.1:8080", "localhost", "LOCALHOST:1", "machine.local:8080"})
    EXPECT_TRUE(web::host_allowed(ok, "127.0.0.1", p)) << ok;
  for (const char* bad : {"evil.example", "127.0.0.1.evil.example", "localhost.", "", ":8080",
                          "127.0.0.1:80a", "127.0.0.1:", "[::1]", "localhost:123456", "127.0.0.2"})
    EXPECT_FALSE(web::host_allowed(bad, "127.0.0.1", p)) << bad;
  EXPECT_TRUE(web::host_allowed("[::1]:8080", "::1", p));
}

TEST(HttpPolicy, ScreensCrossSiteAndMistypedRequests) {
  using F = http::field;
  const std::string host = "127.0.0.1:8080";
  EXPECT_EQ(screened(header(http::verb::get, "/api/runs", {{F::host, host}})), 0);
  EXPECT_EQ(screened(header(http::verb::get, "/api/runs", {{F::host, "evil.example"}})), 403);
  EXPECT_EQ(screened(header(http::verb::get, "/api/runs", {})), 403);  // no Host
  // A foreign Origin on anything, "null" included; the page's own is fine.
  EXPECT_EQ(
      screened(header(http::verb::get, "/", {{F::host, host}, {F::origin, "http://evil.example"}})),
      403);
  EXPECT_EQ(screened(header(
                http::verb::post, "/api/runs/stop",
                {{F::host, host}, {F::origin, "null"}, {F::content_type, "application/json"}})),
            403);
  EXPECT_EQ(screened(header(http::verb::post, "/api/runs/stop",
                            {{F::host, host},
                             {F::origin, "http://127.0.0.1:8080"},
                             {F::content_type, "Application/JSON; charset=utf-8"}})),
            0);
  // A CORS "simple request" (text/plain, form types, none) is refused: 415.
  for (const char* type : {"text/plain", "application/x-www-form-urlencoded",
                           "multipart/form-data; boundary=x", "application/jsonx", ""})
    EXPECT_EQ(screened(header(http::verb::post, "/api/runs/start",
                              {{F::host, host}, {F::content_type, type}})),
              415)
        << type;
  // Sizes are decided from the header: 413 before a body byte is read.
  EXPECT_EQ(screened(header(http::verb::post, "/api/runs/start",
                            {{F::host, host},
                             {F::content_type, "application/json"},
                             {F::content_length, "100000000"}})),
            413);
  // With a token: 401 without it, whatever else the request has right.
  const web::Policy tok{.token = "t0k"};
  EXPECT_EQ(screened(header(http::verb::get, "/", {{F::host, host}}), tok), 401);
  EXPECT_EQ(
      screened(header(http::verb::get, "/", {{F::host, host}, {F::authorization, "bEaReR t0k"}}),
               tok),
      0);
  EXPECT_EQ(screened(header(http::verb::get, "/?token=t0k", {{F::host, host}}), tok), 0);
  EXPECT_EQ(
      screened(header(http::verb::get, "/", {{F::host, host}, {F::authorization, "Basic t0k"}}),
               tok),
      401);
}

TEST(HttpPolicy, HandlersThatThrowGive500NotACrash) {
  const web::Api api{
      .runs = []() -> web::Response { throw std::runtime_error("db.sqlite: locked"); }};
  web::Request req{http::verb::get, "/api/runs", 11};
  const auto r = web::route(req, api);
  EXPECT_EQ(r.status, 500);
  EXPECT_EQ(r.body, R"({"error": "db.sqlite: locked"})");
  EXPECT_EQ(web::json_error("a\"b\\c\n\x01"), R"({"error": "a\"b\\c\u000a\u0001"})");
}

}  // namespace
