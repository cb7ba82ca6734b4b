// Captures (.cdq) and the drivers' decoders for Python: a capture's records one by one, and
// what a registered driver makes of a device's bytes (what `daq decode` prints, item by item).
#include "cal/replay/capture.hpp"

#include <fmt/format.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "cal/analysis/error.hpp"
#include "cal/drivers/registry.hpp"

namespace py = pybind11;
namespace d = cal::drivers;

namespace caldaq_py {
namespace {

std::string_view record_kind(cal::replay::RecordKind k) {
  switch (k) {
    case cal::replay::RecordKind::received:
      return "received";
    case cal::replay::RecordKind::sent:
      return "sent";
    case cal::replay::RecordKind::event:
      return "event";
  }
  return "unknown";
}

class Capture {
 public:
  explicit Capture(const std::string& path) : reader_(path) {}
  const std::string& header_json() const { return reader_.header_json(); }
  // The next record as a dict, or None at the end (or at damage: see `damage`).
  py::object next() {
    std::optional<cal::replay::Record> r;
    {
      py::gil_scoped_release release;
      r = reader_.next();
    }
    if (!r) return py::none();
    py::dict out;
    out["time_ns"] = r->time_ns;
    out["device"] = r->device;
    out["kind"] = std::string(record_kind(r->kind));
    out["bytes"] = py::bytes(reinterpret_cast<const char*>(r->bytes.data()), r->bytes.size());
    return out;
  }
  py::object damage() const {
    const auto& dm = reader_.damage();
    if (!dm) return py::none();
    py::dict out;
    out["offset"] = dm->offset;
    out["block"] = dm->block;
    out["what"] = dm->what;
    out["text"] = cal::replay::describe(*dm);
    return out;
  }
  std::uint64_t records_read() const { return reader_.records_read(); }

 private:
  cal::replay::CaptureReader reader_;
};

template <class T>
py::object opt(const std::optional<T>& v) {
  return v ? py::cast(*v) : py::none();
}

// Codec text quotes device bytes that need not be UTF-8: U+FFFD for those, as the CLI's JSON.
py::str text(const std::string& s) {
  return py::reinterpret_steal<py::str>(
      PyUnicode_DecodeUTF8(s.data(), static_cast<Py_ssize_t>(s.size()), "replace"));
}

// One item with the fields of `daq decode --json` (caldaq.decode.v1) for its type.
py::dict item_dict(const d::DecodedItem& i) {
  py::dict j;
  j["type"] = std::string(d::to_string(i.kind));
  j["offset"] = i.offset;
  switch (i.kind) {
    case d::DecodedItem::Kind::reading:
      j["time_text"] = i.time_text;
      j["device_time_unix_ns"] = opt(i.device_time_unix_ns);
      j["device_time_relative_s"] = opt(i.device_time_relative_s);
      j["sample"] = opt(i.sample);
      j["channel"] = i.channel;
      j["quantity"] = std::string(d::to_string(i.quantity));
      j["value"] = i.value;
      j["status"] = std::string(d::to_string(i.status));
      break;
    case d::DecodedItem::Kind::error:
      j["kind"] = i.error_kind;
      j["reason"] = text(i.text);
      break;
    case d::DecodedItem::Kind::gap:
      j["reason"] = text(i.text);
      j["lost_samples"] = opt(i.lost_samples);
      break;
    case d::DecodedItem::Kind::note:
      j["text"] = text(i.text);
      break;
  }
  return j;
}

// The driver's decoder over `data` fed line by line as `daq decode` feeds a file, so that the
// items and their offsets are the CLI's.
py::dict decode(const std::string& driver, const py::bytes& data,
                const std::map<std::string, std::string>& set) {
  const auto& drv = d::driver(driver);
  std::vector<std::pair<std::string, std::string>> pairs(set.begin(), set.end());
  const auto options = d::options_from_text(drv, pairs);
  auto decoder = drv.make_decoder(options);
  const std::string_view bytes = data;
  std::vector<d::DecodedItem> items;
  {
    py::gil_scoped_release release;
    std::size_t at = 0;
    while (at < bytes.size()) {
      const auto nl = bytes.find('\n', at);
      const auto end = nl == std::string_view::npos ? bytes.size() : nl + 1;
      decoder->feed(std::as_bytes(std::span(bytes.data() + at, end - at)), items);
      at = end;
    }
    decoder->finish(items);
  }
  py::list out;
  std::size_t readings = 0, errors = 0, gaps = 0;
  for (const auto& i : items) {
    readings += i.kind == d::DecodedItem::Kind::reading;
    errors += i.kind == d::DecodedItem::Kind::error;
    gaps += i.kind == d::DecodedItem::Kind::gap;
    out.append(item_dict(i));
  }
  const auto& stats = decoder->stats();
  py::dict summary;
  summary["driver"] = std::string(drv.name());
  summary["bytes"] = stats.bytes;
  summary["frames"] = stats.frames;
  summary["readings"] = readings;
  summary["errors"] = errors;
  summary["gaps"] = gaps;
  py::dict result;
  result["items"] = out;
  result["summary"] = summary;
  return result;
}

}  // namespace

void bind_capture(py::module_& m) {
  py::class_<Capture>(m, "CaptureReader")
      .def(py::init<const std::string&>(), py::arg("path"))
      .def_property_readonly("header_json", &Capture::header_json)
      .def("next", &Capture::next)
      .def_property_readonly("damage", &Capture::damage)
      .def_property_readonly("records_read", &Capture::records_read);
  m.def("decode", &decode, py::arg("driver"), py::arg("data"),
        py::arg("options") = std::map<std::string, std::string>{});
  m.def("driver_names", [] {
    std::vector<std::string> names;
    for (const auto n : d::driver_names()) names.emplace_back(n);
    return names;
  });
}

}  // namespace caldaq_py
