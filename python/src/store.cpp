// caldaq.Store: a run store opened from Python (read-only by default). Records come out as
// plain dicts (the JSON documents as text, parsed on the Python side); readings as chunks of
// numpy arrays, streamed in bounded memory.
//
// One Store is one SQLite connection: every call on it, and on the streams reading through
// it, holds the store's own mutex with the GIL released, so Python threads may share it.
#include "cal/storage/store.hpp"

#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <set>
#include <unordered_map>

#include "bindings.hpp"
#include "cal/analysis/error.hpp"
#include "cal/drivers/instrument.hpp"
#include "json_input.hpp"
#include "reading_compensation.hpp"
#include "reading_times.hpp"

namespace py = pybind11;
namespace st = cal::storage;
using namespace pybind11::literals;  // "name"_a = value: a dict's fields in one call

namespace caldaq_py {
namespace {

struct SharedStore {
  SharedStore(const std::string& path, st::StoreOptions o) : store(path, o) {}
  st::Store store;
  std::mutex mutex;
};

// Runs f on the store with the GIL released and the store's mutex held.
template <class F>
auto locked(SharedStore& s, F&& f) {
  py::gil_scoped_release release;
  std::lock_guard lock(s.mutex);
  return f(s.store);
}

// A stored direction ('+' or '-') as the dicts name it.
const char* direction_name(char direction) { return direction == '+' ? "up" : "down"; }

template <class T>
py::object optional_value(const std::optional<T>& v) {
  return v ? py::cast(*v) : py::none();
}

py::dict run_dict(const st::RunRecord& r) {
  return py::dict("id"_a = r.id, "machine_id"_a = r.machine_id, "campaign"_a = r.campaign,
                  "kind"_a = r.kind, "axis"_a = r.axis, "settings_json"_a = r.settings_json,
                  "capture_path"_a = r.capture_path, "software_version"_a = r.software_version,
                  "started_unix_ms"_a = r.started_unix_ms,
                  "ended_unix_ms"_a = optional_value(r.ended_unix_ms),
                  "status"_a = std::string(st::to_string(r.status)), "note"_a = r.note,
                  "origin_session_ns"_a = optional_value(r.origin_session_ns),
                  "origin_unix_ns"_a = optional_value(r.origin_unix_ns));
}

py::dict instrument_dict(const st::InstrumentRecord& i) {
  return py::dict("device"_a = i.device, "driver"_a = i.driver, "transport"_a = i.transport,
                  "settings_json"_a = i.settings_json, "origin"_a = i.origin,
                  "origin_detail"_a = i.origin_detail);
}

py::dict target_dict(const st::CapturedTarget& t) {
  return py::dict("target_index"_a = t.target_index, "run"_a = t.run_number,
                  "direction"_a = direction_name(t.direction), "nominal_mm"_a = t.nominal_mm,
                  "time_ns"_a = t.time_ns, "raw_m"_a = t.raw_m, "deviation_um"_a = t.deviation_um,
                  "refractive_index"_a = t.refractive_index,
                  "material_temperature_degc"_a = t.material_temperature_degc);
}

py::dict result_dict(const st::ResultRecord& r) {
  return py::dict("id"_a = r.id, "standard"_a = r.standard, "json"_a = r.json,
                  "created_unix_ms"_a = r.created_unix_ms, "provenance_json"_a = r.provenance_json,
                  "superseded_by"_a = optional_value(r.superseded_by), "current"_a = r.current());
}

py::dict missed_dict(const st::MissedStop& m) {
  return py::dict("run"_a = m.run_number, "direction"_a = direction_name(m.direction),
                  "target_index"_a = m.target_index, "nominal_mm"_a = m.nominal_mm);
}

py::object quality_obj(const std::optional<st::RunQuality>& q) {
  if (!q) return py::none();
  py::list suspects;
  for (const auto& s : q->suspects)
    suspects.append(py::dict("run"_a = s.run_number, "direction"_a = direction_name(s.direction),
                             "target_index"_a = s.target_index, "reason"_a = s.reason));
  return py::dict("state"_a = q->state, "summary"_a = q->summary, "suspects"_a = suspects);
}

py::dict compensation_dict(const st::CompensationRecord& c) {
  return py::dict("id"_a = c.id, "machine_id"_a = c.machine_id, "source_run_id"_a = c.source_run_id,
                  "source"_a = c.source, "axis"_a = c.axis, "format"_a = c.format,
                  "created_unix_ms"_a = c.created_unix_ms, "json"_a = c.json);
}

py::dict machine_dict(const st::MachineRecord& m) {
  return py::dict("id"_a = m.id, "name"_a = m.name, "description"_a = m.description,
                  "config_json"_a = m.config_json);
}

template <class T, class F>
py::list list_of(const std::vector<T>& v, F&& f) {
  py::list out;
  for (const auto& x : v) out.append(f(x));
  return out;
}

// A Store method that lists one run's records (instruments, targets, ...) as a Python method
// that returns them as dicts.
template <class Get, class F>
auto run_records(Get get, F to_dict) {
  return [get, to_dict](SharedStore& s, std::int64_t run_id) {
    return list_of(locked(s, [&](st::Store& st) { return std::invoke(get, st, run_id); }), to_dict);
  };
}

// A column of a chunk as a new numpy array.
template <class T, class Rows, class Get>
py::array_t<T> column(const Rows& rows, Get get) {
  py::array_t<T> a(static_cast<py::ssize_t>(rows.size()));
  T* p = a.mutable_data();
  for (std::size_t k = 0; k < rows.size(); ++k) p[k] = get(rows[k]);
  return a;
}

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A run's readings a chunk at a time, in the order and with the times of `daq export`
// (reading_times.hpp: a group of readings from one transport read spread back by the sample
// period), optionally with each laser reading's compensation (reading_compensation.hpp); holds
// its store (and so its connection) alive. Memory: a chunk, the readings of one stored time,
// and the compensation stage's 2 minutes of environment.
class Stream {
 public:
  Stream(std::shared_ptr<SharedStore> s, std::int64_t run_id, std::vector<std::uint8_t> quantities,
         std::size_t chunk, bool compensated)
      : store_(std::move(s)), chunk_(chunk), wanted_(quantities.begin(), quantities.end()) {
    if (chunk_ == 0) throw cal::InputError("chunk: expected a number of readings > 0, got 0");
    locked(*store_, [&](st::Store& st) {
      const auto run = st.run(run_id);
      if (!run)
        throw cal::InputError(
            fmt::format("{}: no run {} (see daq runs)", st.path().string(), run_id));
      const auto settings = cal::daq::parse_stored_json(run->settings_json);
      clock_ = std::make_unique<daq::ExportClock>(st, *run, settings);
      rows_ = std::make_unique<daq::ExportRows>(*clock_);
      if (compensated) {
        compensation_ = std::make_unique<daq::ReadingCompensation>(st, *run, settings);
        // The environment is read along even where only the laser's readings are asked for.
        if (!quantities.empty())
          for (const auto q : daq::ReadingCompensation::inputs())
            if (std::find(quantities.begin(), quantities.end(), q) == quantities.end())
              quantities.push_back(q);
      }
      stream_ = std::make_unique<st::ReadingStream>(st.stream_readings(run_id, quantities));
    });
  }

