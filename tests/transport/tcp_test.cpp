// The TCP transport against a loopback server played by the test.
#include <gtest/gtest.h>

#include <boost/asio.hpp>
#include <string>
#include <utility>

#include "../support/asio_loop.hpp"
#include "cal/drivers/transport/transport.hpp"

namespace {

namespace t = cal::drivers::transport;
namespace asio = boost::asio;
using asio::ip::tcp;
using namespace std::chrono_literals;

using cal::test::run_until;

using cal::test::bytes;

TEST(TcpTransport, ConnectsAndMovesBytesBothWays) {
  asio::io_context io;
  tcp::acceptor acceptor(io, tcp::endpoint(asio::ip::address_v4::loopback(), 0));
  const auto port = acceptor.local_endpoint().port();
  tcp::socket peer(io);
  acceptor.async_accept(peer, [](const boost::system::error_code&) {});

  auto client = t::make_tcp(io, {.host = "127.0.0.1", .port = port});
  std::string received;
  std::optional<t::Error> error;
  client->open(
      [&](std::span<const std::byte> b) {
        received.append(reinterpret_cast<const char*>(b.data()), b.size());
      },
      [&](const t::Error& e) { error = e; });
  run_until(io, [&] { return client->is_open() && peer.is_open(); });
  ASSERT_TRUE(client->is_open());
  EXPECT_EQ(client->describe(), "tcp 127.0.0.1:" + std::to_string(port));

  const std::string request = R"({"jsonrpc": "2.0", "method": "x", "params": [], "id": 1})"
                              "\n";
  client->write(bytes(request));
  std::string at_peer(request.size(), '\0');
  asio::read(peer, asio::buffer(at_peer));
  EXPECT_EQ(at_peer, request);

  asio::write(peer, asio::buffer(std::string("{\"result\": [0, 1]}\n")));
  run_until(io, [&] { return received.size() >= 19; });
  EXPECT_EQ(received, "{\"result\": [0, 1]}\n");
  EXPECT_FALSE(error);

  // The instrument end closes: one closed_by_peer report.
  peer.close();
  run_until(io, [&] { return error.has_value(); });
  ASSERT_TRUE(error);
  EXPECT_EQ(error->kind, t::ErrorKind::closed_by_peer);
  EXPECT_FALSE(client->is_open());
}

TEST(TcpTransport, ReportsARefusedConnectionWithTheAddress) {
  asio::io_context io;
  // A port that was just free: bind, read the number, close, so nothing listens there.
  std::uint16_t port = 0;
  {
    tcp::acceptor a(io, tcp::endpoint(asio::ip::address_v4::loopback(), 0));
    port = a.local_endpoint().port();
  }
  auto client = t::make_tcp(io, {.host = "127.0.0.1", .port = port});
  std::optional<t::Error> error;
  client->open([](auto) {}, [&](const t::Error& e) { error = e; });
  run_until(io, [&] { return error.has_value(); });
  ASSERT_TRUE(error);
  EXPECT_EQ(error->kind, t::ErrorKind::open_failed);
  EXPECT_NE(error->message.find("tcp 127.0.0.1:" + std::to_string(port) + ": cannot connect"),
            std::string::npos)
      << error->message;
}

TEST(TcpTransport, TimesOutOnAHostThatNeverAnswers) {
  // An address from TEST-NET-1 (RFC 5737) is never routed: the SYN goes nowhere and only the
  // deadline ends the attempt (or the network is unreachable at once, an open_failed; both
  // are acceptable, a hang is not).
  asio::io_context io;
  auto client = t::make_tcp(io, {.host = "192.0.2.1", .port = 9090, .connect_timeout = 100ms});
  std::optional<t::Error> error;
  client->open([](auto) {}, [&](const t::Error& e) { error = e; });
  run_until(io, [&] { return error.has_value(); });
  ASSERT_TRUE(error);
  EXPECT_TRUE(error->kind == t::ErrorKind::timeout || error->kind == t::ErrorKind::open_failed)
      << error->message;
  if (error->kind == t::ErrorKind::timeout) {
    EXPECT_NE(error->message.find("no connection within 100 ms"), std::string::npos);
  }
}

TEST(TcpTransport, CloseWhileConnectingCallsNothing) {
  asio::io_context io;
  auto client = t::make_tcp(io, {.host = "192.0.2.1", .port = 9090, .connect_timeout = 50ms});
  int calls = 0;
  client->open([&](auto) { ++calls; }, [&](const t::Error&) { ++calls; });
  client->close();
  io.run_for(150ms);
  EXPECT_EQ(calls, 0);
  EXPECT_FALSE(client->is_open());
}

}  // namespace
