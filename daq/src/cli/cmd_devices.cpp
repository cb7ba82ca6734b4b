// daq devices: what is attached or reachable, and which driver would take it.
#include <fmt/format.h>

#include <boost/asio/io_context.hpp>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cal/analysis/error.hpp"
#include "cal/drivers/catalog.hpp"
#include "cal/drivers/registry.hpp"
#include "cal/drivers/transport/hid.hpp"
#include "cal/drivers/transport/transport.hpp"
#include "cal/drivers/transport/usb.hpp"
#include "commands.hpp"
#include "devices_list.hpp"
#include "json_input.hpp"
#include "serve/instrument_form.hpp"
#include "terminal.hpp"

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

// Sends the probe's request and runs the loop until the probe decides or the deadline passes.
cal::drivers::ProbeSpec::Answer exchange(boost::asio::io_context& io, t::Transport& tr,
                                         const cal::drivers::ProbeSpec& p,
                                         std::chrono::milliseconds deadline, std::string& error) {
  std::string received;
  tr.open(
      {.opened = [&] { tr.write(std::as_bytes(std::span(p.request.data(), p.request.size()))); },
       .data =
           [&](std::span<const std::byte> b) {
             received.append(reinterpret_cast<const char*>(b.data()), b.size());
           },
       .error = [&](const t::Error& e) { error = e.message; }});
  cal::drivers::ProbeSpec::Answer answer;
  const auto end = std::chrono::steady_clock::now() + deadline;
  while (answer.verdict == cal::drivers::ProbeSpec::Verdict::more && error.empty() &&
         std::chrono::steady_clock::now() < end) {
    io.run_for(std::chrono::milliseconds(10));
    io.restart();
    answer = p.recognise(received);
  }
  tr.close();
  if (answer.verdict == cal::drivers::ProbeSpec::Verdict::more) {
    answer.verdict = cal::drivers::ProbeSpec::Verdict::no;
    if (answer.detail.empty())
      answer.detail = received.empty() ? "no answer" : "no complete answer";
  }
  return answer;
}

// Asks `transport` with each driver's probe of that transport kind, in registry order; the
// first that recognises the answer names the device.
json probe(std::string_view kind, const std::string& spec) {
  std::vector<std::string> tried;
  json j{{"driver", nullptr}};
  for (const auto* drv : cal::drivers::device_drivers()) {
    const auto p = drv->probe();
    if (!p || p->transport_kind != kind) continue;
    boost::asio::io_context io;
    std::unique_ptr<t::Transport> tr;
    if (kind == "tcp") {
      const auto colon = spec.rfind(':');
      const std::string host = colon == std::string::npos ? spec : spec.substr(0, colon);
      const auto port =
          colon == std::string::npos ? p->default_port : std::stoi(spec.substr(colon + 1));
      tr = t::make_tcp(io, {.host = host,
                            .port = static_cast<std::uint16_t>(port),
                            .connect_timeout = std::chrono::milliseconds(1500)});
    } else {
      const auto at = spec.find('@');
      t::SerialSettings s{.device = spec.substr(0, at)};
      tr = t::make_serial(
          io, t::parse_serial_settings(
                  at == std::string::npos ? p->default_serial : spec.substr(at + 1), s));
    }
    std::string error;
    const auto answer = exchange(io, *tr, *p, std::chrono::milliseconds(2000), error);
    j["transport"] = tr->describe();
    if (answer.verdict == cal::drivers::ProbeSpec::Verdict::yes) {
      j["driver"] = drv->name();
      j["detail"] = answer.detail;
      return j;
    }
    tried.push_back(fmt::format("{}: {}", drv->name(),
                                !error.empty()          ? error
                                : answer.detail.empty() ? std::string("no answer")
                                                        : answer.detail));
  }
  j["detail"] = tried.empty() ? std::string("no driver probes this kind of transport")
                              : fmt::format("{}", fmt::join(tried, "; "));
  if (!j.contains("transport")) j["transport"] = spec;
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
        {{"device", p}, {"driver", nullptr}, {"detail", "serial port: try --probe-serial " + p}});
  for (const auto& p : o.tcp_probes) out["probes"].push_back(probe("tcp", p));
  for (const auto& p : o.serial_probes) out["probes"].push_back(probe("serial", p));
  return out;
}

