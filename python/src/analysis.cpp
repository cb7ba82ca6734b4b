// The analysis library for Python: the same functions the CLI calls, on numpy arrays, with
// results as dicts whose keys are the CLI's JSON keys (so a result compares key by key with
// `daq ... --json`). Long computations release the GIL.
#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>

#include "bindings.hpp"
#include "cal/analysis/air.hpp"
#include "cal/analysis/circle.hpp"
#include "cal/analysis/circle_standards.hpp"
#include "cal/analysis/compensation.hpp"
#include "cal/analysis/error.hpp"
#include "cal/analysis/iso230_2.hpp"
#include "cal/analysis/squareness.hpp"
#include "cal/analysis/straightness.hpp"
#include "cal/analysis/uncertainty.hpp"
// The CLI's own presentation of the results (daq/src, analysis-level): the same documents.
#include "circle_output.hpp"
#include "iso230_2_output.hpp"
#include "verdict.hpp"

namespace py = pybind11;
using namespace pybind11::literals;  // "name"_a = value: a dict's fields in one call

namespace caldaq_py {
namespace {

using Doubles = py::array_t<double, py::array::c_style | py::array::forcecast>;

std::vector<double> to_vector(const Doubles& a) {
  if (a.ndim() != 1)
    throw cal::InputError(fmt::format("expected a 1-D array, got {} dimensions", a.ndim()));
  return {a.data(), a.data() + a.size()};
}

py::array_t<double> to_array(const std::vector<double>& v) {
  return py::array_t<double>(static_cast<py::ssize_t>(v.size()), v.data());
}

// A document of the CLI (nlohmann) as Python objects: through its JSON text, whose numbers
// read back to the same doubles.
py::object from_json(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

// --- refractive index -----------------------------------------------------------------------

cal::air::Humidity humidity_of(const std::string& kind, double value) {
  if (kind == "relative" || kind == "rh") return cal::air::Humidity::relative_pct(value);
  if (kind == "dew_point") return cal::air::Humidity::dew_point_degc(value);
  if (kind == "vapour_pressure") return cal::air::Humidity::vapour_pressure_pa(value);
  throw cal::InputError(fmt::format(
      "humidity_kind '{}': expected one of relative, dew_point, vapour_pressure", kind));
}

py::dict refractive_index(double temperature_degc, double pressure_pa, double humidity,
                          const std::string& humidity_kind, double co2_umol_per_mol,
                          double wavelength_nm, const std::string& equation) {
  cal::air::Conditions c{.temperature_degc = temperature_degc,
                         .pressure_pa = pressure_pa,
                         .humidity = humidity_of(humidity_kind, humidity),
                         .co2_umol_per_mol = co2_umol_per_mol,
                         .wavelength_vacuum_nm = wavelength_nm};
  const auto r = cal::air::refractive_index(c, cal::air::equation_from_string(equation));
  return py::dict("n"_a = r.n, "water_vapour_pressure_pa"_a = r.water_vapour_pressure_pa,
                  "equation"_a = std::string(cal::air::to_string(r.equation)),
                  "warnings"_a = r.warnings);
}

// --- ISO 230-2 ------------------------------------------------------------------------------

cal::iso230_2::Direction direction_of(const std::string& s) {
  if (s == "up" || s == "+") return cal::iso230_2::Direction::up;
  if (s == "down" || s == "-") return cal::iso230_2::Direction::down;
  throw cal::InputError(fmt::format("direction '{}': expected up, down, + or -", s));
}

py::object iso230_2_evaluate(const Doubles& target_mm, py::array_t<int> run,
                             const std::vector<std::string>& direction, const Doubles& deviation_um,
                             const std::string& standard) {
  const auto t = to_vector(target_mm), dev = to_vector(deviation_um);
  const auto r = run.unchecked<1>();
  if (t.size() != dev.size() || static_cast<std::size_t>(r.shape(0)) != t.size() ||
      direction.size() != t.size())
    throw cal::InputError(fmt::format(
        "target_mm, run, direction and deviation_um: expected equal lengths, got {}, {}, {}, {}",
        t.size(), r.shape(0), direction.size(), dev.size()));
  std::vector<cal::iso230_2::Measurement> data(t.size());
  for (std::size_t k = 0; k < t.size(); ++k)
    data[k] = {t[k], r(static_cast<py::ssize_t>(k)), direction_of(direction[k]), dev[k]};
  const auto s = cal::iso230_2::standard_from_string(standard);
  cal::iso230_2::Evaluation e;
  {
    py::gil_scoped_release release;
    e = cal::iso230_2::evaluate(data, s);
  }
  return from_json(daq::to_json(e));
}

py::list iso230_2_standards() {
  py::list out;
  for (const auto& s : cal::iso230_2::standards())
    out.append(py::dict(py::arg("key") = std::string(s.key),
                        py::arg("title") = std::string(s.title),
                        py::arg("note") = std::string(s.note)));
  return out;
}

// --- ISO 230-4 ------------------------------------------------------------------------------

cal::circle::Plane circle_plane(const std::string& s) {
  if (s == "XY") return cal::circle::Plane::xy;
  if (s == "YZ") return cal::circle::Plane::yz;
  if (s == "ZX") return cal::circle::Plane::zx;
  throw cal::InputError(fmt::format("plane '{}': expected XY, YZ or ZX", s));
}

cal::circle::Direction circle_direction(const std::string& s) {
  if (s == "ccw") return cal::circle::Direction::ccw;
  if (s == "cw") return cal::circle::Direction::cw;
  throw cal::InputError(fmt::format("direction '{}': expected cw or ccw", s));
}

cal::circle::Setup circle_setup(const std::string& plane, double radius_mm, double feed,
                                std::optional<double> cyclic_period_mm, bool radius_calibrated,
                                std::optional<double> calibrated_radius_mm) {
  cal::circle::Setup s;
  s.plane = circle_plane(plane);
  s.radius_mm = radius_mm;
  s.feed_mm_per_min = feed;
  s.cyclic_period_mm = cyclic_period_mm;
  s.radius_calibrated = radius_calibrated;
  s.calibrated_radius_mm = calibrated_radius_mm;
  return s;
}

py::object circle_analyse(const std::vector<py::tuple>& traces, const std::string& plane,
                          double radius_mm, double feed_mm_per_min,
                          std::optional<double> cyclic_period_mm, bool radius_calibrated,
                          std::optional<double> calibrated_radius_mm, const std::string& standard) {
  const auto setup = circle_setup(plane, radius_mm, feed_mm_per_min, cyclic_period_mm,
                                  radius_calibrated, calibrated_radius_mm);
  const auto circular = cal::circle::circular_standard_from_key(standard);
  std::vector<cal::circle::Trace> ts;
  for (const auto& t : traces) {
    if (t.size() != 3)
      throw cal::InputError("a trace: expected (direction, angle_deg, deviation_um)");
    ts.push_back({circle_direction(t[0].cast<std::string>()), to_vector(t[1].cast<Doubles>()),
                  to_vector(t[2].cast<Doubles>())});
  }
  nlohmann::json doc;
  {
    py::gil_scoped_release release;
    doc = daq::circle_json(cal::circle::analyse(setup, ts), radius_mm, plane, feed_mm_per_min,
                           circular);
  }
  return from_json(doc);
}

py::list circular_standards() {
  py::list out;
  for (const auto& s : cal::circle::circular_standards()) {
    py::list values;
    for (const auto& v : s.values)
      values.append(py::dict(py::arg("key") = v.key, py::arg("symbol") = v.symbol,
                             py::arg("meaning") = v.meaning));
    out.append(py::dict(py::arg("key") = s.key, py::arg("label") = s.label,
                        py::arg("title") = s.title, py::arg("values") = values,
                        py::arg("note") = s.note));
  }
  return out;
}

// --- straightness, squareness ---------------------------------------------------------------

py::dict straightness_evaluate(const Doubles& position_mm, const Doubles& deviation_um,
                               const std::string& reference) {
  const auto p = to_vector(position_mm), dv = to_vector(deviation_um);
  const auto ref = cal::straightness::reference_from_string(reference);
  cal::straightness::Result r;
  {
    py::gil_scoped_release release;
    r = cal::straightness::evaluate(p, dv, ref);
  }
  return py::dict("reference"_a = std::string(cal::straightness::to_string(r.reference)),
                  "straightness_um"_a = r.straightness_um, "slope_um_per_m"_a = r.slope_um_per_m,
                  "intercept_um"_a = r.intercept_um, "residual_um"_a = to_array(r.residual_um));
}

py::dict squareness_dict(const cal::squareness::Result& r) {
  return py::dict("squareness_um_per_m"_a = r.squareness_um_per_m, "arcsec"_a = r.arcsec());
}

// --- uncertainty ----------------------------------------------------------------------------

py::object uncertainty_budget(const py::kwargs& kw) {
  cal::unc::PositioningSetup s;
  // Each keyword sets the field of the same name (docs/python.md lists them).
  const auto take = [&](const char* key, double& field) {
    if (kw.contains(key)) field = kw[key].cast<double>();
  };
  take("length_m", s.length_m);
  take("laser_cert_expanded_ppm", s.laser_cert_expanded_ppm);
  take("laser_cert_expanded_um", s.laser_cert_expanded_um);
  take("laser_cert_k", s.laser_cert_k);
  take("temperature_degc", s.air.temperature_degc);
  take("pressure_pa", s.air.pressure_pa);
  double rh = s.air.humidity.value;
  take("humidity_pct", rh);
  s.air.humidity = cal::air::Humidity::relative_pct(rh);
  take("co2_umol_per_mol", s.air.co2_umol_per_mol);
  take("wavelength_nm", s.air.wavelength_vacuum_nm);
  take("u_air_temperature_k", s.u_air_temperature_k);
  take("u_pressure_pa", s.u_pressure_pa);
  take("u_humidity_pct", s.u_humidity_pct);
  take("material_degc", s.material_degc);
  take("alpha_per_k", s.alpha_per_k);
  take("u_material_temperature_k", s.u_material_temperature_k);
  take("u_alpha_per_k", s.u_alpha_per_k);
  take("environmental_variation_um", s.environmental_variation_um);
  take("misalignment_offset_mm", s.misalignment_offset_mm);
  take("dead_path_m", s.dead_path_m);
  take("index_change_during_test", s.index_change_during_test);
  if (kw.contains("dead_path_corrected"))
    s.dead_path_corrected = kw["dead_path_corrected"].cast<bool>();
  if (kw.contains("equation"))
    s.equation = cal::air::equation_from_string(kw["equation"].cast<std::string>());
  static constexpr const char* known[] = {"length_m",
                                          "laser_cert_expanded_ppm",
                                          "laser_cert_expanded_um",
                                          "laser_cert_k",
                                          "temperature_degc",
                                          "pressure_pa",
                                          "humidity_pct",
                                          "co2_umol_per_mol",
                                          "wavelength_nm",
                                          "u_air_temperature_k",
                                          "u_pressure_pa",
                                          "u_humidity_pct",
                                          "material_degc",
                                          "alpha_per_k",
                                          "u_material_temperature_k",
                                          "u_alpha_per_k",
                                          "environmental_variation_um",
                                          "misalignment_offset_mm",
                                          "dead_path_m",
                                          "index_change_during_test",
                                          "dead_path_corrected",
                                          "equation"};
  for (const auto& [k, v] : kw) {
    const auto key = k.cast<std::string>();
    if (std::find(std::begin(known), std::end(known), key) == std::end(known))
      throw cal::InputError(fmt::format("uncertainty_budget: unknown setting '{}'", key));
  }
  auto j = daq::to_json(cal::unc::positioning_budget(s));
  j["schema"] = "caldaq.uncertainty.v1";
  j["length_m"] = s.length_m;
  return from_json(j);
}

}  // namespace

void bind_analysis(py::module_& m) {
  m.def("refractive_index", &refractive_index, py::arg("temperature_degc") = 20.0,
        py::arg("pressure_pa") = 101325.0, py::arg("humidity") = 50.0,
        py::arg("humidity_kind") = "relative", py::arg("co2_umol_per_mol") = 450.0,
        py::arg("wavelength_nm") = 632.991, py::arg("equation") = "ciddor");
  m.def("equation_standard_uncertainty", [](const std::string& equation) {
    return cal::air::equation_standard_uncertainty(cal::air::equation_from_string(equation));
  });
  m.def("iso230_2_standards", &iso230_2_standards);
  m.def("iso230_2_evaluate", &iso230_2_evaluate, py::arg("target_mm"), py::arg("run"),
        py::arg("direction"), py::arg("deviation_um"), py::arg("standard") = "iso230-2:2014");
  m.def("circular_standards", &circular_standards);
  m.def("circle_analyse", &circle_analyse, py::arg("traces"), py::arg("plane") = "XY",
        py::arg("radius_mm") = 100.0, py::arg("feed_mm_per_min") = 1000.0,
        py::arg("cyclic_period_mm") = py::none(), py::arg("radius_calibrated") = true,
        py::arg("calibrated_radius_mm") = py::none(), py::arg("standard") = "iso230-4:2005");
  m.def("straightness", &straightness_evaluate, py::arg("position_mm"), py::arg("deviation_um"),
        py::arg("reference") = "lsq");
  m.def(
      "squareness_from_straightness",
      [](const Doubles& a_pos, const Doubles& a_dev, const Doubles& b_pos, const Doubles& b_dev,
         double square_error_um_per_m) {
        return squareness_dict(cal::squareness::from_straightness(
            {to_vector(a_pos), to_vector(a_dev)}, {to_vector(b_pos), to_vector(b_dev)},
            square_error_um_per_m));
      },
      py::arg("a_position_mm"), py::arg("a_deviation_um"), py::arg("b_position_mm"),
      py::arg("b_deviation_um"), py::arg("square_error_um_per_m") = 0.0);
  m.def(
      "squareness_from_diagonals",
      [](double x_mm, double y_mm, double d1_um, double d2_um) {
        return squareness_dict(cal::squareness::from_diagonals(x_mm, y_mm, d1_um, d2_um));
      },
      py::arg("x_mm"), py::arg("y_mm"), py::arg("d1_um"), py::arg("d2_um"));
  m.def(
      "squareness_from_circle",
      [](double radius_mm, const std::vector<std::pair<Doubles, Doubles>>& traces) {
        std::vector<cal::squareness::CircleTrace> ts;
        for (const auto& [a, dv] : traces) ts.push_back({to_vector(a), to_vector(dv)});
        return squareness_dict(cal::squareness::from_circle(radius_mm, ts));
      },
      py::arg("radius_mm"), py::arg("traces"));
  m.def("uncertainty_budget", &uncertainty_budget);
  m.def(
      "verdict",
      [](const std::string& settings_json, const std::string& result_json) {
        const auto settings = nlohmann::json::parse(settings_json, nullptr, false);
        const auto result = nlohmann::json::parse(result_json, nullptr, false);
        if (settings.is_discarded() || result.is_discarded())
          throw cal::InputError("verdict: the settings and the result must be JSON documents");
        auto j = daq::to_json(daq::verdict_of(settings, result));
        return from_json(j);
      },
      py::arg("settings_json"), py::arg("result_json"));
  m.def(
      "compensation_factor",
      [](double n_air, double alpha_per_k, double material_degc) {
        const auto f = cal::comp::combined_factor(n_air, alpha_per_k, material_degc);
        return py::dict("n_air"_a = f.n_air, "material_degc"_a = f.material_degc,
                        "alpha_per_k"_a = f.alpha_per_k, "factor"_a = f.factor,
                        "air_ppm"_a = f.air_ppm, "material_ppm"_a = f.material_ppm,
                        "total_ppm"_a = f.total_ppm);
      },
      py::arg("n_air"), py::arg("alpha_per_k"), py::arg("material_degc"));
}

}  // namespace caldaq_py
