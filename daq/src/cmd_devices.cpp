// daq devices: what is attached or reachable, and which driver would take it.
#include <fmt/format.h>

#include <boost/asio/io_context.hpp>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cal/analysis/error.hpp"
#include "cal/drivers/catalog.hpp"
#include "cal/drivers/codec/attocube_ids.hpp"
#include "cal/drivers/codec/vaisala_ptu300.hpp"
#include "cal/drivers/transport/hid.hpp"
#include "cal/drivers/transport/transport.hpp"
#include "cal/drivers/transport/usb.hpp"
#include "commands.hpp"
#include "devices_list.hpp"

namespace daq {
namespace {

namespace t = cal::drivers::transport;
using nlohmann::json;

std::vector<std::string> serial_ports() {
  namespace fs = std::filesystem;
  std::vector<std::string> out;
  std::error_code ec;
  // by-id names are stable across re-plugs and name the adapter; prefer them.
  if (fs::is_directory("/dev/serial/by-id", ec))
    for (const auto& e : fs::directory_iterator("/dev/serial/by-id", ec))
      out.push_back(e.path().string());
  if (out.empty())
    for (const auto& e : fs::directory_iterator("/dev", ec)) {
      const std::string name = e.path().filename().string();
      if (name.rfind("ttyUSB", 0) == 0 || name.rfind("ttyACM", 0) == 0)
        out.push_back(e.path().string());
    }
  std::sort(out.begin(), out.end());
  return out;
}

// Runs the loop until a reply line arrives or the deadline passes; returns the bytes.
std::string exchange(boost::asio::io_context& io, t::Transport& tr, std::string request,
                     std::chrono::milliseconds deadline, std::string& error) {
  std::string received;
  tr.open({.opened = [&] { tr.write(std::as_bytes(std::span(request.data(), request.size()))); },
           .data =
               [&](std::span<const std::byte> b) {
                 received.append(reinterpret_cast<const char*>(b.data()), b.size());
               },
           .error = [&](const t::Error& e) { error = e.message; }});
  const auto end = std::chrono::steady_clock::now() + deadline;
  while (received.find('\n') == std::string::npos && error.empty() &&
         std::chrono::steady_clock::now() < end) {
    io.run_for(std::chrono::milliseconds(10));
    io.restart();
  }
  tr.close();
  return received;
}

json probe_tcp(const std::string& spec) {
  const auto colon = spec.rfind(':');
  const std::string host = colon == std::string::npos ? spec : spec.substr(0, colon);
  const auto port = colon == std::string::npos ? 9090 : std::stoi(spec.substr(colon + 1));
  boost::asio::io_context io;
  auto tcp = t::make_tcp(io, {.host = host,
                              .port = static_cast<std::uint16_t>(port),
                              .connect_timeout = std::chrono::milliseconds(1500)});
  cal::drivers::codec::IdsCodec codec;
  const std::string request = codec.encode(cal::drivers::codec::IdsMethod::get_current_mode);
  std::string error;
  const std::string reply = exchange(io, *tcp, request, std::chrono::milliseconds(2000), error);
  std::vector<cal::drivers::codec::IdsResponse> frames;
  codec.feed(reply, frames);
  json j{{"transport", tcp->describe()}};
  if (!frames.empty()) {
    j["driver"] = "ids3010";
    j["detail"] = "mode: " + frames[0].mode;
  } else {
    j["driver"] = nullptr;
    j["detail"] = error.empty() ? "no IDS3010 JSON-RPC answer" : error;
  }
  return j;
}

json probe_serial(const std::string& spec) {
  const auto at = spec.find('@');
  t::SerialSettings s{.device = spec.substr(0, at)};
  s = t::parse_serial_settings(at == std::string::npos ? "4800 7E1" : spec.substr(at + 1), s);
  boost::asio::io_context io;
  auto port = t::make_serial(io, s);
  std::string error;
  const std::string reply = exchange(io, *port, cal::drivers::codec::ptu300_send(),
                                     std::chrono::milliseconds(2000), error);
  cal::drivers::codec::Ptu300Codec codec;
  std::vector<cal::drivers::codec::Ptu300Frame> frames;
  codec.feed(reply, frames);
  json j{{"transport", port->describe()}};
  if (!frames.empty() && (frames[0].pressure_pa || frames[0].temperature_degc)) {
    j["driver"] = "ptu300";
    j["detail"] = "answered SEND";
  } else {
    j["driver"] = nullptr;
    j["detail"] = error.empty() ? "no PTU300 answer to SEND" : error;
  }
  return j;
}

}  // namespace

json list_devices(const DevicesOptions& o) {
  json out{{"schema", "caldaq.devices.v1"},
           {"usb", json::array()},
           {"hid", json::array()},
           {"serial", json::array()},
           {"probes", json::array()}};
  try {
    for (const auto& d : t::enumerate_usb()) {
      const auto* known = cal::drivers::find_known_device(d.vendor_id, d.product_id);
      out["usb"].push_back({{"vid_pid", fmt::format("{:04x}:{:04x}", d.vendor_id, d.product_id)},
                            {"port", d.port_path},
                            {"driver", known ? json(known->driver) : json(nullptr)},
                            {"description", known ? json(known->description) : json("")}});
    }
  } catch (const std::exception& e) {
    out["usb_error"] = e.what();
  }
  try {
    for (const auto& d : t::enumerate_hid()) {
      const auto* known = cal::drivers::find_known_device(d.vendor_id, d.product_id);
      if (!known) continue;  // keyboards and mice are not ours to list
      out["hid"].push_back({{"vid_pid", fmt::format("{:04x}:{:04x}", d.vendor_id, d.product_id)},
                            {"path", d.path},
                            {"interface", d.interface_number},
                            {"product", d.product},
                            {"driver", known->driver}});
    }
  } catch (const std::exception& e) {
    out["hid_error"] = e.what();
  }
  for (const auto& p : serial_ports())
    out["serial"].push_back(
        {{"device", p},
         {"driver", nullptr},
         {"detail", "serial port: try --probe-serial " + p + " (PTU300 at 4800 7E1)"}});
  for (const auto& p : o.tcp_probes) out["probes"].push_back(probe_tcp(p));
  for (const auto& p : o.serial_probes) out["probes"].push_back(probe_serial(p));
  return out;
}

namespace {

void print_text(const json& j) {
  const auto driver = [](const json& d) {
    return d.is_null() ? std::string("-") : d.get<std::string>();
  };
  fmt::print("USB devices ({}):\n", j["usb"].size());
  for (const auto& d : j["usb"])
    fmt::print("  {}  port {:<10} driver {:<8} {}\n", d["vid_pid"].get<std::string>(),
               d["port"].get<std::string>(), driver(d["driver"]),
               d["description"].get<std::string>());
  if (j.contains("usb_error"))
    fmt::print("  (cannot enumerate: {})\n", j["usb_error"].get<std::string>());
  fmt::print("HID instruments ({}):\n", j["hid"].size());
  for (const auto& d : j["hid"])
    fmt::print("  {}  {}  interface {}  driver {}\n", d["vid_pid"].get<std::string>(),
               d["path"].get<std::string>(), d["interface"].get<int>(), driver(d["driver"]));
  fmt::print("Serial ports ({}):\n", j["serial"].size());
  for (const auto& d : j["serial"]) fmt::print("  {}\n", d["device"].get<std::string>());
  if (!j["probes"].empty()) fmt::print("Probes:\n");
  for (const auto& d : j["probes"])
    fmt::print("  {:<40} driver {:<8} {}\n", d["transport"].get<std::string>(), driver(d["driver"]),
               d["detail"].get<std::string>());
}

}  // namespace

void add_devices_command(CLI::App& app) {
  auto opts = std::make_shared<DevicesOptions>();
  CLI::App* cmd = app.add_subcommand(
      "devices",
      "List attached USB/HID instruments and serial ports, and probe networked or serial "
      "instruments");
  cmd->add_option("--probe", opts->tcp_probes,
                  "Ask HOST[:PORT] (default port 9090) for an IDS3010 JSON-RPC answer");
  cmd->add_option("--probe-serial", opts->serial_probes,
                  "Ask DEVICE[@SETTINGS] (default 4800 7E1) for a PTU300 answer to SEND");
  cmd->add_flag("--json", opts->json, "Print caldaq.devices.v1 JSON");
  cmd->callback([opts] {
    const json j = list_devices(*opts);
    if (opts->json)
      fmt::print("{}\n", j.dump(2));
    else
      print_text(j);
  });
}

}  // namespace daq
