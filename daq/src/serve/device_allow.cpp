// Which devices `daq serve` may open (see device_allow.hpp and docs/web.md).
#include "serve/device_allow.hpp"

#include <fmt/format.h>
#include <fnmatch.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdio>

#include "cal/analysis/error.hpp"

namespace daq::serve {
namespace {

std::string lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

std::optional<unsigned> port_number(std::string_view text) {
  unsigned value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || ec != std::errc{} || end != text.data() + text.size() || value == 0 ||
      value > 65535)
    return std::nullopt;
  return value;
}

// "413d:2107" -> "413d:2107" (lower-case, four digits each); nullopt if not VID:PID.
std::optional<std::string> hid_id(std::string_view text) {
  unsigned vid = 0, pid = 0;
  char extra = 0;
  const std::string t(text);
  if (std::sscanf(t.c_str(), "%4x:%4x%c", &vid, &pid, &extra) != 2) return std::nullopt;
  return fmt::format("{:04x}:{:04x}", vid, pid);
}

bool has_dot_dot(std::string_view path) {
  return path == ".." || path.starts_with("../") || path.ends_with("/..") ||
         path.find("/../") != std::string_view::npos;
}

// A host glob: an IPv6 literal in brackets is compared as text ('[' would start a set).
bool host_matches(const std::string& glob, const std::string& host) {
  if (glob.starts_with('[')) return glob == host;
  return ::fnmatch(glob.c_str(), host.c_str(), 0) == 0;
}

bool path_matches(const std::string& glob, const std::string& path) {
  return !has_dot_dot(path) && ::fnmatch(glob.c_str(), path.c_str(), FNM_PATHNAME) == 0;
}

bool same_target(const DeviceTarget& a, const DeviceTarget& b) {
  return a.kind == b.kind && a.name == b.name && a.port == b.port;
}

// The --allow-device pattern that would allow exactly this device.
std::string pattern_for(const DeviceTarget& t) {
  if (t.kind == "tcp") return fmt::format("{}:{}", t.name, t.port);
  if (t.kind == "hid" && !t.name.starts_with('/')) return fmt::format("'hid {}'", t.name);
  return t.name;
}

}  // namespace

std::optional<DeviceTarget> device_target(std::string_view transport) {
  const auto space = transport.find(' ');
  if (space == std::string_view::npos) return std::nullopt;
  const std::string kind(transport.substr(0, space));
  std::string_view rest = transport.substr(space + 1);
  if (kind == "serial") {
    const auto device = rest.substr(0, rest.find(' '));
    if (device.empty()) return std::nullopt;
    return DeviceTarget{.kind = kind, .name = std::string(device)};
  }
  if (kind == "tcp") {
    const auto colon = rest.rfind(':');
    if (colon == std::string_view::npos || colon == 0) return std::nullopt;
    const auto port = port_number(rest.substr(colon + 1));
    if (!port) return std::nullopt;
    return DeviceTarget{.kind = kind, .name = lower(rest.substr(0, colon)), .port = *port};
  }
  if (kind == "hid") {
    if (rest.starts_with('/')) return DeviceTarget{.kind = kind, .name = std::string(rest)};
    if (const auto id = hid_id(rest)) return DeviceTarget{.kind = kind, .name = *id};
  }
  return std::nullopt;
}

DeviceAllowList::DeviceAllowList(const std::vector<std::string>& patterns) {
  for (const auto& text : patterns) {
    const auto fail = [&] {
      throw cal::InputError(fmt::format(
          "--allow-device '{}': expected a device path glob (/dev/ttyUSB*, or serial GLOB), "
          "HOST:PORT or HOST:LOW-HIGH (or tcp HOST:PORT), or hid VID:PID",
          text));
    };
    std::string_view t = text;
    std::string kind;
    if (const auto space = t.find(' '); space != std::string_view::npos) {
      kind = std::string(t.substr(0, space));
      t = t.substr(space + 1);
      if (kind != "serial" && kind != "tcp" && kind != "hid") fail();
    }
    if (t.empty()) fail();
    if (kind == "hid") {
      if (t.starts_with('/')) {
        patterns_.push_back({.kind = "hid", .glob = std::string(t)});
      } else {
        // VID:PID, each part hex or a glob ("413d:*").
        const auto colon = t.find(':');
        if (colon == std::string_view::npos || colon == 0 || colon + 1 == t.size()) fail();
        patterns_.push_back({.kind = "hid", .glob = lower(t)});
      }
    } else if (kind == "serial" || (kind.empty() && t.starts_with('/'))) {
      if (!t.starts_with('/')) fail();
      patterns_.push_back({.kind = kind.empty() ? "path" : "serial", .glob = std::string(t)});
    } else {
      const auto colon = t.rfind(':');
      if (colon == std::string_view::npos || colon == 0) fail();
      const auto ports = t.substr(colon + 1);
      const auto dash = ports.find('-');
      const auto low = port_number(ports.substr(0, dash));
      const auto high = dash == std::string_view::npos ? low : port_number(ports.substr(dash + 1));
      if (!low || !high || *high < *low) fail();
      patterns_.push_back(
          {.kind = "tcp", .glob = lower(t.substr(0, colon)), .low = *low, .high = *high});
    }
  }
}

void DeviceAllowList::allow_devices_of(const cal::daq::Config& config) {
  for (const auto& d : config.devices)
    if (const auto t = device_target(d.transport)) configured_.push_back(*t);
}

bool DeviceAllowList::allows(std::string_view transport) const {
  const auto t = device_target(transport);
  if (!t) return false;
  if (std::any_of(configured_.begin(), configured_.end(),
                  [&](const DeviceTarget& c) { return same_target(c, *t); }))
    return true;
  return std::any_of(patterns_.begin(), patterns_.end(), [&](const Pattern& p) {
    if (p.kind == "tcp")
      return t->kind == "tcp" && t->port >= p.low && t->port <= p.high &&
             host_matches(p.glob, t->name);
    if (p.kind == "serial") return t->kind == "serial" && path_matches(p.glob, t->name);
    if (p.kind == "path")
      return (t->kind == "serial" || t->name.starts_with('/')) && path_matches(p.glob, t->name);
    // hid: by id (a glob on "vvvv:pppp") or by path
    if (t->kind != "hid") return false;
    return t->name.starts_with('/') ? path_matches(p.glob, t->name)
                                    : ::fnmatch(p.glob.c_str(), t->name.c_str(), 0) == 0;
  });
}

std::optional<DeviceRefusal> DeviceAllowList::refusal(
    const std::vector<std::pair<std::string, std::string>>& devices) const {
  for (const auto& [id, transport] : devices) {
    if (allows(transport)) continue;
    const auto t = device_target(transport);
    DeviceRefusal r{.device = "devices." + id, .transport = transport};
    if (t) {
      r.allow = "--allow-device " + pattern_for(*t);
      r.message = fmt::format(
          "{}: '{}' is not a device this service may open: daq serve opens only the devices "
          "of its configuration and those allowed with --allow-device (start it with {})",
          r.device, transport, r.allow);
    } else {
      r.message = fmt::format(
          "{}: '{}' is not a transport (tcp HOST:PORT, serial DEVICE ..., "
          "hid VID:PID)",
          r.device, transport);
    }
    return r;
  }
  return std::nullopt;
}

}  // namespace daq::serve
