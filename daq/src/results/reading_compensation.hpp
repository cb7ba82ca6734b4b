#pragma once
// A stored linear run's laser readings compensated one by one, as the acquisition compensated
// them (docs/python.md, "Compensated values"): the pipeline's own stage (cal::daq::EnvStage) is
// given the stored readings in time order, the air and material samples as they come, and each
// displacement reading of the laser is compensated when it comes, with the environment the
// stage has then (interpolated between samples, held after the newest one), to a length at
// 20 degC. Coefficients and sensor offsets are those of the run's current result
// (compensation_used: the acquisition's settings until a recompensation changes them).
//
// Devices by their stored role (instruments.driver, docs/storage.md): the laser's displacement
// readings are compensated; air temperature and pressure come from any device, humidity from
// the laser's or the air station; material temperatures from each "material" instrument in
// device order, each of its channels its own sensor (as a run's set-up numbers them). The
// memory is the stage's (2 minutes of samples), whatever the run's length.
#include <nlohmann/json.hpp>
#include <optional>
#include <vector>

#include "cal/daq/env_stage.hpp"
#include "cal/storage/store.hpp"

namespace daq {

class ReadingCompensation {
 public:
  // Throws cal::InputError for a run that is not a linear test or whose settings lack the
  // environment (an import, a circle run): its readings were never compensated.
  ReadingCompensation(const cal::storage::RunReader& store, const cal::storage::RunRecord& run,
                      const nlohmann::json& settings);
  // One reading, in the store's order. For a displacement reading of the laser, its
  // compensation (length_m at 20 degC, n, material_degc, ...); nullopt for every other reading,
  // and for one whose environment the equation refuses (a pressure of 0: a sensor fault).
  std::optional<cal::daq::Compensated> add(const cal::storage::RawReading& r);
  // The quantities add() needs besides the ones it compensates (to read them along).
  static std::vector<std::uint8_t> inputs();

 private:
  struct Material {
    std::uint16_t device;
    std::vector<std::uint8_t> channels;  // sorted; one sensor each (empty: one sensor)
    int first_sensor;
  };
  int material_sensor(const cal::storage::RawReading& r) const;

  std::optional<std::uint16_t> laser_, air_;
  std::vector<Material> materials_;
  double offset_material_k_ = 0, offset_air_k_ = 0, offset_pressure_pa_ = 0, offset_humidity_ = 0;
  std::optional<cal::daq::EnvStage> stage_;
};

}  // namespace daq
