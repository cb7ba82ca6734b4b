// One device of a capture at its highest rate (see densify.hpp).
#include "cal/replay/densify.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <deque>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "cal/replay/capture.hpp"

namespace cal::replay {
namespace {

using nlohmann::json;

struct Out {
  std::int64_t time_ns;
  RecordKind kind;
  std::string bytes;
};

std::span<const std::byte> bytes_of(std::string_view s) {
  return {reinterpret_cast<const std::byte*>(s.data()), s.size()};
}

// A time series of recorded values, linearly interpolated inside gaps of at most max_gap_ns
// and held (the left value) across longer ones.
struct Series {
  std::vector<std::int64_t> t;
  std::vector<double> v;
  std::int64_t max_gap_ns = INT64_MAX;
  double at(std::int64_t time) const {
    const auto it = std::upper_bound(t.begin(), t.end(), time);
    if (it == t.begin()) return v.front();
    const auto i = static_cast<std::size_t>(it - t.begin()) - 1;
    if (i + 1 >= t.size() || t[i + 1] - t[i] > max_gap_ns) return v[i];
    const double f = static_cast<double>(time - t[i]) / static_cast<double>(t[i + 1] - t[i]);
    return v[i] + f * (v[i + 1] - v[i]);
  }
};

int find_device(const json& header, std::string_view key, std::string_view value) {
  for (const auto& i : header["instruments"])
    if (i.value(std::string(key), std::string()) == value) return i["device"].get<int>();
  throw std::runtime_error(fmt::format("the capture has no instrument with {} {}", key, value));
}

// "...\"id\":N..." with N + shift.
std::string shift_id(std::string_view s, std::int64_t shift, std::int64_t* id_out = nullptr) {
  const auto at = s.find("\"id\":");
  if (at == std::string_view::npos) return std::string(s);
  auto end = at + 5;
  while (end < s.size() && std::isdigit(static_cast<unsigned char>(s[end]))) ++end;
  const auto id = std::stoll(std::string(s.substr(at + 5, end - at - 5))) + shift;
  if (id_out) *id_out = id;
  return fmt::format("{}{}{}", s.substr(0, at + 5), id, s.substr(end));
}

class Generator {
 public:
  Generator(std::vector<Record> records, json header, std::string kind, double rate_hz)
      : records_(std::move(records)),
        header_(std::move(header)),
        kind_(std::move(kind)),
        period_ns_(static_cast<std::int64_t>(std::llround(1e9 / rate_hz))),
        rate_hz_(rate_hz) {}

  void write(const std::string& path) {
    prepare();
    CaptureWriter writer(path, header_.dump());
    std::deque<Out> pending;
    const auto flush_until = [&](std::int64_t t) {
      while (!pending.empty() && pending.front().time_ns <= t) {
        const auto& o = pending.front();
        writer.record(o.time_ns, static_cast<std::uint16_t>(target_), o.kind, bytes_of(o.bytes));
        pending.pop_front();
      }
    };
    for (std::size_t i = 0; i < records_.size(); ++i) {
      const auto& r = records_[i];
      flush_until(r.time_ns);
      if (r.device != target_) {
        writer.record(r.time_ns, r.device, r.kind, r.bytes);
        continue;
      }
      for (auto& o : transform(i)) pending.push_back(std::move(o));
    }
    flush_until(INT64_MAX);
    writer.close();
  }

 private:
  std::vector<Record> records_;
  json header_;
  std::string kind_;
  std::int64_t period_ns_;
  double rate_hz_;
  int target_ = -1;
  std::vector<std::int64_t> target_times_;
  Series series_;
  std::string last_sent_;
  std::int64_t id_shift_ = 0;
  std::int64_t last_id_ = 0;
  bool started_ = false;

  // The time of the device's next record (positions_only: of its next Xcom line).
  std::int64_t next_target_time(std::size_t i, bool positions_only = false) const {
    for (std::size_t j = i + 1; j < records_.size(); ++j)
      if (records_[j].device == target_ &&
          (!positions_only ||
           (records_[j].kind == RecordKind::received && xcom(records_[j].text()))))
        return records_[j].time_ns;
    return records_.back().time_ns;
  }

