// daq import rtx FILE: a Renishaw dynamic capture (.rtx) as a stored run, so that it can be
// listed, shown, exported and compared with runs measured here.
#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "cal/analysis/error.hpp"
#include "cal/drivers/instrument.hpp"
#include "cal/replay/rtx.hpp"
#include "cal/storage/store.hpp"
#include "commands.hpp"
#include "database.hpp"

namespace daq {
namespace {

using nlohmann::json;
namespace st = cal::storage;

struct ImportOptions {
  std::string file, db, unit = "mm", axis, machine, campaign;
  bool json = false;
};

double metres_per_unit(const std::string& unit) {
  if (unit == "mm") return 1e-3;
  if (unit == "um") return 1e-6;
  if (unit == "m") return 1.0;
  if (unit == "in") return 25.4e-3;
  throw cal::InputError(fmt::format("--unit '{}' (expected mm, um, m or in)", unit));
}

struct ImportSummary {
  std::int64_t run_id = 0;
  std::uint64_t samples = 0, invalid = 0;
  double min_m = INFINITY, max_m = -INFINITY;
};

// Streams the samples into the run in chunks: a 50 kHz capture of an hour is 180 M samples.
void copy_samples(cal::replay::RtxReader& r, st::Store& store, double scale, ImportSummary& s) {
  const double rate = r.header().sample_rate_hz;
  std::vector<double> buf(1 << 16);
  std::vector<st::RawReading> rows;
  while (const auto n = r.read(buf)) {
    rows.clear();
    for (std::size_t i = 0; i < n; ++i, ++s.samples) {
      const double v = buf[i] * scale;
      const bool ok = std::isfinite(v);
      if (ok) s.min_m = std::min(s.min_m, v), s.max_m = std::max(s.max_m, v);
      s.invalid += ok ? 0 : 1;
      rows.push_back(
          {.time_ns = std::llround(static_cast<double>(s.samples) * 1e9 / rate),
           .quantity = static_cast<std::uint8_t>(cal::drivers::Quantity::displacement_m),
           .status = static_cast<std::uint8_t>(ok ? cal::drivers::ReadingStatus::ok
                                                  : cal::drivers::ReadingStatus::out_of_range),
           .value = ok ? v : 0.0});
    }
    store.append_readings(s.run_id, rows);
  }
}

void import_rtx(const ImportOptions& o) {
  const double scale = metres_per_unit(o.unit);
  cal::replay::RtxReader reader(o.file);
  const auto& h = reader.header();
  json header = json::object();
  for (const auto& [k, v] : h.fields) header[k] = v;
  const auto field = [&](const char* key) {
    const auto* v = h.find(key);
    return v ? *v : std::string{};
  };
  std::vector<std::string> notes;
  if (h.trailing_bytes)
    notes.push_back(
        fmt::format("the file ends inside a sample ({} bytes dropped)", h.trailing_bytes));
  if (!h.eof_marker) notes.push_back("no EOF:: marker: the file may be truncated");
  if (h.declared_samples && *h.declared_samples != h.samples)
    notes.push_back(fmt::format("the header declares {} samples, the file holds {}",
                                *h.declared_samples, h.samples));

  st::Store store(database_path(o.db));
  const std::string machine = !o.machine.empty()          ? o.machine
                              : !field("Machine").empty() ? field("Machine")
                                                          : "imported";
  std::int64_t machine_id = 0;
  if (auto m = store.machine_by_name(machine))
    machine_id = m->id;
  else
    machine_id = store.add_machine({.name = machine, .description = "from a Renishaw .rtx file"});
  const json settings{{"source", std::filesystem::absolute(o.file).string()},
                      {"format", "renishaw-rtx"},
                      {"sample_rate_hz", h.sample_rate_hz},
                      {"unit", o.unit},
                      {"unit_from", "the --unit option (the .rtx header does not state it)"},
                      {"header", header},
                      {"notes", notes}};
  ImportSummary s;
  s.run_id = store.begin_run({.machine_id = machine_id,
                              .campaign = o.campaign,
                              .kind = "dynamic",
                              .axis = o.axis.empty() ? field("Axis") : o.axis,
                              .settings_json = settings.dump(),
                              .software_version = "daq 0.1.0 import rtx"});
  store.add_instrument(
      {.run_id = s.run_id,
       .device = 0,
       .driver = "renishaw-rtx (" + field("Owner") + " " + field("Version no") + ")",
       .transport = "file " + o.file,
       .settings_json = json{{"serial", field("Serial No")}}.dump()});
  try {
    copy_samples(reader, store, scale, s);
  } catch (const std::exception& e) {
    store.finish_run(s.run_id, st::RunStatus::incomplete, e.what());
    throw;
  }
  std::string note;
  for (const auto& n : notes) note += (note.empty() ? "" : "; ") + n;
  store.finish_run(s.run_id, notes.empty() ? st::RunStatus::complete : st::RunStatus::incomplete,
                   note);
  if (o.json) {
    json j{{"schema", "caldaq.import.v1"},
           {"run_id", s.run_id},
           {"samples", s.samples},
           {"invalid", s.invalid},
           {"sample_rate_hz", h.sample_rate_hz},
           {"duration_s", static_cast<double>(s.samples) / h.sample_rate_hz},
           {"notes", notes}};
    if (s.samples > s.invalid) j["min_m"] = s.min_m, j["max_m"] = s.max_m;
    return fmt::print("{}\n", j.dump(2));
  }
  fmt::print("imported {} into run {}: {} samples at {} Hz ({:.3f} s), unit {} (from --unit)\n",
             o.file, s.run_id, s.samples, h.sample_rate_hz,
             static_cast<double>(s.samples) / h.sample_rate_hz, o.unit);
  if (s.samples > s.invalid)
    fmt::print("  range {:.6f} .. {:.6f} mm\n", s.min_m * 1e3, s.max_m * 1e3);
  if (s.invalid)
    fmt::print("  {} samples are not finite numbers: stored as out of range\n", s.invalid);
  for (const auto& n : notes) fmt::print("  note: {}\n", n);
}

}  // namespace

void add_import_commands(CLI::App& app) {
  auto o = std::make_shared<ImportOptions>();
  auto* imp = app.add_subcommand("import", "Import a measurement made with other software");
  imp->require_subcommand(1);
  auto* rtx = imp->add_subcommand("rtx", "Renishaw dynamic capture (.rtx) as a stored run");
  rtx->add_option("FILE", o->file, "The .rtx file")->required();
  add_db_option(*rtx, o->db);
  rtx->add_option("--unit", o->unit, "Unit of the samples: mm, um, m or in")->capture_default_str();
  rtx->add_option("--axis", o->axis, "Axis name (default: the header's Axis)");
  rtx->add_option("--machine", o->machine, "Machine name (default: the header's Machine)");
  rtx->add_option("--campaign", o->campaign, "Campaign to file the run under");
  rtx->add_flag("--json", o->json, "Print caldaq.import.v1 JSON");
  rtx->callback([o] {
    try {
      import_rtx(*o);
    } catch (const cal::replay::RtxError& e) {
      throw cal::InputError(e.what());
    }
  });
}

}  // namespace daq
