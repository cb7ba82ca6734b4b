#pragma once
// Private to storage/pg: the connection pool's leases (cal/storage/pg/pool.hpp) and a read-only
// request run on one.
#include <condition_variable>
#include <mutex>
#include <vector>

#include "cal/storage/pg/pool.hpp"
#include "central_schema.hpp"

namespace cal::storage::pg {

struct ConnectionPool::Impl {
  std::string url, shown;
  std::size_t max = 1;
  std::mutex mutex;
  std::condition_variable given_back;
  std::vector<std::unique_ptr<pqxx::connection>> idle;  // connected, leased to no one
  std::size_t out = 0;                                  // leased, or being connected for a lease
  std::int64_t made = 0;
};

// One connection, the caller's alone until the lease ends; back to the pool then, unless
// dropped (broken).
class Lease {
 public:
  explicit Lease(ConnectionPool::Impl& pool);
  ~Lease();
  Lease(const Lease&) = delete;
  Lease& operator=(const Lease&) = delete;
  pqxx::connection& connection() { return *conn_; }
  // The connection is broken: closed instead of given back, and the idle ones with it (a server
  // restart broke them all; each would fail its next request).
  void drop();

 private:
  ConnectionPool::Impl& pool_;
  std::unique_ptr<pqxx::connection> conn_;
};

// f(read_transaction&) on a leased connection; errors name the server and `what` (StoreError).
// A connection found broken (the server restarted since it was made) is dropped and f run once
// more on a new one: the requests only read, so running one again changes nothing.
template <class F>
auto with_connection(ConnectionPool& pool, std::string_view what, F&& f) {
  return guarded(pool.shown_url(), what, [&] {
    for (int attempt = 0;; ++attempt) {
      Lease lease(pool.impl());
      try {
        pqxx::read_transaction t(lease.connection());
        return f(t);
      } catch (const pqxx::failure&) {
        // broken_connection, or the server's "terminating connection due to administrator
        // command" read as an error on a connection libpq has since marked closed.
        if (lease.connection().is_open() || attempt > 0) throw;
        lease.drop();
      }
    }
  });
}

}  // namespace cal::storage::pg