  void prepare() {
    if (kind_ == "ids3010") {
      target_ = find_device(header_, "driver", "ids3010");
      for (const auto& r : records_)
        if (r.device == target_ && r.kind == RecordKind::received)
          if (const auto v = displacement(r.text())) add(r.time_ns, *v);
    } else if (kind_ == "ptu300") {
      target_ = find_device(header_, "driver", "ptu300");
    } else if (kind_ == "gauge" || kind_ == "temper") {
      target_ = find_device(header_, "role", "material");
      for (const auto& r : records_)
        if (r.device == target_ && r.kind == RecordKind::received)
          add(r.time_ns, std::strtod(std::string(r.text()).c_str(), nullptr));
      if (kind_ == "temper")
        replace_instrument("temper", "material", "hid 413d:2107",
                           {{"family", "gold"}, {"channels", {0}}});
    } else if (kind_ == "ballbar") {
      target_ = find_device(header_, "role", "ballbar");
      header_["config"]["circle"]["sample_rate_hz"] = rate_hz_;
    } else if (kind_ == "shdr" || kind_ == "halsampler") {
      target_ = find_device(header_, "driver", "shdr");
      series_.max_gap_ns = 50'000'000;
      for (const auto& r : records_)
        if (r.device == target_ && r.kind == RecordKind::received)
          if (const auto v = xcom(r.text())) add(r.time_ns, *v);
      if (kind_ == "halsampler")
        replace_instrument("halsampler", "position", "tcp 127.0.0.1:5000",
                           {{"tagged", false}, {"column", 0}, {"unit", "mm"}});
    } else {
      throw std::runtime_error("unknown KIND " + kind_);
    }
    if (series_.t.empty() && kind_ != "ptu300" && kind_ != "ballbar")
      throw std::runtime_error("the capture has no values of the device to densify");
  }
  // The target device's entry in the header, as another driver's (daq replay builds it).
  void replace_instrument(const char* driver, const char* role, const char* transport,
                          json options) {
    for (auto& i : header_["instruments"])
      if (i["device"] == target_)
        i = {{"device", target_},
             {"driver", driver},
             {"role", role},
             {"origin", "simulated"},
             {"test_axis", 0},
             {"transport", transport},
             {"options", std::move(options)}};
  }
  void add(std::int64_t t, double v) {
    series_.t.push_back(t);
    series_.v.push_back(v);
  }

  static std::optional<double> displacement(std::string_view s) {
    const auto at = s.find("\"result\":[0,");
    if (at == std::string_view::npos || s.find(',', at + 12) == std::string_view::npos)
      return std::nullopt;
    const auto rest = s.substr(at + 12);
    if (std::count(rest.begin(), rest.end(), ',') != 2) return std::nullopt;  // [0,a,b,c]
    return std::strtod(std::string(rest).c_str(), nullptr);
  }
  static std::optional<double> xcom(std::string_view s) {
    const auto at = s.find("|Xcom|");
    if (at == std::string_view::npos) return std::nullopt;
    return std::strtod(std::string(s.substr(at + 6)).c_str(), nullptr);
  }

  // Times of the inserted records after the record at time t: t + k period, before the
  // device's next record.
  template <class F>
  void fill(std::vector<Out>& out, std::int64_t t, std::int64_t next, F make) const {
    for (std::int64_t when = t + period_ns_; when < next; when += period_ns_) make(out, when);
  }

