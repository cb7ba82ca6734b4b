// The machine model for Python: a caldaq.model.v1 or v2 file read and validated as `daq model`
// reads it (daq/src/model), the volumetric error at points or over a grid (cal::kinematics), the
// five-axis error at poses of a model with rotary axes (cal::kinematics rotary.hpp, as `daq model
// map --points` gives it), and a model built from measured profiles (as `daq model build` builds
// it from stored runs).
#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <span>

#include "bindings.hpp"
#include "cal/analysis/error.hpp"
#include "cal/analysis/kinematics.hpp"
#include "cal/analysis/rotary.hpp"
#include "model/model_build.hpp"
#include "model/model_file.hpp"

namespace py = pybind11;
namespace kin = cal::kinematics;
namespace mdl = cal::daq::model;

namespace caldaq_py {
namespace {

using Doubles = py::array_t<double, py::array::c_style | py::array::forcecast>;

kin::Method method_of(const std::string& s) {
  if (s == "htm") return kin::Method::htm;
  if (s == "first-order") return kin::Method::first_order;
  throw cal::InputError(fmt::format("method '{}': expected htm or first-order", s));
}

py::array_t<double> rows3(const std::vector<double>& v) {
  py::array_t<double> a({static_cast<py::ssize_t>(v.size() / 3), py::ssize_t{3}});
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

// The model's rotary axes' letters from the workpiece to the tool ("C", "A").
std::vector<std::string> rotary_axes(const mdl::Model& m) {
  std::vector<std::string> out;
  for (const auto& r : m.rotary) out.emplace_back(kin::to_string(r.axis.letter));
  return out;
}

kin::Vec3 vec3(const std::vector<double>& v, const char* what) {
  if (v.size() != 3) throw cal::InputError(fmt::format("{}: expected 3 values (X Y Z)", what));
  return {v[0], v[1], v[2]};
}

// error_um and rotation_urad (N x 3) of error_of(k) for k < n, computed without the GIL.
template <typename ErrorOf>
py::dict errors_at(std::size_t n, ErrorOf&& error_of) {
  std::vector<double> err(3 * n), rot(3 * n);
  {
    py::gil_scoped_release release;
    for (std::size_t k = 0; k < n; ++k) {
      const kin::VolumetricError e = error_of(k);
      for (std::size_t i = 0; i < 3; ++i) {
        err[3 * k + i] = e.translation_um[i];
        rot[3 * k + i] = e.rotation_urad[i];
      }
    }
  }
  py::dict d;
  d["error_um"] = rows3(err);
  d["rotation_urad"] = rows3(rot);
  return d;
}

// A model with rotary axes maps poses, not points: the linear map would leave them out.
void require_linear(const mdl::Model& m, const char* what) {
  mdl::require_no_rotary(m, m.name.empty() ? "the model" : m.name, what);
}

// Translation and rotation at each row of an N x 3 array of positions (mm).
py::dict map_points(const mdl::Model& m, const Doubles& points_mm, const std::string& method) {
  require_linear(m, "Model.map_points (Model.map_poses maps its rotary axes)");
  if (points_mm.ndim() != 2 || points_mm.shape(1) != 3)
    throw cal::InputError("points_mm: expected an N x 3 array (x_mm, y_mm, z_mm)");
  const auto how = method_of(method);
  const double* p = points_mm.data();
  return errors_at(static_cast<std::size_t>(points_mm.shape(0)), [&](std::size_t k) {
    return kin::volumetric_error(m.machine, {p[3 * k], p[3 * k + 1], p[3 * k + 2]}, how);
  });
}

py::dict map_grid(const mdl::Model& m, const std::vector<std::size_t>& count,
                  std::optional<std::vector<double>> min_mm,
                  std::optional<std::vector<double>> max_mm, const std::string& method) {
  require_linear(m, "Model.map_grid (Model.map_poses maps its rotary axes)");
  if (count.size() != 3 || std::find(count.begin(), count.end(), 0u) != count.end())
    throw cal::InputError("count: expected three counts >= 1 (X Y Z)");
  if (min_mm.has_value() != max_mm.has_value())
    throw cal::InputError("give both min_mm and max_mm, or neither (the model's travel)");
  kin::Grid g = min_mm ? kin::Grid{vec3(*min_mm, "min_mm"),
                                   vec3(*max_mm, "max_mm"),
                                   {count[0], count[1], count[2]}}
                       : mdl::travel_grid(m, {count[0], count[1], count[2]});
  const auto how = method_of(method);
  kin::ErrorMap map;
  kin::MapSummary s;
  {
    py::gil_scoped_release release;
    map = kin::volumetric_error_map(m.machine, g, how);
    s = kin::summarize(map);
  }
  py::dict d;
  d["positions_mm"] = rows3(map.positions_mm);
  d["error_um"] = rows3(map.errors_um);
  d["rotation_urad"] = rows3(map.rotations_urad);
  d["count"] = std::vector<std::size_t>{map.count[0], map.count[1], map.count[2]};
  d["max_norm_um"] = s.max_norm_um;
  d["max_norm_at_mm"] = s.max_norm_at_mm;
  d["range_um"] = s.range_um;
  return d;
}

// The tool tip's position and orientation error at each row of an N x (3 + R) array of poses:
// x_mm, y_mm, z_mm and the angle (deg) of each of the model's R rotary axes in its order
// (Model.rotary_axes), as `daq model map --points` computes it (kin::five_axis_error).
py::dict map_poses(const mdl::Model& m, const Doubles& poses, const std::string& method) {
  const auto cols = static_cast<py::ssize_t>(3 + m.rotary.size());
  if (poses.ndim() != 2 || poses.shape(1) != cols) {
    std::string columns = "x_mm, y_mm, z_mm";
    for (const auto& a : rotary_axes(m)) columns += ", " + a + "_deg";
    throw cal::InputError(fmt::format("poses: expected an N x {} array ({})", cols, columns));
  }
  const auto how = method_of(method);
  const auto machine = mdl::five_axis(m);
  const auto width = static_cast<std::size_t>(cols);
  const double* p = poses.data();
  return errors_at(static_cast<std::size_t>(poses.shape(0)), [&](std::size_t k) {
    const double* row = p + width * k;
    if (m.rotary.empty())  // as `daq model map` maps a model without rotary axes
      return kin::volumetric_error(m.machine, {row[0], row[1], row[2]}, how);
    return kin::five_axis_error(machine, {row[0], row[1], row[2]},
                                std::span<const double>(row + 3, width - 3), how);
  });
}

mdl::Model build(const std::vector<py::dict>& profiles, const std::string& machine,
                 const std::string& topology, bool allow_missing) {
  std::vector<mdl::MeasuredProfile> ps;
  for (const auto& p : profiles) {
    mdl::MeasuredProfile m;
    m.component = p["component"].cast<std::string>();
    m.kind = p["kind"].cast<std::string>();
    m.position_mm = p["position_mm"].cast<std::vector<double>>();
    m.value = p["value"].cast<std::vector<double>>();
    if (p.contains("run_id")) m.run_id = p["run_id"].cast<std::int64_t>();
    if (p.contains("stationary_mm"))
      m.stationary_mm = vec3(p["stationary_mm"].cast<std::vector<double>>(), "stationary_mm");
    if (p.contains("probe_offset_mm"))
      m.probe_offset_mm = vec3(p["probe_offset_mm"].cast<std::vector<double>>(), "probe_offset_mm");
    if (p.contains("square")) m.square = p["square"].cast<bool>();
    ps.push_back(std::move(m));
  }
  mdl::BuildOptions o;
  o.machine = machine;
  o.topology = kin::topology_from_string(topology);
  o.allow_missing = allow_missing;
  return mdl::build(ps, o).model;
}

}  // namespace

void bind_model(py::module_& m) {
  py::class_<mdl::Model>(m, "Model")
      .def_static("load", &mdl::read, py::arg("path"))
      .def_static("parse", &mdl::parse, py::arg("text"), py::arg("where") = "<text>")
      .def_readonly("name", &mdl::Model::name)
      .def("to_json", [](const mdl::Model& x) { return mdl::to_json(x); })
      .def("save", [](const mdl::Model& x, const std::string& path) { mdl::write(x, path); })
      .def("map_points", &map_points, py::arg("points_mm"), py::arg("method") = "htm")
      .def_property_readonly("rotary_axes", &rotary_axes)
      .def("map_poses", &map_poses, py::arg("poses"), py::arg("method") = "htm")
      .def("map_grid", &map_grid, py::arg("count") = std::vector<std::size_t>{5, 5, 5},
           py::arg("min_mm") = py::none(), py::arg("max_mm") = py::none(),
           py::arg("method") = "htm");
  m.def("model_build", &build, py::arg("profiles"), py::arg("machine") = "",
        py::arg("topology") = "FXYZ", py::arg("allow_missing") = false);
}

}  // namespace caldaq_py
