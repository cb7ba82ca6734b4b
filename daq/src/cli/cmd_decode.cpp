// daq decode DRIVER FILE|-: what a driver makes of a dump of bytes (docs/cli.md), in the spirit
// of sigrok-cli's input decoders. The bytes go through the driver's own codec (the registry's
// decoder), so this is what a run would read from the same device.
#include <fmt/format.h>

#include <cstdio>
#include <ctime>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "cal/analysis/enum_names.hpp"
#include "cal/analysis/error.hpp"
#include "cal/analysis/text.hpp"
#include "cal/drivers/registry.hpp"
#include "command.hpp"
#include "commands.hpp"

namespace daq {
namespace {

namespace d = cal::drivers;
using cal::text::terminal_safe;
using nlohmann::json;

struct DecodeOptions {
  std::string driver, input;
  std::vector<std::string> set;  // KEY=VALUE
  bool json = false;
};

std::string_view unit_of(d::Quantity q) {
  using enum d::Quantity;
  static constexpr cal::EnumName<d::Quantity> kNames[] = {{displacement_m, "m"},
                                                          {length_m, "m"},
                                                          {machine_position_m, "m"},
                                                          {air_temperature_degc, "degC"},
                                                          {material_temperature_degc, "degC"},
                                                          {dew_point_degc, "degC"},
                                                          {air_pressure_pa, "Pa"},
                                                          {air_humidity_pct, "%RH"},
                                                          {angle_rad, "rad"},
                                                          {refractive_index, ""}};
  static_assert(cal::names_every_value(kNames));
  return cal::name_of(kNames, q, "");
}

// The device's time as printed: UTC with nanoseconds, or seconds since the stream's start.
std::string time_text(const d::DecodedItem& i) {
  if (!i.time_text.empty()) return i.time_text;
  if (i.device_time_unix_ns) {
    const std::int64_t ns = *i.device_time_unix_ns;
    const std::int64_t s = ns / 1'000'000'000 - (ns % 1'000'000'000 < 0);
    return fmt::format("{}.{:09}Z", cal::text::utc_text(s, "%Y-%m-%dT%H:%M:%S"),
                       ((ns % 1'000'000'000) + 1'000'000'000) % 1'000'000'000);
  }
  if (i.device_time_relative_s) return fmt::format("+{:.6f} s", *i.device_time_relative_s);
  return {};
}

json item_json(const d::DecodedItem& i) {
  json j{{"schema", "caldaq.decode.v1"}, {"type", d::to_string(i.kind)}, {"offset", i.offset}};
  switch (i.kind) {
    case d::DecodedItem::Kind::reading: {
      const auto t = time_text(i);
      j["device_time"] = t.empty() ? json(nullptr) : json(t);
      if (i.device_time_unix_ns) j["device_time_unix_ns"] = *i.device_time_unix_ns;
      if (i.device_time_relative_s) j["device_time_relative_s"] = *i.device_time_relative_s;
      if (i.sample) j["sample"] = *i.sample;
      j["channel"] = i.channel;
      j["quantity"] = d::to_string(i.quantity);
      j["value"] = i.value;
      j["unit"] = unit_of(i.quantity);
      j["status"] = d::to_string(i.status);
      break;
    }
    case d::DecodedItem::Kind::error:
      j["kind"] = i.error_kind;
      j["reason"] = i.text;
      break;
    case d::DecodedItem::Kind::gap:
      j["reason"] = i.text;
      j["lost_samples"] = i.lost_samples ? json(*i.lost_samples) : json(nullptr);
      break;
    case d::DecodedItem::Kind::note:
      j["text"] = i.text;
      break;
  }
  return j;
}

void print_item(const d::DecodedItem& i) {
  switch (i.kind) {
    case d::DecodedItem::Kind::reading: {
      // The device's time, else its sample number (halsampler -t), else "-".
      auto t = time_text(i);
      if (t.empty() && i.sample) t = fmt::format("sample {}", *i.sample);
      fmt::print("{:>9}  {:<31} ch {}  {:<26} {:>16.9g} {:<4} {}\n", i.offset,
                 t.empty() ? "-" : terminal_safe(t), i.channel, d::to_string(i.quantity), i.value,
                 unit_of(i.quantity), d::to_string(i.status));
      return;
    }
    case d::DecodedItem::Kind::error:
      fmt::print("{:>9}  error ({}): {}\n", i.offset, terminal_safe(i.error_kind),
                 terminal_safe(i.text));
      return;
    case d::DecodedItem::Kind::gap:
      fmt::print("{:>9}  gap: {}\n", i.offset, terminal_safe(i.text));
      return;
    case d::DecodedItem::Kind::note:
      fmt::print("{:>9}  note: {}\n", i.offset, terminal_safe(i.text));
      return;
  }
}

void run_decode(const DecodeOptions& o) {
  const auto& drv = d::driver(o.driver);
  std::vector<std::pair<std::string, std::string>> set;
  for (const auto& kv : o.set) {
    const auto eq = kv.find('=');
    if (eq == std::string::npos || eq == 0)
      throw cal::InputError(fmt::format("--set '{}': expected KEY=VALUE", kv));
    set.emplace_back(kv.substr(0, eq), kv.substr(eq + 1));
  }
  const auto options = d::options_from_text(drv, set);
  auto decoder = drv.make_decoder(options);

  std::ifstream file;
  std::istream* in = &std::cin;
  if (o.input != "-") {
    file.open(o.input, std::ios::binary);
    if (!file) throw cal::InputError(fmt::format("{}: cannot open", o.input));
    in = &file;
  }
  std::size_t readings = 0, errors = 0, gaps = 0;
  std::vector<d::DecodedItem> items;
  const auto flush = [&] {
    for (const auto& i : items) {
      readings += i.kind == d::DecodedItem::Kind::reading;
      errors += i.kind == d::DecodedItem::Kind::error;
      gaps += i.kind == d::DecodedItem::Kind::gap;
      // The codec quotes the bytes it could not read; where they are not UTF-8 they are shown
      // as U+FFFD (not \u00XX, which would claim they were Latin-1): the item's offset says
      // where the exact bytes are in the dump.
      if (o.json)
        fmt::print("{}\n", item_json(i).dump(-1, ' ', false, json::error_handler_t::replace));
      else
        print_item(i);
    }
    items.clear();
  };
  // Line by line (the last piece as it is), so that the items come out in stream order.
  std::string line;
  while (std::getline(*in, line)) {
    if (!in->eof()) line.push_back('\n');
    decoder->feed(std::as_bytes(std::span(line.data(), line.size())), items);
    flush();
  }
  if (in->bad()) throw cal::InputError(fmt::format("{}: read error", o.input));
  decoder->finish(items);
  flush();
  const auto& stats = decoder->stats();
  if (o.json)
    return fmt::print("{}\n", json{{"schema", "caldaq.decode.v1"},
                                   {"type", "summary"},
                                   {"driver", drv.name()},
                                   {"bytes", stats.bytes},
                                   {"frames", stats.frames},
                                   {"readings", readings},
                                   {"errors", errors},
                                   {"gaps", gaps}}
                                  .dump());
  fmt::print("{}: {} bytes, {} frames, {} readings, {} errors, {} gaps\n", drv.name(), stats.bytes,
             stats.frames, readings, errors, gaps);
}

}  // namespace

void add_decode_command(CLI::App& app) {
  const auto [cmd, o] = add_command<DecodeOptions>(
      app, "decode", run_decode,
      "Run a dump of a device's bytes through its driver's codec and print every reading and "
      "every codec error (docs/cli.md)");
  cmd->add_option("DRIVER", o->driver,
                  fmt::format("The driver ({})", fmt::join(d::driver_names(), ", ")))
      ->required();
  cmd->add_option("FILE", o->input, "The dump, or - for stdin")->required();
  cmd->add_option("--set", o->set,
                  "KEY=VALUE: an option of the driver, as in its [devices.ID] table "
                  "(daq devices --options)");
  cmd->add_flag("--json", o->json, "One caldaq.decode.v1 JSON object per line");
}

}  // namespace daq