  std::vector<Out> transform(std::size_t i) {
    const auto& r = records_[i];
    const std::string text(r.text());
    const auto next = next_target_time(i);
    std::vector<Out> out;
    if (kind_ == "ids3010") {
      if (r.kind == RecordKind::event) return {{r.time_ns, r.kind, text}};
      auto shifted = shift_id(text, id_shift_, &last_id_);
      if (r.kind == RecordKind::sent) last_sent_ = shifted;
      out.push_back({r.time_ns, r.kind, shifted});
      if (r.kind == RecordKind::received && displacement(text) &&
          last_sent_.find("getAxesDisplacement") != std::string::npos) {
        fill(out, r.time_ns, next, [&](std::vector<Out>& o, std::int64_t when) {
          const auto id = ++last_id_;
          ++id_shift_;
          const auto v = static_cast<std::int64_t>(std::llround(series_.at(when)));
          o.push_back({when, RecordKind::sent, shift_id(last_sent_, id - id_of(last_sent_))});
          o.push_back(
              {when, RecordKind::received,
               fmt::format("{{\"id\":{},\"jsonrpc\":\"2.0\",\"result\":[0,{},0,0]}}\r\n", id, v)});
        });
      }
      return out;
    }
    if (kind_ == "ptu300" || kind_ == "gauge") {
      out.push_back({r.time_ns, r.kind, text});
      if (r.kind == RecordKind::sent) last_sent_ = text;
      const bool answer = r.kind == RecordKind::received &&
                          (kind_ == "gauge" || text.find("hPa") != std::string::npos);
      if (answer && !last_sent_.empty())
        fill(out, r.time_ns, next, [&](std::vector<Out>& o, std::int64_t when) {
          o.push_back({when, RecordKind::sent, last_sent_});
          o.push_back({when, RecordKind::received, text});
        });
      return out;
    }
    if (kind_ == "temper") return temper(r, next);
    if (kind_ == "ballbar") return ballbar(r);
    if (kind_ == "shdr") {
      out.push_back({r.time_ns, r.kind, text});
      const auto v = xcom(text);
      if (r.kind != RecordKind::received || !v) return out;
      const auto stamp = text.substr(0, text.find('|'));
      fill(out, r.time_ns, std::min(next, r.time_ns + series_.max_gap_ns),
           [&](std::vector<Out>& o, std::int64_t when) {
             o.push_back({when, RecordKind::received,
                          fmt::format("{}|Xcom|{:.4f}\n", stamp, series_.at(when))});
           });
      return out;
    }
    return halsampler(r, i);
  }
  static std::int64_t id_of(const std::string& s) {
    std::int64_t id = 0;
    shift_id(s, 0, &id);
    return id;
  }

  std::vector<Out> temper(const Record& r, std::int64_t next) {
    std::vector<Out> out;
    const auto report = [](std::initializer_list<int> b) {
      std::string s;
      for (int x : b) s.push_back(static_cast<char>(x));
      s.resize(8, '\0');
      return s;
    };
    if (r.kind == RecordKind::event) {
      out.push_back({r.time_ns, r.kind, std::string(r.text())});
      if (r.text() == "opened" && !started_) {
        started_ = true;
        out.push_back({r.time_ns, RecordKind::sent, report({0x01, 0x82, 0x77, 0x01})});
        out.push_back({r.time_ns, RecordKind::received, report({0x82, 0x02})});
      }
      return out;
    }
    if (r.kind != RecordKind::received) return out;
    const auto read = [&](std::vector<Out>& o, std::int64_t when) {
      const auto centi = static_cast<int>(std::lround(series_.at(when) * 100));
      o.push_back({when, RecordKind::sent, report({0x01, 0x80, 0x33, 0x01})});
      o.push_back(
          {when, RecordKind::received, report({0x80, 0x80, (centi >> 8) & 0xFF, centi & 0xFF})});
    };
    read(out, r.time_ns);
    fill(out, r.time_ns, next, read);
    return out;
  }

  // Each recorded chunk of lines becomes rate / recorded-rate times as many lines over the same
  // span, interpolated between consecutive recorded lengths.
  std::vector<Out> ballbar(const Record& r) {
    if (r.kind != RecordKind::received) return {{r.time_ns, r.kind, std::string(r.text())}};
    std::vector<double> values;
    std::string_view s = r.text();
    while (!s.empty()) {
      const auto end = s.find('\n');
      if (end > 1) values.push_back(std::strtod(std::string(s.substr(0, end)).c_str(), nullptr));
      s = end == std::string_view::npos ? std::string_view{} : s.substr(end + 1);
    }
    const double recorded_hz = header_value_recorded_hz();
    const int factor = std::max(1, static_cast<int>(std::lround(rate_hz_ / recorded_hz)));
    std::string text;
    for (std::size_t k = 0; k < values.size(); ++k) {
      const double next = k + 1 < values.size() ? values[k + 1] : values[k];
      for (int j = 0; j < factor; ++j)
        text += fmt::format("{:+010.5f}\r\n",
                            values[k] + (next - values[k]) * static_cast<double>(j) / factor);
    }
    return {{r.time_ns, r.kind, text}};
  }
  double recorded_hz_ = 0;
  double header_value_recorded_hz() {
    if (recorded_hz_ == 0) recorded_hz_ = 1000.0;  // daq sim's bar (sim_shop.cpp)
    return recorded_hz_;
  }

