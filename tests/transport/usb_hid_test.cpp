// Enumeration cannot be checked against real devices on a build machine (there may be no USB
// at all), so these tests check the contracts that hold everywhere: filtering is consistent
// with the unfiltered list, and a device that is not attached gives a named open error.
#include <gtest/gtest.h>

#include <boost/asio/io_context.hpp>
#include <utility>

#include "cal/drivers/transport/hid.hpp"
#include "cal/drivers/transport/usb.hpp"

namespace {

namespace t = cal::drivers::transport;
using namespace std::chrono_literals;

TEST(UsbEnumeration, FilteringKeepsExactlyTheMatchingDevices) {
  const auto all = t::enumerate_usb();
  for (const auto& d : all) {
    EXPECT_FALSE(d.port_path.empty());
    const auto same_vid = t::enumerate_usb(d.vendor_id);
    EXPECT_FALSE(same_vid.empty());
    for (const auto& m : same_vid) EXPECT_EQ(m.vendor_id, d.vendor_id);
  }
  // 0xffff is reserved by the USB-IF and never assigned: nothing may match it.
  EXPECT_TRUE(t::enumerate_usb(0xffff, 0xffff).empty());
}

TEST(HidEnumeration, FilteringKeepsExactlyTheMatchingDevices) {
  const auto all = t::enumerate_hid();
  for (const auto& d : all) {
    EXPECT_FALSE(d.path.empty());
    for (const auto& m : t::enumerate_hid(d.vendor_id, d.product_id)) {
      EXPECT_EQ(m.vendor_id, d.vendor_id);
      EXPECT_EQ(m.product_id, d.product_id);
    }
  }
  EXPECT_TRUE(t::enumerate_hid(0xffff, 0xffff).empty());
}

TEST(HidTransport, AnAbsentDeviceIsANamedOpenError) {
  boost::asio::io_context io;
  auto hid = t::make_hid(io, {.vendor_id = 0xffff, .product_id = 0xfffe, .interface_number = 1});
  std::optional<t::Error> error;
  hid->open([](auto) {}, [&](const t::Error& e) { error = e; });
  io.run_for(20ms);
  ASSERT_TRUE(error);
  EXPECT_EQ(error->kind, t::ErrorKind::open_failed);
  EXPECT_EQ(error->message, "hid ffff:fffe interface 1: no such device attached");
  EXPECT_FALSE(hid->is_open());
}

TEST(UsbHotplug, WatcherStartsAndStopsCleanlyWhereSupported) {
  boost::asio::io_context io;
  if (!t::usb_hotplug_supported()) {
    EXPECT_THROW(t::UsbHotplugWatcher(io, 0, 0, [](auto, const auto&) {}), std::runtime_error);
    return;
  }
  // With LIBUSB_HOTPLUG_ENUMERATE every attached device is reported as arrived first: the
  // count must equal the enumeration's.
  std::size_t arrived = 0;
  {
    t::UsbHotplugWatcher watcher(io, 0, 0, [&](t::UsbHotplugWatcher::Event e, const auto&) {
      if (e == t::UsbHotplugWatcher::Event::arrived) ++arrived;
    });
    io.run_for(50ms);
  }
  EXPECT_EQ(arrived, t::enumerate_usb().size());
}

}  // namespace
