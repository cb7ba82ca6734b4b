// The live server with a real HTTP/WebSocket client on loopback: routes, the token rule, and
// the WebSocket pushing only the latest state at its period.
#include "server.hpp"

#include "assets.hpp"

#include <gtest/gtest.h>

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <thread>

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
    if (!api.page) api.page = [] { return std::string("<html>live</html>"); };
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
  EXPECT_EQ(page.body(), "<html>live</html>");
  EXPECT_EQ(page[http::field::content_type], "text/html; charset=utf-8");
  EXPECT_EQ(request(port, http::verb::get, "/api/runs").body(), R"({"runs": [1, 2]})");
  auto started = request(port, http::verb::post, "/api/runs/start", {}, R"({"kind": "linear"})");
  EXPECT_EQ(started.result_int(), 202);
  EXPECT_EQ(started.body(), R"({"started": {"kind": "linear"}})");
  EXPECT_EQ(request(port, http::verb::get, "/nope").result_int(), 404);
  EXPECT_EQ(request(port, http::verb::get, "/api/runs/start").result_int(), 404);  // GET != POST
}

TEST(LiveServer, AnotherAddressNeedsAToken) {
  asio::io_context io;
  EXPECT_THROW(LiveServer(io, {.address = "0.0.0.0", .port = 0}, {}), std::invalid_argument);
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

TEST(LivePage, IsOneSelfContainedDocument) {
  // The chart library and its style are inlined: no external script, style or font, so the
  // page works on a machine-shop PC without internet.
  const std::string page = cal::daq::web::live_page();
  EXPECT_EQ(page.find("/*UPLOT_JS*/"), std::string::npos);
  EXPECT_EQ(page.find("/*UPLOT_CSS*/"), std::string::npos);
  EXPECT_NE(page.find("uPlot"), std::string::npos);
  EXPECT_GT(page.size(), 50'000u);  // uPlot.iife.min.js alone is 51 kB
  EXPECT_EQ(page.find("<script src="), std::string::npos);
  EXPECT_EQ(page.find("<link"), std::string::npos);
  EXPECT_NE(page.find("new WebSocket"), std::string::npos);
}

}  // namespace
