// For the tests that drive real Asio I/O on the wall clock (transports, simulated twins): the
// bytes of a text, and the event loop run until a condition holds.
#pragma once

#include <boost/asio/io_context.hpp>
#include <chrono>
#include <cstddef>
#include <span>
#include <string_view>

namespace cal::test {

inline std::span<const std::byte> bytes(std::string_view s) {
  return std::as_bytes(std::span(s.data(), s.size()));
}

// Runs `io` until `done` or a 3 s safety limit (a hang is a failed expectation, not a stuck
// test; generous, since the tests share a loaded machine).
template <class Pred>
void run_until(boost::asio::io_context& io, Pred done) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(3);
  while (!done() && std::chrono::steady_clock::now() < deadline) {
    io.run_for(std::chrono::milliseconds(5));
    io.restart();
  }
}

}  // namespace cal::test
