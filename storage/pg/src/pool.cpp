// The central store's connection pool (cal/storage/pg/pool.hpp).
#include "pool.hpp"

#include "cal/storage/pg/sync.hpp"

namespace cal::storage::pg {

ConnectionPool::ConnectionPool(std::string_view url, std::size_t max_connections)
    : impl_(std::make_unique<Impl>()) {
  impl_->url = std::string(url);
  impl_->shown = redacted(url);
  impl_->max = max_connections == 0 ? 1 : max_connections;
}

ConnectionPool::~ConnectionPool() = default;

const std::string& ConnectionPool::shown_url() const { return impl_->shown; }
std::size_t ConnectionPool::max_connections() const { return impl_->max; }
std::int64_t ConnectionPool::connections_made() const {
  const std::lock_guard lock(impl_->mutex);
  return impl_->made;
}

Lease::Lease(ConnectionPool::Impl& pool) : pool_(pool) {
  std::unique_lock lock(pool_.mutex);
  pool_.given_back.wait(
      lock, [&] { return !pool_.idle.empty() || pool_.out + pool_.idle.size() < pool_.max; });
  ++pool_.out;
  if (!pool_.idle.empty()) {
    conn_ = std::move(pool_.idle.back());
    pool_.idle.pop_back();
    return;
  }
  lock.unlock();  // connecting takes a while: the others lease meanwhile
  try {
    conn_ = connect(pool_.shown, pool_.url);
    // A new connection's server is checked once (a server restored from another version).
    guarded(pool_.shown, "read the central schema version",
            [&] { check_reader_schema(*conn_, pool_.shown); });
  } catch (...) {
    conn_.reset();
    lock.lock();
    --pool_.out;
    pool_.given_back.notify_one();
    throw;
  }
  lock.lock();
  ++pool_.made;
}

Lease::~Lease() {
  const std::lock_guard lock(pool_.mutex);
  --pool_.out;
  if (conn_ && conn_->is_open()) pool_.idle.push_back(std::move(conn_));
  pool_.given_back.notify_all();
}

void Lease::drop() {
  conn_.reset();
  std::vector<std::unique_ptr<pqxx::connection>> broken;
  const std::lock_guard lock(pool_.mutex);
  broken.swap(pool_.idle);
  pool_.given_back.notify_all();
}

}  // namespace cal::storage::pg
