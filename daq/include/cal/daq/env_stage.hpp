#pragma once
// Environmental compensation of laser readings (pipeline stage; plain C++, no I/O, no clock:
// time comes with each sample). Air temperature, pressure and humidity and the material
// temperatures arrive as timestamped samples (about 1 Hz); a laser reading (up to 10 kHz) is
// compensated with the environment linearly interpolated to its own time, or, when it is
// newer than the newest sample, with the newest sample held (and flagged: `held`).
//
// A sensor that has sent nothing for `stale_after_s` (or never) is stale. The configured
// policy either continues on the configured fallback value, which is recorded in every
// compensated result (`fallback_air`, `fallback_material`) and announced once per episode,
// or asks the run to stop (`must_stop`). Formulas: cal::air (refractive index),
// cal::comp (normalisation to 20 degC); docs/acquisition.md.
//
// The CO2 mole fraction is optional: without a CO2 sensor (EnvSensors::co2 false) the
// configured constant is used, and any CO2 samples that do arrive replace it while current;
// with one, it is interpolated and checked like the other air quantities. Material sensors may
// be disabled (a broken or badly placed probe): they are then neither averaged nor checked.
//
// Cost per laser reading: while the reading is newer than every sample (the live case: the
// newest samples are held), the environment is computed once per air sample and each reading
// costs two divisions. Otherwise a binary search per quantity (samples are kept for 2
// minutes), and the refractive-index equation only when the air it is given changes (the
// index of the last air state, bit for bit, is kept): once per reading while interpolating
// between two samples. The results are those of the full computation, bit for bit
// (tests/daq/env_stage_test.cpp). The caches make compensate() unsafe to call from two
// threads at once on one stage (one stage per event loop).
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "cal/analysis/air.hpp"
#include "cal/daq/config.hpp"

namespace cal::daq {

enum class AirQuantity { temperature_degc, pressure_pa, humidity_pct, co2_umol_per_mol };

struct Compensated {
  std::int64_t time_ns = 0;
  double raw_m = 0.0;     // as the laser gave it (vacuum wavelength)
  double length_m = 0.0;  // raw / n, normalised to 20 degC
  double n = 1.0;         // refractive index used
  double air_temperature_degc = 0.0, pressure_pa = 0.0, humidity_pct = 0.0;
  double material_degc = 20.0;
  double factor_ppm = 0.0;    // (length / raw - 1) 1e6
  bool fallback_air = false;  // a fallback value was used for an air quantity
  bool fallback_material = false;
  bool held = false;  // the reading is newer than the newest sample: held value
  double co2_umol_per_mol = 450.0;
};

struct EnvSensors {
  std::vector<bool> material_enabled;  // one per material thermometer; false: disabled
  bool co2 = false;                    // a CO2 sensor feeds AirQuantity::co2_umol_per_mol
  // Keep every sample instead of the last 2 minutes: for compensating after the run, when all
  // of a run's samples are given first and the stops are compensated afterwards at their own
  // times (the memory is then the run's environment samples).
  bool keep_all_samples = false;
};

struct EnvHealth {
  bool must_stop = false;             // a sensor is stale and the policy is stop
  std::vector<std::string> messages;  // new events since the last check (stale, fallback, back)
};

class EnvStage {
 public:
  // material_sensors: how many material thermometers there are (all enabled; their mean is
  // used), no CO2 sensor. Throws cal::InputError for an unknown equation, a stale age that is
  // not > 0, a non-finite expansion coefficient, or a negative count.
  EnvStage(const EnvironmentConfig& config, int material_sensors);
  // The same with the sensors described; at least one material sensor must be enabled when
  // there are any.
  EnvStage(const EnvironmentConfig& config, const EnvSensors& sensors);

  // Disable (or enable again) a material sensor during a run; refuses to disable the last
  // enabled one (cal::InputError), as the material temperature would then be unknown.
  void set_material_enabled(int sensor, bool enabled);

  void add_air(std::int64_t time_ns, AirQuantity q, double value);
  // sensor is 0-based; throws cal::InputError for a sensor that does not exist. Non-finite
  // values are dropped (a sensor's error code is no temperature).
  void add_material(std::int64_t time_ns, int sensor, double value_degc);

  // Stale detection at time t (call it for each laser reading or on a timer).
  EnvHealth check(std::int64_t time_ns);
  // Throws cal::InputError when the environment at t is outside the equation's range (a
  // sensor fault such as a pressure of 0): such a reading cannot be compensated.
  Compensated compensate(std::int64_t time_ns, double raw_m) const;
  // compensate(time_ns, raw_m).length_m, the very same arithmetic (so the same bits), without
  // the record: for a stream that needs only the length (10 kHz; the held environment is
  // looked up once per air sample, not copied per reading).
  double compensated_length_m(std::int64_t time_ns, double raw_m) const;

 private:
  struct Series {
    std::string name;
    double fallback = 0.0;
    std::deque<std::pair<std::int64_t, double>> samples;  // time-ordered, bounded
    bool stale_reported = false;
    bool required = true;  // checked for staleness (the optional CO2 without a sensor is not)
    bool enabled = true;   // a disabled material sensor is ignored
    // The value at t: interpolated, held (newest), or false (none / stale). Out-parameters
    // rather than an optional: this runs several times per 10 kHz reading.
    bool at(std::int64_t t, std::int64_t stale_ns, bool& held, double& value) const;
  };
  void add(Series& s, std::int64_t t, double v);
  void check_series(Series& s, std::int64_t t, EnvHealth& h);

  // The refractive index of the last air state (see the cost note above).
  struct IndexCache {
    bool valid = false;
    double key[4] = {};  // temperature, pressure, humidity, CO2 as given to the equation
    double n = 1.0;
  };
  double refractive_index(const double (&air)[4]) const;
  // The same for the combined factor, which depends on n and the material temperature only.
  struct FactorCache {
    bool valid = false;
    double n = 0.0, material_degc = 0.0;
    double total_ppm = 0.0;
  };
  double factor_ppm(double n, double material_degc) const;
  // While a reading is newer than every sensor's newest sample and no sensor goes stale, the
  // environment is held: constant. It is then computed once and kept for that time interval
  // (until the next sample or a staleness), and each reading only divides by it.
  struct HeldCache {
    bool valid = false;
    std::int64_t after_ns = 0, until_ns = 0;  // valid for after_ns < t <= until_ns
    Compensated environment;                  // everything but time, raw and length
  };
  Compensated environment_at(std::int64_t t) const;
  // The held environment when it serves time t (newer than the newest sample), else nullptr.
  const Compensated* held_at(std::int64_t t) const {
    return held_cache_.valid && t > held_cache_.after_ns && t <= held_cache_.until_ns
               ? &held_cache_.environment
               : nullptr;
  }

  EnvironmentConfig config_;
  air::Equation equation_;
  bool keep_all_ = false;
  mutable IndexCache index_cache_;
  mutable FactorCache factor_cache_;
  mutable HeldCache held_cache_;
  std::int64_t stale_ns_;
  Series air_[4];
  std::vector<Series> material_;
};

}  // namespace cal::daq
