// HID transport: hidapi's synchronous API driven by a poll timer on the event loop.
#include <fmt/format.h>
#include <hidapi/hidapi.h>

#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <stdexcept>
#include <utility>

#include "cal/drivers/transport/hid.hpp"

namespace cal::drivers::transport {
namespace {

namespace asio = boost::asio;

// hidapi reports strings as wchar_t; the devices we support use ASCII, so a narrowing copy of
// the basic-Latin range is enough (anything else becomes '?').
std::string narrow(const wchar_t* w) {
  std::string out;
  if (!w) return out;
  for (; *w; ++w) out.push_back(*w >= 0x20 && *w < 0x7f ? static_cast<char>(*w) : '?');
  return out;
}

std::string last_error(hid_device* dev) {
  const std::string text = narrow(hid_error(dev));
  return text.empty() ? "unknown hidapi error" : text;
}

void init_hidapi() {
  // hid_init is idempotent and process-wide; hid_exit is left to process exit because other
  // transports may still hold devices.
  if (hid_init() != 0) throw std::runtime_error("hidapi: hid_init failed");
}

struct DeviceCloser {
  void operator()(hid_device* d) const { hid_close(d); }
};
using DevicePtr = std::unique_ptr<hid_device, DeviceCloser>;

// Shared with the timer handler so that a transport closed between two polls is safe.
struct HidSession : std::enable_shared_from_this<HidSession> {
  HidSession(asio::io_context& io, std::string d) : timer(io), description(std::move(d)) {}

  void poll() {
    timer.expires_after(interval);
    timer.async_wait([self = shared_from_this()](const boost::system::error_code& ec) {
      if (ec || !self->device) return;
      self->drain();
      if (self->device) self->poll();
    });
  }

  // Reads every report queued in the kernel, without blocking the loop.
  void drain() {
    std::array<unsigned char, 64> report{};
    for (;;) {
      const int n = hid_read_timeout(device.get(), report.data(), report.size(), 0);
      if (n == 0) return;
      if (n < 0) return fail(ErrorKind::read_failed, "read failed: " + last_error(device.get()));
      on_data(std::as_bytes(std::span(report.data(), static_cast<std::size_t>(n))));
      if (!device) return;  // the handler closed us
    }
  }

  void fail(ErrorKind kind, const std::string& what) {
    auto handler = std::move(on_error);
    close();
    if (handler) handler(Error{kind, description + ": " + what});
  }

  void close() {
    timer.cancel();
    device.reset();
    on_data = nullptr;
    on_error = nullptr;
  }

  asio::steady_timer timer;
  std::string description;
  DevicePtr device;
  std::chrono::milliseconds interval{5};
  Transport::DataHandler on_data;
  Transport::ErrorHandler on_error;
};

std::string find_path(const HidSettings& s) {
  if (!s.path.empty()) return s.path;
  for (const auto& d : enumerate_hid(s.vendor_id, s.product_id)) {
    if (!s.serial_number.empty() && d.serial_number != s.serial_number) continue;
    if (s.interface_number >= 0 && d.interface_number != s.interface_number) continue;
    return d.path;
  }
  return {};
}

class HidTransport final : public Transport {
 public:
  HidTransport(asio::io_context& io, HidSettings settings)
      : io_(io), settings_(std::move(settings)) {}
  ~HidTransport() override { close(); }

  void open(Handlers handlers) override {
    close();
    session_ = std::make_shared<HidSession>(io_, describe());
    session_->interval = settings_.poll_interval;
    std::string problem;
    try {
      init_hidapi();
      const std::string path = find_path(settings_);
      if (path.empty()) {
        problem = "no such device attached";
      } else {
        session_->device.reset(hid_open_path(path.c_str()));
        if (!session_->device)
          problem = fmt::format("cannot open {} (permissions? see udev/README.md)", path);
      }
    } catch (const std::exception& e) {
      problem = e.what();
    }
    if (problem.empty()) {
      session_->on_data = std::move(handlers.data);
      session_->on_error = std::move(handlers.error);
      if (handlers.opened)
        asio::post(io_, [s = std::weak_ptr(session_), opened = std::move(handlers.opened)] {
          if (auto live = s.lock(); live && live->device) opened();
        });
      return session_->poll();
    }
    asio::post(io_, [on_error = std::move(handlers.error), message = describe() + ": " + problem] {
      on_error(Error{ErrorKind::open_failed, message});
    });
  }

  void write(std::span<const std::byte> bytes) override {
    if (!is_open()) return;
    const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
    if (hid_write(session_->device.get(), data, bytes.size()) < 0)
      session_->fail(ErrorKind::write_failed,
                     "write failed: " + last_error(session_->device.get()));
  }
  void close() override {
    if (session_) session_->close();
    session_.reset();
  }
  bool is_open() const override { return session_ && session_->device; }
  std::string describe() const override {
    if (!settings_.path.empty()) return "hid " + settings_.path;
    std::string text = fmt::format("hid {:04x}:{:04x}", settings_.vendor_id, settings_.product_id);
    if (!settings_.serial_number.empty()) text += " serial " + settings_.serial_number;
    if (settings_.interface_number >= 0)
      text += fmt::format(" interface {}", settings_.interface_number);
    return text;
  }

 private:
  asio::io_context& io_;
  HidSettings settings_;
  std::shared_ptr<HidSession> session_;
};

}  // namespace

std::vector<HidDeviceInfo> enumerate_hid(std::uint16_t vendor_id, std::uint16_t product_id) {
  init_hidapi();
  std::vector<HidDeviceInfo> out;
  hid_device_info* list = hid_enumerate(vendor_id, product_id);
  for (const hid_device_info* d = list; d; d = d->next) {
    out.push_back({d->vendor_id, d->product_id, d->path ? d->path : "", narrow(d->serial_number),
                   narrow(d->manufacturer_string), narrow(d->product_string), d->interface_number});
  }
  hid_free_enumeration(list);
  return out;
}

std::unique_ptr<Transport> make_hid(asio::io_context& io, HidSettings settings) {
  return std::make_unique<HidTransport>(io, std::move(settings));
}

}  // namespace cal::drivers::transport
