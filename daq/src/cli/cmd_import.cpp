// daq import rtx FILE: a Renishaw dynamic capture (.rtx) as a stored run, so that it can be
// listed, shown, exported and compared with runs measured here.
#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "cal/analysis/error.hpp"
#include "cal/analysis/text.hpp"
#include "cal/drivers/codec/common.hpp"
#include "cal/drivers/instrument.hpp"
#include "cal/replay/rtx.hpp"
#include "cal/storage/store.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "database.hpp"
#include "json_input.hpp"
#include "terminal.hpp"

namespace daq {
namespace {

using nlohmann::json;
namespace st = cal::storage;

struct ImportOptions {
  std::string file, db, unit, axis, machine, campaign, header_encoding = "utf-8";
  bool json = false;
};

// What the samples are, from the header's File Type, and their unit from --unit (the .rtx
// header does not state it): a linear capture is a displacement (default unit mm), an angular
// one an angle (no default: the unit must be given).
struct Interpretation {
  cal::drivers::Quantity quantity;
  std::string unit;    // as given or defaulted
  double si_per_unit;  // metres or radians per unit
  std::string si;      // "m" or "rad"
  // si_per_unit as an exact decimal (mm {1, -3}, in {254, -4}); multiplier 0 for arcsec and
  // deg (pi is no decimal). With it a sample that stands for a decimal (its shortest form has
  // at most 15 digits) is stored as that decimal in SI, correctly rounded (scaled_double).
  cal::drivers::codec::DecimalScale exact{0, 0};
};

Interpretation interpret(cal::replay::RtxKind kind, const std::string& unit,
                         const std::string& file) {
  using Q = cal::drivers::Quantity;
  constexpr double pi = 3.14159265358979323846;
  if (kind == cal::replay::RtxKind::linear) {
    const std::string u = unit.empty() ? "mm" : unit;
    using namespace cal::drivers::codec;
    if (u == "mm") return {Q::displacement_m, u, 1e-3, "m", kMillimetresToMetres};
    if (u == "um") return {Q::displacement_m, u, 1e-6, "m", kMicrometresToMetres};
    if (u == "m") return {Q::displacement_m, u, 1.0, "m", kUnitScale};
    if (u == "in") return {Q::displacement_m, u, 25.4e-3, "m", kInchesToMetres};
    throw cal::InputError(
        fmt::format("{}: a Linear capture: --unit '{}' (expected mm, um, m or in)", file, u));
  }
  if (unit == "arcsec") return {Q::angle_rad, unit, pi / (180.0 * 3600.0), "rad"};
  if (unit == "urad" || unit == "um/m")
    return {Q::angle_rad, unit, 1e-6, "rad", cal::drivers::codec::kMicrometresToMetres};
  if (unit == "mrad" || unit == "mm/m")
    return {Q::angle_rad, unit, 1e-3, "rad", cal::drivers::codec::kMillimetresToMetres};
  if (unit == "deg") return {Q::angle_rad, unit, pi / 180.0, "rad"};
  throw cal::InputError(fmt::format(
      "{}: an Angular capture: give --unit arcsec, urad, um/m, mrad, mm/m or deg (the .rtx "
      "header does not state the unit{})",
      file, unit.empty() ? "" : fmt::format("; '{}' is not an angle unit", unit)));
}

struct ImportSummary {
  std::int64_t run_id = 0;
  std::uint64_t samples = 0, invalid = 0;
  double min_m = INFINITY, max_m = -INFINITY;
};

// Streams the samples into the run in chunks: a 50 kHz capture of an hour is 180 M samples.
void copy_samples(cal::replay::RtxReader& r, st::Store& store, const Interpretation& how,
                  ImportSummary& s) {
  const double scale = how.si_per_unit;
  const double rate = r.header().sample_rate_hz;
  std::vector<double> buf(1 << 16);
  std::vector<st::RawReading> rows;
  while (const auto n = r.read(buf)) {
    rows.clear();
    for (std::size_t i = 0; i < n; ++i, ++s.samples) {
      const double v = how.exact.multiplier != 0
                           ? cal::drivers::codec::scaled_double(buf[i], how.exact)
                           : buf[i] * scale;
      const bool ok = std::isfinite(v);
      if (ok) s.min_m = std::min(s.min_m, v), s.max_m = std::max(s.max_m, v);
      s.invalid += ok ? 0 : 1;
      rows.push_back(
          {.time_ns = std::llround(static_cast<double>(s.samples) * 1e9 / rate),
           .quantity = static_cast<std::uint8_t>(how.quantity),
           .status = static_cast<std::uint8_t>(ok ? cal::drivers::ReadingStatus::ok
                                                  : cal::drivers::ReadingStatus::out_of_range),
           .value = ok ? v : 0.0});
    }
    store.append_readings(s.run_id, rows);
  }
}

void import_rtx(const ImportOptions& o) {
  cal::replay::RtxReader reader(o.file, o.header_encoding == "windows-1252"
                                            ? cal::replay::RtxHeaderEncoding::windows1252
                                            : cal::replay::RtxHeaderEncoding::utf8);
  const auto& h = reader.header();
  const Interpretation how = interpret(h.kind, o.unit, o.file);
  for (const auto& [text, option] :
       {std::pair{&o.machine, "--machine"}, {&o.axis, "--axis"}, {&o.campaign, "--campaign"}})
    cal::text::require_utf8(*text, option);
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
  if (!h.eof_marker) notes.push_back("no end marker (\\r\\nEOF): the file may be truncated");
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
                      {"file_type", h.kind == cal::replay::RtxKind::linear ? "linear" : "angular"},
                      {"quantity", cal::drivers::to_string(how.quantity)},
                      {"unit", how.unit},
                      {"unit_from", o.unit.empty() ? "the default of a linear capture (the .rtx "
                                                     "header does not state it)"
                                                   : "the --unit option (the .rtx header does "
                                                     "not state it)"},
                      {"header", header},
                      {"header_encoding", o.header_encoding},
                      {"notes", notes}};
  ImportSummary s;
  s.run_id = store.begin_run({.machine_id = machine_id,
                              .campaign = o.campaign,
                              .kind = "dynamic",
                              .axis = o.axis.empty() ? field("Axis") : o.axis,
                              // The path as the file system has it may not be UTF-8: shown
                              // with U+FFFD there (the header itself is UTF-8 by now).
                              .settings_json = cal::daq::dump_output(settings),
                              .software_version = "daq 0.1.0 import rtx"});
  store.add_instrument(
      {.run_id = s.run_id,
       .device = 0,
       .driver = "renishaw-rtx (" + field("Owner") + " " + field("Version no") + ")",
       .transport = "file " + o.file,
       .settings_json = json{{"serial", field("Serial No")}}.dump(),
       .origin = "imported",
       .origin_detail = "Renishaw .rtx file " + o.file +
                        " (the file does not say whether the "
                        "instrument was real)"});
  try {
    copy_samples(reader, store, how, s);
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
           {"quantity", cal::drivers::to_string(how.quantity)},
           {"notes", notes}};
    if (s.samples > s.invalid) {
      j[fmt::format("min_{}", how.si)] = s.min_m;
      j[fmt::format("max_{}", how.si)] = s.max_m;
    }
    return fmt::print("{}\n", cal::daq::dump_output(j, 2));
  }
  print_line("imported {} into run {}: {} {} samples at {} Hz ({:.3f} s), unit {}{}", o.file,
             s.run_id, s.samples, h.kind == cal::replay::RtxKind::linear ? "linear" : "angular",
             h.sample_rate_hz, static_cast<double>(s.samples) / h.sample_rate_hz, how.unit,
             o.unit.empty() ? " (the default; the header does not state it)" : " (from --unit)");
  if (s.samples > s.invalid && how.si == "m")
    print_line("  range {:.6f} .. {:.6f} mm", s.min_m * 1e3, s.max_m * 1e3);
  else if (s.samples > s.invalid)
    print_line("  range {:.3f} .. {:.3f} arcsec", s.min_m * 180 * 3600 / 3.14159265358979323846,
               s.max_m * 180 * 3600 / 3.14159265358979323846);
  if (s.invalid)
    print_line("  {} samples are not finite numbers: stored as out of range", s.invalid);
  for (const auto& n : notes) print_line("  note: {}", n);
}

}  // namespace

void add_import_commands(CLI::App& app) {
  auto o = std::make_shared<ImportOptions>();
  auto* imp = add_group(app, "import", "Import a measurement made with other software");
  auto* rtx = imp->add_subcommand("rtx", "Renishaw dynamic capture (.rtx) as a stored run");
  rtx->add_option("FILE", o->file, "The .rtx file")->required();
  add_db_option(*rtx, o->db);
  rtx->add_option("--unit", o->unit,
                  "Unit of the samples: mm (default), um, m or in for a Linear capture; arcsec, "
                  "urad, um/m, mrad, mm/m or deg for an Angular one (required)");
  rtx->add_option("--axis", o->axis, "Axis name (default: the header's Axis)");
  rtx->add_option("--machine", o->machine, "Machine name (default: the header's Machine)");
  rtx->add_option("--campaign", o->campaign, "Campaign to file the run under");
  rtx->add_option("--header-encoding", o->header_encoding,
                  "utf-8 (default: other bytes are refused) or windows-1252 (a header written "
                  "in the Western Windows code page, converted to UTF-8)")
      ->check(CLI::IsMember({"utf-8", "windows-1252"}));
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
