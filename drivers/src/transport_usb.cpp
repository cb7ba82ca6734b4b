// libusb enumeration and hot-plug. libusb's hot-plug callbacks run on the thread that calls
// libusb_handle_events, so the watcher owns such a thread and posts to the io_context.
#include <fmt/format.h>
#include <libusb-1.0/libusb.h>

#include <atomic>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <stdexcept>
#include <thread>
#include <utility>

#include "cal/drivers/transport/usb.hpp"

namespace cal::drivers::transport {
namespace {

struct ContextDeleter {
  void operator()(libusb_context* c) const { libusb_exit(c); }
};
using ContextPtr = std::unique_ptr<libusb_context, ContextDeleter>;

// A context per user: libusb contexts are cheap, and a private one keeps us independent of
// any other library in the process that uses the default context.
ContextPtr make_context() {
  libusb_context* ctx = nullptr;
  const int rc = libusb_init(&ctx);
  if (rc != 0)
    throw std::runtime_error(fmt::format("libusb: init failed: {}", libusb_strerror(rc)));
  return ContextPtr(ctx);
}

UsbDeviceInfo describe(libusb_device* dev) {
  UsbDeviceInfo info;
  libusb_device_descriptor desc{};
  if (libusb_get_device_descriptor(dev, &desc) == 0) {
    info.vendor_id = desc.idVendor;
    info.product_id = desc.idProduct;
  }
  info.bus = libusb_get_bus_number(dev);
  info.address = libusb_get_device_address(dev);
  std::array<std::uint8_t, 8> ports{};
  const int n = libusb_get_port_numbers(dev, ports.data(), static_cast<int>(ports.size()));
  info.port_path = std::to_string(info.bus);
  for (int i = 0; i < n; ++i) info.port_path += (i == 0 ? "-" : ".") + std::to_string(ports[i]);
  return info;
}

bool matches(const UsbDeviceInfo& d, std::uint16_t vid, std::uint16_t pid) {
  return (vid == 0 || d.vendor_id == vid) && (pid == 0 || d.product_id == pid);
}

}  // namespace

std::vector<UsbDeviceInfo> enumerate_usb(std::uint16_t vendor_id, std::uint16_t product_id) {
  const ContextPtr ctx = make_context();
  libusb_device** list = nullptr;
  const ssize_t n = libusb_get_device_list(ctx.get(), &list);
  if (n < 0)
    throw std::runtime_error(
        fmt::format("libusb: cannot list devices: {}", libusb_strerror(static_cast<int>(n))));
  std::vector<UsbDeviceInfo> out;
  for (ssize_t i = 0; i < n; ++i) {
    UsbDeviceInfo info = describe(list[i]);
    if (matches(info, vendor_id, product_id)) out.push_back(std::move(info));
  }
  libusb_free_device_list(list, 1);
  return out;
}

bool usb_hotplug_supported() { return libusb_has_capability(LIBUSB_CAP_HAS_HOTPLUG) != 0; }

struct UsbHotplugWatcher::Impl {
  Impl(boost::asio::io_context& i, Handler h) : io(i), handler(std::move(h)) {}
  boost::asio::io_context& io;
  Handler handler;
  ContextPtr ctx = make_context();
  libusb_hotplug_callback_handle handle = 0;
  std::atomic<bool> stop{false};
  std::thread events;
  // Shared with posted handlers: a watcher destroyed with events still queued drops them.
  std::shared_ptr<std::atomic<bool>> alive = std::make_shared<std::atomic<bool>>(true);

  static int LIBUSB_CALL on_event(libusb_context*, libusb_device* dev, libusb_hotplug_event event,
                                  void* user) {
    auto* self = static_cast<Impl*>(user);
    const Event e = event == LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED ? Event::arrived : Event::left;
    boost::asio::post(self->io, [alive = self->alive, h = self->handler, e, info = describe(dev)] {
      if (*alive) h(e, info);
    });
    return 0;  // stay registered
  }
};

UsbHotplugWatcher::UsbHotplugWatcher(boost::asio::io_context& io, std::uint16_t vendor_id,
                                     std::uint16_t product_id, Handler handler)
    : impl_(std::make_unique<Impl>(io, std::move(handler))) {
  if (!usb_hotplug_supported())
    throw std::runtime_error("libusb: hot-plug events are not supported on this platform");
  const int rc = libusb_hotplug_register_callback(
      impl_->ctx.get(),
      static_cast<libusb_hotplug_event>(LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED |
                                        LIBUSB_HOTPLUG_EVENT_DEVICE_LEFT),
      LIBUSB_HOTPLUG_ENUMERATE, vendor_id ? vendor_id : LIBUSB_HOTPLUG_MATCH_ANY,
      product_id ? product_id : LIBUSB_HOTPLUG_MATCH_ANY, LIBUSB_HOTPLUG_MATCH_ANY, &Impl::on_event,
      impl_.get(), &impl_->handle);
  if (rc != LIBUSB_SUCCESS)
    throw std::runtime_error(
        fmt::format("libusb: cannot register hot-plug callback: {}", libusb_strerror(rc)));
  impl_->events = std::thread([impl = impl_.get()] {
    while (!impl->stop) {
      timeval tv{0, 100'000};  // wake up every 100 ms to notice stop
      libusb_handle_events_timeout_completed(impl->ctx.get(), &tv, nullptr);
    }
  });
}

UsbHotplugWatcher::~UsbHotplugWatcher() {
  *impl_->alive = false;
  impl_->stop = true;
  // Deregistering wakes libusb_handle_events, so the join is prompt.
  libusb_hotplug_deregister_callback(impl_->ctx.get(), impl_->handle);
  impl_->events.join();
}

}  // namespace cal::drivers::transport
