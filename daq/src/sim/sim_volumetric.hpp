#pragma once
// The SIMULATED volumetric campaign: a machine of any of the 24 chain orders with all 21
// geometric errors injected as known functions, and the 18 linear tests (positioning,
// straightness against a square, pitch and yaw with two laser beams, roll with a level) that
// measure them on the simulated shop (sim_shop.hpp). The truth follows the conventions the
// model build uses (docs/volumetric-walkthrough.md): straightness with a zero least-squares
// line over the test's targets (its slope is squareness), positioning and angular errors zero
// at the first target (where the laser and the angular optics are zeroed).
#include <filesystem>
#include <functional>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cal/analysis/comp_read.hpp"
#include "cal/analysis/kinematics.hpp"
#include "cal/daq/config.hpp"
#include "linear_run.hpp"
#include "model/model_file.hpp"
#include "sim_shop.hpp"

namespace daq {

// Travel of the simulated machine, mm: X 0..500, Y 0..400, Z 0..300.
inline constexpr std::array<double, 3> kSimTravelMm{500.0, 400.0, 300.0};

// The injected geometry (tool offset 0: the instruments read at their own offsets).
cal::kinematics::Machine volumetric_geometry(cal::kinematics::Topology t);
// The shop truth around it: no backlash, cyclic error or scale expansion (the machine at
// 20 degC), `noise_um` of position noise.
ShopTruth volumetric_truth(cal::kinematics::Topology t, double noise_um = 0.0);
// The injected geometry as a model file (caldaq.model.v1, named "SIMULATED truth (YFXZ)", the
// travel of kSimTravelMm, every error given with the source "injected"), for comparing a model
// built from the simulated campaign with what it should have found (`daq sim --truth-out`,
// `daq model compare`).
cal::daq::model::Model volumetric_truth_model(cal::kinematics::Topology t);

// The 18 tests, in the order they are best measured (angular first: the model build uses them
// to correct the others' Abbe terms, but any order works).
std::vector<cal::daq::LinearTestConfig> volumetric_tests();
// The test of one component ("E_YX"); throws cal::InputError for an unknown name.
cal::daq::LinearTestConfig volumetric_test(std::string_view component);

// What the simulated control adds (um) when it loads the files of a cross-axis or volumetric
// compensation (SINUMERIK CEC, ISG cross or volumetric lists, LinuxCNC matrixkins, caldaq's cross
// CSV; cal::comptable::read_cross_applied): as its vendor's text says, or with the other sign
// (`inverted`), so that `daq verify` is tested against a known truth. For
// SimulatedAcquisition::compensation and `daq sim --control-table`. Throws cal::InputError.
std::function<cal::kinematics::Vec3(const cal::kinematics::Vec3&)> control_loads(
    std::string_view format, std::span<const std::string> files, bool inverted,
    const std::map<std::string, int>& axis_numbers = {{"X", 1}, {"Y", 2}, {"Z", 3}});
// The same with the files' names (HEIDENHAIN: the *.CMA assigns the *.COM tables by name).
std::function<cal::kinematics::Vec3(const cal::kinematics::Vec3&)> control_loads(
    std::string_view format, std::span<const cal::comptable::CompFile> files, bool inverted,
    const std::map<std::string, int>& axis_numbers = {{"X", 1}, {"Y", 2}, {"Z", 3}});

// One test acquired in this process on a fresh simulated shop with `truth`, through the real
// drivers (IDS3010, PTU300, gauge codecs) against the twins, stored in `database` under
// machine `machine` with the machine's topology; `compensation` (optional) is the control's
// (sim_shop.hpp). speed 0 (default): simulated time that jumps from event to event
// (cal/drivers/loop_time.hpp); speed > 0: it runs `speed` times faster than the wall clock. The
// loop is bounded by simulated time. Throws cal::InputError for a bad test.
struct SimulatedAcquisition {
  ShopTruth truth;
  std::filesystem::path database;
  std::string machine = "SIMULATED volumetric";
  double speed = 0.0;
  std::function<cal::kinematics::Vec3(const cal::kinematics::Vec3&)> compensation;
  // The laser's poll period in simulated seconds (100 Hz: a 3 mm overrun excursion at
  // 6000 mm/min, about 0.1 s, is seen by several readings).
  double laser_poll_s = 0.01;
  cal::storage::StoreOptions store_options;  // the run's store (tests: full_sync off)
};
LinearRunOutcome acquire_simulated(const SimulatedAcquisition& a,
                                   const cal::daq::LinearTestConfig& test);

}  // namespace daq
