// Simulated time's accounting of the bytes to each reader (see reader_bytes.hpp).
#include "reader_bytes.hpp"

#include <algorithm>
#include <boost/asio/execution_context.hpp>
#include <map>
#include <optional>
#include <string>

#include "cal/drivers/loop_time.hpp"

namespace cal::drivers::detail {

namespace asio = boost::asio;

struct ReaderBytes::Impl {
  VirtualTime* time = nullptr;
  struct Reader {
    std::int64_t in_flight = 0;  // this reader's part of the VirtualTime's bytes in flight
    bool closed = false;
  };
  std::map<std::string, Reader, std::less<>> readers;
  // The VirtualTime forgets every byte in flight when they do not arrive within kSettle: then
  // so does this, or a later read would take bytes off the count that are no longer in it.
  std::uint64_t settle_timeouts = 0;

  Reader& operator[](std::string_view name) {
    if (time->stats().settle_timeouts != settle_timeouts) {
      settle_timeouts = time->stats().settle_timeouts;
      for (auto& [n, r] : readers) r.in_flight = 0;
    }
    auto at = readers.find(name);
    if (at == readers.end()) at = readers.emplace(std::string(name), Reader{}).first;
    return at->second;
  }
};

namespace {
// Owned by the io_context (an Asio service), as its VirtualTime is.
struct ReaderBytesService : asio::execution_context::service {
  static asio::execution_context::id id;
  explicit ReaderBytesService(asio::execution_context& ctx) : service(ctx) {}
  void shutdown() override {}
  ReaderBytes::Impl impl;
  std::optional<ReaderBytes> accounting;
};
asio::execution_context::id ReaderBytesService::id;
}  // namespace

ReaderBytes* ReaderBytes::of(asio::execution_context& ctx) {
  auto* time = VirtualTime::of(ctx);
  if (!time) return nullptr;
  auto& s = asio::use_service<ReaderBytesService>(ctx);
  if (!s.accounting) {
    s.impl.time = time;
    s.accounting.emplace(s.impl);
  }
  return &*s.accounting;
}

void ReaderBytes::written(std::size_t n, std::string_view reader) {
  auto& r = impl_[reader];
  if (r.closed) return;
  r.in_flight += static_cast<std::int64_t>(n);
  impl_.time->bytes_written(n);
}

void ReaderBytes::read(std::size_t n, std::string_view reader) {
  auto& r = impl_[reader];
  // Not more than is counted: bytes sent while the reader was closed may be read by the next
  // one that opens the channel.
  const auto k = std::min(static_cast<std::int64_t>(n), r.in_flight);
  r.in_flight -= k;
  impl_.time->bytes_read(static_cast<std::size_t>(k));
}

void ReaderBytes::opened(std::string_view reader) { impl_[reader].closed = false; }

void ReaderBytes::closed(std::string_view reader) {
  auto& r = impl_[reader];
  impl_.time->bytes_read(static_cast<std::size_t>(r.in_flight));
  r = {.in_flight = 0, .closed = true};
}

}  // namespace cal::drivers::detail