namespace {

// ---- the drivers and their options (daq devices --options; the JSON is the set-up page's too) --

std::string range_text(const cal::drivers::OptionSpec& o) {
  if (!o.choices.empty()) return fmt::format("{}", fmt::join(o.choices, ", "));
  if (o.min && o.max) return fmt::format("{} .. {}", *o.min, *o.max);
  if (o.min) return fmt::format(">= {}", *o.min);
  if (o.max) return fmt::format("<= {}", *o.max);
  return "";
}

void print_options_text() {
  fmt::print("Keys of every [devices.ID] table: {}\n",
             fmt::join(cal::drivers::common_device_keys(), ", "));
  for (const auto* d : cal::drivers::device_drivers()) {
    fmt::print("\n{}  {}\n  transport: {}\n", d->name(), d->description(), d->transport_example());
    if (d->options().empty()) fmt::print("  (no options of its own)\n");
    for (const auto& o : d->options()) {
      const auto def = cal::drivers::format_option_value(o.default_value);
      fmt::print("  {:<22} {:<13} {:<18} default {:<12} {}\n", o.name,
                 cal::drivers::to_string(o.type),
                 range_text(o) + (o.unit.empty() ? "" : " " + o.unit),
                 def.empty() ? "(derived)" : def, o.help);
    }
  }
}

// The table cells may hold '|': escaped for Markdown.
std::string cell(std::string s) {
  for (std::size_t at = 0; (at = s.find('|', at)) != std::string::npos; at += 2) s.insert(at, "\\");
  return s;
}

void print_options_markdown() {
  fmt::print("Every `[devices.ID]` table takes the common keys {}; each driver adds its own:\n",
             fmt::join(cal::drivers::common_device_keys(), ", "));
  for (const auto* d : cal::drivers::device_drivers()) {
    fmt::print("\n### `{}`: {}\n\n", d->name(), d->description());
    fmt::print("Transport: `{}`. `daq decode {}` reads {}.\n\n", d->transport_example(), d->name(),
               d->decode_input());
    if (d->options().empty()) {
      fmt::print("No options of its own.\n");
      continue;
    }
    fmt::print("| key | type | unit | values | default | meaning |\n");
    fmt::print("| --- | --- | --- | --- | --- | --- |\n");
    for (const auto& o : d->options()) {
      const auto def = cal::drivers::format_option_value(o.default_value);
      fmt::print("| `{}` | {} | {} | {} | {} | {} |\n", o.name, cal::drivers::to_string(o.type),
                 o.unit, cell(range_text(o)), def.empty() ? "(derived)" : "`" + cell(def) + "`",
                 cell(o.help));
    }
    if (!d->usb_ids().empty()) {
      std::vector<std::string> ids;
      for (const auto& k : d->usb_ids())
        ids.push_back(fmt::format("`{:04x}:{:04x}` {}", k.vendor_id, k.product_id, k.description));
      fmt::print("\nUSB ids: {}.\n", fmt::join(ids, "; "));
    }
  }
}

void print_text(const json& j) {
  const auto driver = [](const json& d) {
    return d.is_null() ? std::string("-") : d.get<std::string>();
  };
  print_line("USB devices ({}):", j["usb"].size());
  for (const auto& d : j["usb"])
    print_line("  {}  port {:<10} driver {:<8} {}", d["vid_pid"].get<std::string>(),
               d["port"].get<std::string>(), driver(d["driver"]),
               d["description"].get<std::string>());
  if (j.contains("usb_error"))
    print_line("  (cannot enumerate: {})", j["usb_error"].get<std::string>());
  print_line("HID instruments ({}):", j["hid"].size());
  for (const auto& d : j["hid"])
    print_line("  {}  {}  interface {}  driver {}", d["vid_pid"].get<std::string>(),
               d["path"].get<std::string>(), d["interface"].get<int>(), driver(d["driver"]));
  print_line("Serial ports ({}):", j["serial"].size());
  for (const auto& d : j["serial"]) print_line("  {}", d["device"].get<std::string>());
  if (!j["probes"].empty()) print_line("Probes:");
  for (const auto& d : j["probes"])
    print_line("  {:<40} driver {:<8} {}", d["transport"].get<std::string>(), driver(d["driver"]),
               d["detail"].get<std::string>());
}

}  // namespace

void add_devices_command(CLI::App& app) {
  auto opts = std::make_shared<DevicesOptions>();
  CLI::App* cmd = app.add_subcommand(
      "devices",
      "List attached USB/HID instruments and serial ports, and probe networked or serial "
      "instruments");
  // The probes' help names the drivers that probe each kind of transport (from the registry).
  std::vector<std::string> tcp, serial;
  for (const auto* d : cal::drivers::device_drivers())
    if (const auto p = d->probe()) {
      if (p->transport_kind == "tcp")
        tcp.push_back(fmt::format("{} on port {}", d->name(), p->default_port));
      else
        serial.push_back(fmt::format("{} at {}", d->name(), p->default_serial));
    }
  cmd->add_option(
      "--probe", opts->tcp_probes,
      fmt::format("Ask HOST[:PORT] with each network driver's probe ({})", fmt::join(tcp, ", ")));
  cmd->add_option("--probe-serial", opts->serial_probes,
                  fmt::format("Ask DEVICE[@SETTINGS] with each serial driver's probe ({})",
                              fmt::join(serial, ", ")));
  cmd->add_flag("--options", opts->options,
                "List the drivers and the options of each ([devices.ID] keys, daq decode --set)");
  cmd->add_flag("--markdown", opts->markdown, "With --options: as the Markdown of docs/drivers.md");
  cmd->add_flag("--json", opts->json,
                "Print caldaq.devices.v1 JSON (with --options: caldaq.drivers.v1)");
  cmd->callback([opts] {
    if (opts->options) {
      if (opts->json)
        return fmt::print("{}\n", cal::daq::dump_output(serve::driver_descriptions(), 2));
      return opts->markdown ? print_options_markdown() : print_options_text();
    }
    const json j = list_devices(*opts);
    if (opts->json)
      fmt::print("{}\n", cal::daq::dump_output(j, 2));
    else
      print_text(j);
  });
}

}  // namespace daq
