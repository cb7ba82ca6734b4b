// Instrument states and fresh values for the operator's page (see device_board.hpp).
#include "serve/device_board.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>

#include "cal/analysis/air.hpp"
#include "cal/analysis/compensation.hpp"
#include "kinds/kind.hpp"
#include "roles.hpp"

namespace daq::serve {

using cal::drivers::InstrumentState;
using cal::drivers::Quantity;
using nlohmann::json;

namespace {
// A device that has read nothing for this long (or three of its periods, if longer) is silent:
// its values are no longer shown.
constexpr std::chrono::milliseconds kSilentAfter{2000};
}  // namespace

DeviceBoard::DeviceBoard(const cal::daq::Config& config, WallClock wall)
    : config_(config), wall_(std::move(wall)) {
  for (const auto& d : config_.devices) devices_[d.id].config = &d;
}

DeviceBoard::Clock::time_point DeviceBoard::now() const { return wall_ ? wall_() : Clock::now(); }

void DeviceBoard::expect(const std::string& id, std::chrono::milliseconds period,
                         int max_attempts) {
  if (auto it = devices_.find(id); it != devices_.end()) {
    it->second.period = period;
    it->second.max_attempts = max_attempts;
    it->second.failed = false;
  }
}

void DeviceBoard::on_state(const std::string& id, InstrumentState s, std::string_view why) {
  const auto it = devices_.find(id);
  if (it == devices_.end()) return;
  auto& d = it->second;
  d.state = s;
  switch (s) {
    case InstrumentState::connecting:
      ++d.attempts;
      d.opened = false;
      break;
    case InstrumentState::configuring:
      d.opened = true;
      d.reason.clear();
      break;
    case InstrumentState::reconnecting:
      d.reason = std::string(why);
      break;
    case InstrumentState::closed:
      d.reason = std::string(why);
      d.failed = why != "stopped";  // given up, not stopped by the service
      d.last_reading.reset();
      d.values.clear();
      break;
    case InstrumentState::signal_lost:
      d.reason = why.empty() ? "the device reports its readings as invalid" : std::string(why);
      break;
    case InstrumentState::streaming:
      d.reason.clear();
      break;
  }
}

void DeviceBoard::on_reading(const std::string& id, const cal::drivers::Reading& r) {
  const auto it = devices_.find(id);
  if (it == devices_.end()) return;
  auto& d = it->second;
  const auto t = now();
  d.last_reading = t;
  d.attempts = 0;
  d.opened = true;
  if (t - d.bucket_start >= std::chrono::seconds(1)) {
    // A new second: the current bucket becomes the previous one (or both start afresh after
    // a longer pause).
    const bool next = t - d.bucket_start < std::chrono::seconds(2);
    d.ok[1] = next ? d.ok[0] : 0, d.bad[1] = next ? d.bad[0] : 0;
    d.ok[0] = d.bad[0] = 0;
    d.bucket_start = t;
  }
  if (r.status != cal::drivers::ReadingStatus::ok || !std::isfinite(r.value)) {
    ++d.bad[0];
    // Its last valid value is no longer the current one (an indicator out of range, a beam
    // interrupted while the device stays streaming): none is shown until a valid one comes.
    d.values.erase({static_cast<int>(r.quantity), r.channel});
    return;
  }
  ++d.ok[0];
  d.values[{static_cast<int>(r.quantity), r.channel}] = {r.value, t};
}

void DeviceBoard::on_failed(const std::string& id, const std::string& why) {
  const auto it = devices_.find(id);
  if (it == devices_.end()) return;
  it->second.failed = true;
  it->second.state = InstrumentState::closed;
  it->second.reason = why;
  it->second.last_reading.reset();
  it->second.values.clear();
}

bool DeviceBoard::fresh(const Device& d) const {
  const auto limit = std::max(kSilentAfter, 3 * d.period);
  return d.last_reading && now() - *d.last_reading <= limit;
}

std::string DeviceBoard::condition(const Device& d) const {
  if (d.failed) return "failed";
  switch (d.state) {
    case InstrumentState::closed:
      return "closed";
    case InstrumentState::connecting:
      return "connecting";
    case InstrumentState::configuring:
      // Open, nothing read yet: a ballbar sends only once mounted and moving.
      return d.last_reading ? "connecting" : "open";
    case InstrumentState::reconnecting:
      return "reconnecting";
    case InstrumentState::signal_lost:
      return fresh(d) ? "signal lost" : "silent";
    case InstrumentState::streaming:
      return fresh(d) ? "streaming" : "silent";
  }
  return "closed";
}

std::optional<double> DeviceBoard::value(const Device& d, Quantity q, int channel) const {
  if (!fresh(d) || d.state != InstrumentState::streaming) return std::nullopt;
  const auto it = d.values.find({static_cast<int>(q), channel});
  if (it == d.values.end()) return std::nullopt;
  if (now() - it->second.at > std::max(kSilentAfter, 3 * d.period)) return std::nullopt;
  return it->second.value;
}

json DeviceBoard::device_json(const Device& d) const {
  const auto& c = *d.config;
  const auto state = condition(d);
  json j{{"id", c.id},
         {"role", c.role},
         {"driver", c.driver},
         {"product", product_name(c.driver)},
         {"serial_number", c.serial_number},
         {"transport", c.transport},
         {"state", state},
         {"reason", d.reason},
         {"attempt", d.attempts},
         {"max_attempts", d.max_attempts},
         {"age_s", d.last_reading
                       ? json(std::chrono::duration<double>(now() - *d.last_reading).count())
                       : json(nullptr)}};
  if (state == "silent")
    j["reason"] = fmt::format("no reading for {:.1f} s",
                              std::chrono::duration<double>(now() - *d.last_reading).count());
  const auto n = d.ok[0] + d.ok[1] + d.bad[0] + d.bad[1];
  j["valid_pct"] =
      n && fresh(d) ? json(100.0 * static_cast<double>(d.ok[0] + d.ok[1]) / static_cast<double>(n))
                    : json(nullptr);
  json values = json::object();
  for (const auto& [key, v] : d.values) {
    const auto q = static_cast<Quantity>(key.first);
    if (const auto x = value(d, q, key.second))
      values[key.second ? fmt::format("{}.{}", cal::drivers::to_string(q), key.second)
                        : std::string(cal::drivers::to_string(q))] = *x;
  }
  j["values"] = values;
  return j;
}

// The environment as a run would compensate with it now, from fresh values only: air from any
// device that reports it (the air station, or a laser's environment unit), material as the
// mean of the material thermometers.
json DeviceBoard::environment_json() const {
  // The page names where the air values come from: with the air station silent, a laser's
  // environment unit may still give them (and a run would use them).
  std::string source;
  const auto air = [&](Quantity q) -> std::optional<double> {
    const auto* preferred = config_.device_for("air");
    if (preferred)
      if (auto v = value(devices_.at(preferred->id), q)) {
        if (source.empty()) source = preferred->id;
        return v;
      }
    for (const auto& [id, d] : devices_)
      if (auto v = value(d, q)) {
        if (source.empty()) source = id;
        return v;
      }
    return std::nullopt;
  };
  const auto t = air(Quantity::air_temperature_degc), p = air(Quantity::air_pressure_pa),
             rh = air(Quantity::air_humidity_pct);
  double sum = 0.0;
  int count = 0, sensors = 0;
  for (const auto& [id, d] : devices_) {
    if (d.config->role != "material") continue;
    ++sensors;
    auto v = value(d, Quantity::material_temperature_degc);
    if (!v) v = value(d, Quantity::length_m);  // a line thermometer reports through the gauge
    if (v) sum += *v, ++count;
  }
  const auto opt = [](const std::optional<double>& v) { return v ? json(*v) : json(nullptr); };
  json j{{"air_source", source.empty() ? json(nullptr) : json(source)},
         {"air_temperature_degc", opt(t)},
         {"pressure_pa", opt(p)},
         {"humidity_pct", opt(rh)},
         {"material_degc", count ? json(sum / count) : json(nullptr)},
         {"material_sensors", sensors},
         {"equation", config_.environment.equation},
         {"n", nullptr},
         {"factor_ppm", nullptr},
         {"material_fallback", count == 0}};
  if (!t || !p || !rh) return j;
  try {
    const auto& e = config_.environment;
    const double n = cal::air::refractive_index({.temperature_degc = *t,
                                                 .pressure_pa = *p,
                                                 .humidity = cal::air::Humidity::relative_pct(*rh),
                                                 .co2_umol_per_mol = e.co2_umol_per_mol,
                                                 .wavelength_vacuum_nm = e.wavelength_nm},
                                                cal::air::equation_from_string(e.equation))
                         .n;
    const double material = count ? sum / count : e.fallback_material_degc;
    j["n"] = n;
    j["factor_ppm"] =
        cal::comp::combined_factor(n, e.expansion_ppm_per_k * 1e-6, material).total_ppm;
  } catch (const std::exception& e) {  // outside the equation's range: a sensor fault
    j["problem"] = e.what();
  }
  return j;
}

json DeviceBoard::to_json() const {
  json list = json::array();
  for (const auto& d : config_.devices) list.push_back(device_json(devices_.at(d.id)));
  return {{"schema", "caldaq.devices-state.v1"},
          {"devices", list},
          {"environment", environment_json()}};
}

std::optional<std::string> DeviceBoard::not_ready(const Device& d, bool may_be_silent) const {
  const auto& c = *d.config;
  const auto state = condition(d);
  const auto why = d.reason.empty() ? std::string() : ": " + d.reason;
  const std::string name = fmt::format("{} ({})", c.id, c.transport);
  if (state == "streaming") return std::nullopt;
  // A ballbar sends nothing until it is mounted and moving: reachable is enough.
  if (may_be_silent && (state == "open" || state == "silent")) return std::nullopt;
  if (state == "reconnecting")
    return fmt::format("{} is reconnecting (attempt {}{}){}", name, d.attempts,
                       d.max_attempts >= 0 ? fmt::format(" of {}", d.max_attempts) : "", why);
  if (state == "silent")
    return fmt::format("{} is silent: {}", name, device_json(d)["reason"].get<std::string>());
  return fmt::format("{} is {}{}", name, state, why);
}

bool run_uses(const cal::daq::Config& c, std::string_view test, const cal::daq::DeviceConfig& dc) {
  if (test == "circle") return dc.role == "ballbar";
  if (dc.role == "air" || dc.role == "material") return true;
  if (!c.linear) return dc.role == "laser" || dc.role == "position";
  const auto& kind = kinds::kind(c.linear->measure.kind);
  if (dc.role == "laser" || dc.role == "position") return !kind.stops_from_probe();
  return !dc.role.empty() && dc.role == kind.probe_role();
}

std::optional<std::string> DeviceBoard::refusal(std::string_view test) const {
  std::vector<std::string> reasons;
  for (const auto& c : config_.devices) {
    if (!run_uses(config_, test, c)) continue;
    if (auto why = not_ready(devices_.at(c.id), test == "circle")) reasons.push_back(*why);
  }
  // Every device that is not ready is named: the operator fixes them all at once.
  if (reasons.empty()) return std::nullopt;
  return fmt::format("not ready: {}", fmt::join(reasons, "; "));
}

namespace {

class Watched final : public cal::drivers::Instrument {
 public:
  Watched(std::unique_ptr<Instrument> inner, std::string id, std::shared_ptr<DeviceBoard> board)
      : inner_(std::move(inner)), id_(std::move(id)), board_(std::move(board)) {}
  void start(cal::drivers::InstrumentEvents e) override {
    auto reading = std::move(e.reading);
    auto state = std::move(e.state);
    e.reading = [this, reading](const cal::drivers::Reading& r) {
      board_->on_reading(id_, r);
      if (reading) reading(r);
    };
    e.state = [this, state](InstrumentState s, std::string_view why) {
      board_->on_state(id_, s, why);
      if (state) state(s, why);
    };
    inner_->start(std::move(e));
  }
  void stop() override { inner_->stop(); }
  InstrumentState state() const override { return inner_->state(); }
  const cal::drivers::codec::CodecStats& codec_stats() const override {
    return inner_->codec_stats();
  }
  std::string describe() const override { return inner_->describe(); }

 private:
  std::unique_ptr<Instrument> inner_;
  std::string id_;
  std::shared_ptr<DeviceBoard> board_;
};

}  // namespace

std::unique_ptr<cal::drivers::Instrument> watched(std::unique_ptr<cal::drivers::Instrument> inner,
                                                  std::string id,
                                                  std::shared_ptr<DeviceBoard> board) {
  return std::make_unique<Watched>(std::move(inner), std::move(id), std::move(board));
}

}  // namespace daq::serve
