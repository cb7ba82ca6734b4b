// Transports named by text, as configurations write them (see transport.hpp).
#include <fmt/format.h>

#include <charconv>
#include <cstdio>

#include "cal/analysis/error.hpp"
#include "cal/drivers/transport/hid.hpp"
#include "cal/drivers/transport/transport.hpp"

namespace cal::drivers::transport {
namespace {

struct Parsed {
  std::string kind;
  TcpSettings tcp;
  SerialSettings serial;
  HidSettings hid;
};

Parsed parse(std::string_view text) {
  const auto space = text.find(' ');
  Parsed p;
  p.kind = std::string(text.substr(0, space));
  const std::string rest =
      space == std::string_view::npos ? "" : std::string(text.substr(space + 1));
  const auto fail = [&](std::string_view expected) {
    throw InputError(fmt::format("'{}': expected {}", text, expected));
  };
  if (p.kind == "tcp") {
    const auto colon = rest.rfind(':');
    if (colon == std::string::npos || colon == 0) fail("tcp HOST:PORT");
    const std::string_view port = std::string_view(rest).substr(colon + 1);
    unsigned value = 0;
    const auto [end, ec] = std::from_chars(port.data(), port.data() + port.size(), value);
    if (port.empty() || ec != std::errc{} || end != port.data() + port.size() || value == 0 ||
        value > 65535)
      fail("tcp HOST:PORT with a port 1..65535");
    p.tcp = {.host = rest.substr(0, colon), .port = static_cast<std::uint16_t>(value)};
  } else if (p.kind == "serial") {
    const auto sp = rest.find(' ');
    if (sp == std::string::npos || sp == 0)
      fail("serial DEVICE BAUD FRAME [FLOW], e.g. serial /dev/ttyUSB0 4800 7E1");
    try {
      p.serial = parse_serial_settings(std::string_view(rest).substr(sp + 1),
                                       {.device = rest.substr(0, sp)});
    } catch (const InputError& e) {
      throw InputError(fmt::format("'{}': {}", text, e.what()));
    }
  } else if (p.kind == "hid") {
    if (rest.starts_with("/")) {
      p.hid.path = rest;
    } else {
      unsigned vid = 0, pid = 0;
      char extra = 0;
      if (std::sscanf(rest.c_str(), "%4x:%4x%c", &vid, &pid, &extra) != 2)
        fail("hid VID:PID (hex) or hid /dev/hidrawN");
      p.hid.vendor_id = static_cast<std::uint16_t>(vid);
      p.hid.product_id = static_cast<std::uint16_t>(pid);
    }
  } else {
    throw InputError(fmt::format("'{}': '{}' is not one of: tcp, serial, hid", text, p.kind));
  }
  return p;
}

}  // namespace

void check_transport_text(std::string_view text) { parse(text); }

std::unique_ptr<Transport> make_transport(boost::asio::io_context& io, std::string_view text,
                                          int hid_interface) {
  Parsed p = parse(text);
  if (p.kind == "tcp") return make_tcp(io, p.tcp);
  if (p.kind == "serial") return make_serial(io, p.serial);
  if (p.hid.path.empty()) p.hid.interface_number = hid_interface;
  return make_hid(io, p.hid);
}

}  // namespace cal::drivers::transport
