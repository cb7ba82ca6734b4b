#pragma once
// Private to drivers/: the asynchronous read loop and ordered write queue shared by the Asio
// transports (serial port, TCP socket). Includes Boost.Asio, so only transport .cpp files
// include it.
#include <array>
#include <boost/asio.hpp>
#include <deque>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "cal/drivers/loop_time.hpp"
#include "cal/drivers/transport/transport.hpp"
#include "reader_bytes.hpp"

namespace cal::drivers::transport::detail {

// The session outlives the Transport object that owns it until its last pending handler has
// run: every handler holds a shared_ptr, so closing (or destroying) a transport while a read
// is in flight is safe. After close(), the user's handlers are never called again.
template <class Stream>
class Session : public std::enable_shared_from_this<Session<Stream>> {
 public:
  Session(Stream stream, std::string description)
      : stream_(std::move(stream)),
        description_(std::move(description)),
        readers_(::cal::drivers::detail::ReaderBytes::of(stream_.get_executor().context())) {}

  Stream& stream() { return stream_; }
  const std::string& description() const { return description_; }
  bool active() const { return static_cast<bool>(on_data_); }

  // reader: this end's name in simulated time's accounting of a twin's bytes (its
  // pseudo-terminal's path, "tcp:PORT" by our port; see reader_bytes.hpp).
  void start(Transport::Handlers handlers, std::string reader) {
    reader_ = std::move(reader);
    to_twin_ = ::cal::drivers::detail::ReaderBytes::to_twin(reader_);
    if (readers_) readers_->opened(reader_);
    on_data_ = std::move(handlers.data);
    on_error_ = std::move(handlers.error);
    read_next();
    // Announced from the loop, after open() returned, like every other event.
    if (handlers.opened)
      boost::asio::post(stream_.get_executor(),
                        [self = this->shared_from_this(), opened = std::move(handlers.opened)] {
                          if (self->active()) opened();
                        });
  }

  void write(std::span<const std::byte> bytes) {
    if (!active()) return;
    const auto* p = reinterpret_cast<const char*>(bytes.data());
    queue_.emplace_back(p, p + bytes.size());
    // Simulated time waits for these bytes to reach their reader (a twin in this process),
    // counted as this driver's (reader_bytes.hpp).
    if (readers_) readers_->written(bytes.size(), to_twin_);
    if (queue_.size() == 1) write_next();
  }

  void close() {
    // What the twin sent us and we did not read is read by nobody: not waited for any more.
    if (readers_ && !reader_.empty()) readers_->closed(reader_);
    on_data_ = nullptr;
    on_error_ = nullptr;
    // Ours not yet handed to the stream never reach the twin (the first one's handler takes
    // off what of it was not written).
    if (readers_)
      for (std::size_t i = 1; i < queue_.size(); ++i) readers_->read(queue_[i].size(), to_twin_);
    queue_.clear();
    boost::system::error_code ignored;
    stream_.close(ignored);
  }

  // Reports the first error of the session and closes it; later errors are consequences.
  void fail(ErrorKind kind, const std::string& what) {
    auto on_error = std::move(on_error_);
    close();
    if (on_error) on_error(Error{kind, description_ + ": " + what});
  }

 private:
  void read_next() {
    stream_.async_read_some(
        boost::asio::buffer(buffer_),
        [self = this->shared_from_this()](const boost::system::error_code& ec, std::size_t n) {
          self->on_read(ec, n);
        });
  }

  void on_read(const boost::system::error_code& ec, std::size_t n) {
    if (readers_) readers_->read(n, reader_);
    if (!active()) return;  // closed while the read was in flight
    if (n > 0) on_data_(std::span<const std::byte>(buffer_.data(), n));
    if (!active()) return;  // the data handler closed us
    if (ec == boost::asio::error::eof) return fail(ErrorKind::closed_by_peer, "end of stream");
    if (ec) return fail(ErrorKind::read_failed, "read failed: " + ec.message());
    read_next();
  }

  void write_next() {
    boost::asio::async_write(stream_, boost::asio::buffer(queue_.front()),
                             [self = this->shared_from_this(), size = queue_.front().size()](
                                 const boost::system::error_code& ec, std::size_t written) {
                               if (self->readers_ && written < size)  // never reaches the twin
                                 self->readers_->read(size - written, self->to_twin_);
                               if (!self->active()) return;
                               if (ec)
                                 return self->fail(ErrorKind::write_failed,
                                                   "write failed: " + ec.message());
                               self->queue_.pop_front();
                               if (!self->queue_.empty()) self->write_next();
                             });
  }

  Stream stream_;
  std::string description_;
  Transport::DataHandler on_data_;
  Transport::ErrorHandler on_error_;
  std::array<std::byte, 4096> buffer_{};
  std::deque<std::vector<char>> queue_;
  // Simulated mode only: the bytes our twin sent us (reader_bytes.hpp).
  ::cal::drivers::detail::ReaderBytes* readers_;
  std::string reader_;
  std::string to_twin_;  // our bytes to the twin count under this name
};

}  // namespace cal::drivers::transport::detail