  // The next chunk as a dict of numpy arrays, or None at the end.
  // The stream is touched only under the store's lock, and each call takes its own rows, so
  // two threads calling next() on one stream get whole, distinct chunks.
  py::object next() {
    std::vector<daq::ExportRow> rows;
    std::vector<std::optional<cal::daq::Compensated>> comps;  // with compensation: one per row
    locked(*store_, [&](st::Store&) { take(rows, comps); });
    if (rows.empty()) return py::none();
    py::dict d;
    using Row = daq::ExportRow;
    d["time_ns"] = column<std::int64_t>(rows, [](const Row& x) { return x.r.time_ns; });
    d["device"] = column<std::uint16_t>(rows, [](const Row& x) { return x.r.device; });
    d["channel"] = column<std::uint8_t>(rows, [](const Row& x) { return x.r.channel; });
    d["quantity"] = column<std::uint8_t>(rows, [](const Row& x) { return x.r.quantity; });
    d["status"] = column<std::uint8_t>(rows, [](const Row& x) { return x.r.status; });
    d["value"] = column<double>(rows, [](const Row& x) { return x.r.value; });
    d["time_s"] = column<double>(rows, [&](const Row& x) { return clock_->seconds(x.session_ns); });
    // Unix ns as `daq export` rounds them (it prints them to the microsecond); -2^63 is NaT.
    d["utc_ns"] = column<std::int64_t>(rows, [&](const Row& x) {
      return clock_->unix_ns(x.session_ns).value_or(std::numeric_limits<std::int64_t>::min());
    });
    if (compensation_) {
      // NaN where a reading has none (not the laser's displacement).
      using C = std::optional<cal::daq::Compensated>;
      d["compensated"] = column<double>(comps, [](const C& c) { return c ? c->length_m : kNaN; });
      d["refractive_index"] = column<double>(comps, [](const C& c) { return c ? c->n : kNaN; });
      d["material_temperature_degc"] =
          column<double>(comps, [](const C& c) { return c ? c->material_degc : kNaN; });
    }
    return d;
  }
  std::uint64_t chunks_read() {
    return locked(*store_,
                  [&](st::Store&) { return stream_ ? stream_->chunks_read() : chunks_done_; });
  }

