#pragma once
// A small, bounded pool of connections to the central store (issue 35): what `daq serve --db
// postgresql://...` answers its requests with, instead of a new connection per request. A
// connection is leased to one caller at a time (never shared by two threads at once), given back
// when the request ends, and dropped when found broken (the server restarted): the request is then
// run once more on a new connection. libpqxx stays out of this header (storage/pg/src/pool.hpp).
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

namespace cal::storage::pg {

class ConnectionPool {
 public:
  // Connects lazily: the first lease makes the first connection. At most max_connections (>= 1)
  // exist at once; a lease past them waits until one is given back.
  ConnectionPool(std::string_view url, std::size_t max_connections);
  ~ConnectionPool();
  ConnectionPool(const ConnectionPool&) = delete;
  ConnectionPool& operator=(const ConnectionPool&) = delete;

  const std::string& shown_url() const;  // the URI with its password as ***
  std::size_t max_connections() const;
  std::int64_t connections_made() const;  // since the pool was made (reconnections included)

  struct Impl;
  Impl& impl() { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace cal::storage::pg