  // The end of the feed: the device's "closed" after record i, else the capture's last record.
  std::int64_t feed_end_time(std::size_t i) const {
    for (std::size_t j = i + 1; j < records_.size(); ++j)
      if (records_[j].device == target_ && records_[j].kind == RecordKind::event &&
          records_[j].text() == "closed")
        return records_[j].time_ns;
    return records_.back().time_ns;
  }
  bool position_after(std::size_t i) const {
    for (std::size_t j = i + 1; j < records_.size(); ++j)
      if (records_[j].device == target_ && records_[j].kind == RecordKind::received &&
          xcom(records_[j].text()))
        return true;
    return false;
  }

  // A line at each recorded position and every period between (the servo thread samples
  // whether the axis moves or not). After the last recorded position the lines go on to the
  // end of the feed, and one is at its very last instant: the original run ended on a reading
  // of the laser right after its last stop's dwell (the SHDR adapter's feed holds its value,
  // so its trigger needed no later sample), and a periodic feed proves the axis still only up
  // to its newest sample. Without that line the feed stopped short of the laser's last reading
  // and the last stop was never captured (issue 32: 109 of 110 stops).
  std::vector<Out> halsampler(const Record& r, std::size_t i) {
    std::vector<Out> out;
    if (r.kind == RecordKind::event) {
      if (r.text() == "opened" || r.text() == "closed")
        out.push_back({r.time_ns, r.kind, std::string(r.text())});
      return out;
    }
    if (r.kind != RecordKind::received || !xcom(r.text())) return out;
    const auto line = [&](std::vector<Out>& o, std::int64_t when) {
      o.push_back({when, RecordKind::received, fmt::format("{:.6f} \n", series_.at(when))});
    };
    line(out, r.time_ns);
    if (position_after(i)) {
      fill(out, r.time_ns, next_target_time(i, true), line);
      return out;
    }
    const auto end = feed_end_time(i);
    fill(out, r.time_ns, end, line);
    if (out.back().time_ns < end) line(out, end);
    return out;
  }
};

}  // namespace

std::span<const DenseKind> dense_kinds() {
  static constexpr std::array<DenseKind, 7> kinds{{
      {"ids3010", "linear", 10000, "IDS3010 getAxesDisplacement, JSON-RPC"},
      {"ptu300", "linear", 10, "PTU300 SEND lines at 4800 7E1"},
      {"gauge", "linear", 90, "serial thermometer (line gauge, polled) at 9600 8N1"},
      {"ballbar", "circle", 10000, "ballbar (line gauge, streaming), the issue's 10 kHz"},
      {"shdr", "linear", 1000, "MTConnect SHDR Xcom lines while moving"},
      {"halsampler", "linear", 1000, "halsampler lines (servo thread)"},
      {"temper", "linear", 200, "TEMPer HID reports (the 5 ms HID poll)"},
  }};
  return kinds;
}

void densify(const std::filesystem::path& in, const std::filesystem::path& out,
             std::string_view kind, double rate_hz) {
  if (!(rate_hz > 0 && rate_hz <= 1e6))
    throw std::runtime_error(fmt::format("densify: rate {} Hz: expected (0, 1e6]", rate_hz));
  CaptureReader reader(in);
  std::vector<Record> records;
  while (auto r = reader.next()) records.push_back(std::move(*r));
  if (reader.damage()) throw std::runtime_error(in.string() + ": " + describe(*reader.damage()));
  if (records.empty()) throw std::runtime_error(in.string() + ": no records");
  try {
    Generator g(std::move(records), nlohmann::json::parse(reader.header_json()), std::string(kind),
                rate_hz);
    g.write(out.string());
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(fmt::format("{}: header: {}", in.string(), e.what()));
  }
}

}  // namespace cal::replay