 private:
  // Up to a chunk of rows (under the store's lock): reads on until that many are complete.
  void take(std::vector<daq::ExportRow>& rows,
            std::vector<std::optional<cal::daq::Compensated>>& comps) {
    rows.reserve(chunk_);
    while (rows.size() < chunk_) {
      if (head_ == ready_.size()) {
        ready_.clear();
        head_ = 0;
        if (!stream_) break;
        fill();
        continue;
      }
      const auto& x = ready_[head_++];
      if (wanted_.empty() || wanted_.count(x.r.quantity))
        rows.push_back(x);
      else if (compensation_)
        pending_.erase(x.tag);  // an environment reading read along for the compensation
    }
    if (!compensation_) return;
    comps.resize(rows.size());
    for (std::size_t k = 0; k < rows.size(); ++k)
      if (const auto it = pending_.find(rows[k].tag); it != pending_.end()) {
        comps[k] = it->second;
        pending_.erase(it);
      }
  }

  // The rows that the next stored batch completes, into ready_ (all of them at the end).
  void fill() {
    if (!stream_->next(batch_, chunk_)) {
      rows_->finish(ready_);
      chunks_done_ = stream_->chunks_read();
      stream_.reset();
      return;
    }
    for (const auto& r : batch_) {
      const std::uint64_t tag = next_tag_++;
      if (compensation_)
        if (const auto c = compensation_->add(r)) pending_[tag] = *c;
      rows_->add(r, ready_, tag);
    }
    batch_.clear();
  }

  std::shared_ptr<SharedStore> store_;
  std::size_t chunk_;
  std::set<std::uint8_t> wanted_;  // the quantities asked for (empty: all)
  std::unique_ptr<st::ReadingStream> stream_;
  std::unique_ptr<daq::ExportClock> clock_;
  std::unique_ptr<daq::ExportRows> rows_;
  std::unique_ptr<daq::ReadingCompensation> compensation_;
  std::vector<st::RawReading> batch_;
  std::vector<daq::ExportRow> ready_;  // complete rows, from head_ on
  std::size_t head_ = 0;
  std::unordered_map<std::uint64_t, cal::daq::Compensated> pending_;  // by the rows' tags
  std::uint64_t next_tag_ = 0;
  std::uint64_t chunks_done_ = 0;
};

template <class T>
using Column = py::array_t<T, py::array::c_style | py::array::forcecast>;

// Readings from equal-length columns, stored in one transaction (Store::append_readings).
void append_readings(SharedStore& s, std::int64_t run_id, const Column<std::int64_t>& time_ns,
                     const Column<std::uint16_t>& device, const Column<std::uint8_t>& channel,
                     const Column<std::uint8_t>& quantity, const Column<std::uint8_t>& status,
                     const Column<double>& value) {
  const auto n = time_ns.size();
  for (const auto* a :
       {static_cast<const py::array*>(&device), static_cast<const py::array*>(&channel),
        static_cast<const py::array*>(&quantity), static_cast<const py::array*>(&status),
        static_cast<const py::array*>(&value)})
    if (a->ndim() != 1 || a->size() != n)
      throw cal::InputError(fmt::format(
          "append_readings: expected 1-D columns of {} readings (as time_ns), got one of {}", n,
          a->size()));
  std::vector<st::RawReading> rs(static_cast<std::size_t>(n));
  for (py::ssize_t k = 0; k < n; ++k)
    rs[static_cast<std::size_t>(k)] = {time_ns.data()[k],  device.data()[k], channel.data()[k],
                                       quantity.data()[k], status.data()[k], value.data()[k]};
  locked(s, [&](st::Store& st) { st.append_readings(run_id, rs); });
}

std::shared_ptr<SharedStore> open_store(const std::string& path, bool read_only) {
  py::gil_scoped_release release;
  st::StoreOptions o;
  o.read_only = read_only;
  return std::make_shared<SharedStore>(path, o);
}

}  // namespace

void bind_store(py::module_& m) {
  py::list quantity_names;
  for (int q = 0; q <= static_cast<int>(cal::drivers::Quantity::angle_rad); ++q)
    quantity_names.append(
        std::string(cal::drivers::to_string(static_cast<cal::drivers::Quantity>(q))));
  m.attr("QUANTITIES") = py::tuple(quantity_names);
  m.attr("SCHEMA_VERSION") = st::schema_version;

  py::class_<Stream>(m, "ReadingStream")
      .def("next", &Stream::next)
      .def_property_readonly("chunks_read", &Stream::chunks_read);

  py::class_<SharedStore, std::shared_ptr<SharedStore>>(m, "Store")
      .def(py::init(&open_store), py::arg("path"), py::arg("read_only") = true)
      .def_property_readonly("path", [](SharedStore& s) { return s.store.path().string(); })
      .def_property_readonly("version", [](SharedStore& s) { return s.store.version(); })
      .def_property_readonly("read_only", [](SharedStore& s) { return s.store.read_only(); })
      .def("runs",
           [](SharedStore& s) {
             return list_of(locked(s, [](st::Store& st) { return st.runs(); }), run_dict);
           })
      .def("run",
           [](SharedStore& s, std::int64_t id) -> py::object {
             const auto r = locked(s, [&](st::Store& st) { return st.run(id); });
             return r ? py::object(run_dict(*r)) : py::none();
           })
      .def("machine",
           [](SharedStore& s, std::int64_t id) -> py::object {
             const auto r = locked(s, [&](st::Store& st) { return st.machine(id); });
             return r ? py::object(machine_dict(*r)) : py::none();
           })
      .def("instruments", run_records(&st::Store::instruments, instrument_dict))
      .def("series", run_records(&st::Store::series,
                                 [](const st::Store::Series& x) {
                                   return py::dict("device"_a = x.device, "channel"_a = x.channel,
                                                   "quantity"_a = x.quantity, "count"_a = x.count,
                                                   "first_ns"_a = x.first_ns,
                                                   "last_ns"_a = x.last_ns);
                                 }))
      .def("reading_count",
           [](SharedStore& s, std::int64_t id) {
             return locked(s, [&](st::Store& st) { return st.reading_count(id); });
           })
      .def("targets", run_records(&st::Store::targets, target_dict))
      .def("results", run_records(&st::Store::results, result_dict))
      .def("missed_stops", run_records(&st::Store::missed_stops, missed_dict))
      .def("quality",
           [](SharedStore& s, std::int64_t id) {
             return quality_obj(locked(s, [&](st::Store& st) { return st.quality(id); }));
           })
      .def(
          "compensations",
          [](SharedStore& s, std::int64_t machine_id, const std::string& axis) {
            return list_of(
                locked(s, [&](st::Store& st) { return st.compensations(machine_id, axis); }),
                compensation_dict);
          },
          py::arg("machine_id") = 0, py::arg("axis") = "")
      .def(
          "add_compensation",
          [](SharedStore& s, std::int64_t machine_id, const std::string& axis,
             const std::string& format, const std::string& json, const std::string& source,
             std::int64_t source_run_id) {
            st::CompensationRecord c{.machine_id = machine_id,
                                     .source_run_id = source_run_id,
                                     .source = source,
                                     .axis = axis,
                                     .format = format,
                                     .json = json};
            return locked(s, [&](st::Store& st) { return st.add_compensation(c); });
          },
          py::arg("machine_id"), py::arg("axis"), py::arg("format"), py::arg("json"),
          py::arg("source") = "", py::arg("source_run_id") = 0)
      // Writing (read_only=False): what an import or a test needs to store a run.
      .def(
          "add_machine",
          [](SharedStore& s, const std::string& name, const std::string& description) {
            return locked(s, [&](st::Store& st) {
              return st.add_machine({.name = name, .description = description});
            });
          },
          py::arg("name"), py::arg("description") = "")
      .def(
          "begin_run",
          [](SharedStore& s, std::int64_t machine_id, const std::string& kind,
             const std::string& axis, const std::string& campaign,
             const std::string& settings_json) {
            st::RunRecord r{.machine_id = machine_id,
                            .campaign = campaign,
                            .kind = kind,
                            .axis = axis,
                            .settings_json = settings_json,
                            .software_version = "caldaq python"};
            return locked(s, [&](st::Store& st) { return st.begin_run(r); });
          },
          py::arg("machine_id"), py::arg("kind"), py::arg("axis") = "", py::arg("campaign") = "",
          py::arg("settings_json") = "{}")
      .def(
          "add_instrument",
          [](SharedStore& s, std::int64_t run_id, int device, const std::string& driver,
             const std::string& transport, const std::string& origin,
             const std::string& origin_detail) {
            st::InstrumentRecord i{.run_id = run_id,
                                   .device = device,
                                   .driver = driver,
                                   .transport = transport,
                                   .origin = origin,
                                   .origin_detail = origin_detail};
            locked(s, [&](st::Store& st) { st.add_instrument(i); });
          },
          py::arg("run_id"), py::arg("device"), py::arg("driver"), py::arg("transport") = "",
          py::arg("origin") = "imported", py::arg("origin_detail") = "")
      .def("append_readings", &append_readings, py::arg("run_id"), py::arg("time_ns"),
           py::arg("device"), py::arg("channel"), py::arg("quantity"), py::arg("status"),
           py::arg("value"))
      .def(
          "set_time_origin",
          [](SharedStore& s, std::int64_t run_id, std::int64_t session_ns, std::int64_t unix_ns) {
            locked(s, [&](st::Store& st) { st.set_time_origin(run_id, session_ns, unix_ns); });
          },
          py::arg("run_id"), py::arg("session_ns"), py::arg("unix_ns"))
      .def(
          "finish_run",
          [](SharedStore& s, std::int64_t run_id, const std::string& status,
             const std::string& note) {
            const auto v =
                status == "complete"  ? st::RunStatus::complete
                : status == "aborted" ? st::RunStatus::aborted
                : status == "incomplete"
                    ? st::RunStatus::incomplete
                    : throw cal::InputError(fmt::format("status '{}': expected complete, "
                                                        "aborted or incomplete",
                                                        status));
            locked(s, [&](st::Store& st) { st.finish_run(run_id, v, note); });
          },
          py::arg("run_id"), py::arg("status") = "complete", py::arg("note") = "")
      .def(
          "stream",
          [](std::shared_ptr<SharedStore> s, std::int64_t run_id,
             std::vector<std::uint8_t> quantities, std::size_t chunk, bool compensated) {
            return Stream(std::move(s), run_id, std::move(quantities), chunk, compensated);
          },
          py::arg("run_id"), py::arg("quantities") = std::vector<std::uint8_t>{},
          py::arg("chunk") = 65536, py::arg("compensated") = false);
}

}  // namespace caldaq_py
