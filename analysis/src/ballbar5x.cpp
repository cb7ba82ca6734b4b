// The ballbar on a rotary table axis (ballbar5x.hpp; derivation in docs/kinematics.md, "The
// ballbar on a rotary axis").
#include "cal/analysis/ballbar5x.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <numbers>

#include "cal/analysis/error.hpp"

namespace cal::kinematics {
namespace {

using Eigen::Matrix3d;
using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::VectorXd;

constexpr double kRadPerDeg = std::numbers::pi / 180.0;
constexpr double kMinRadiusMm = 1.0;      // radial / tangential need the ball off the line
constexpr double kMaxLengthMm = 2000.0;   // longer than any ballbar
constexpr double kSeparableRatio = 1e-9;  // smallest / largest singular value of the design

Vector3d vec(const Vec3& v) { return {v[0], v[1], v[2]}; }
Vec3 arr(const Vector3d& v) { return {v.x(), v.y(), v.z()}; }

Vector3d unit_of(RotaryLetter l) {
  return Vector3d::Unit(static_cast<Eigen::Index>(direction_index(l)));
}

// The index of the axis in the chain; a table axis, or InputError.
std::size_t axis_index(const FiveAxisMachine& m, RotaryLetter l) {
  for (std::size_t i = 0; i < m.rotary.size(); ++i) {
    if (m.rotary[i].letter != l) continue;
    if (m.rotary[i].side != Side::table) {
      throw InputError(fmt::format(
          "the {} axis is on the spindle side: the ballbar tests here are of table axes",
          to_string(l)));
    }
    return i;
  }
  throw InputError(fmt::format("the machine has no {} axis", to_string(l)));
}

std::vector<double> angles_at(const FiveAxisMachine& m, std::size_t index, double deg) {
  std::vector<double> a(m.rotary.size(), 0.0);
  a[index] = deg;
  return a;
}

void check_test(const RotaryBallbarTest& t) {
  for (double x : t.table_ball_mm) {
    if (!std::isfinite(x)) throw InputError(fmt::format("test {}: table ball not finite", t.name));
  }
  if (!(t.length_mm > 0.0 && t.length_mm <= kMaxLengthMm)) {
    throw InputError(fmt::format("test {}: bar length {} mm must be in (0, {}] mm", t.name,
                                 t.length_mm, kMaxLengthMm));
  }
  if (t.angles_deg.empty()) throw InputError(fmt::format("test {}: no angles", t.name));
  for (double a : t.angles_deg) {
    if (!std::isfinite(a) || std::abs(a) > 3600.0) {
      throw InputError(fmt::format("test {}: angle {} deg is not finite within +-3600", t.name, a));
    }
  }
}

// The four location errors' slots (position slots, then orientation slots, the axis's own
// direction left out): the order of location_error_names.
std::array<std::size_t, 2> cross_slots(RotaryLetter l) {
  const std::size_t own = direction_index(l);
  std::array<std::size_t, 2> s{};
  std::size_t n = 0;
  for (std::size_t i = 0; i < 3; ++i) {
    if (i != own) s.at(n++) = i;
  }
  return s;
}

}  // namespace

std::string_view to_string(BarSetup s) {
  switch (s) {
    case BarSetup::tangential:
      return "tangential";
    case BarSetup::axial:
      return "axial";
    case BarSetup::radial:
      return "radial";
  }
  return "radial";  // no value but the three (no default: -Wswitch names a new one)
}

BarSetup bar_setup_from_string(std::string_view s) {
  if (s == "radial") return BarSetup::radial;
  if (s == "tangential") return BarSetup::tangential;
  if (s == "axial") return BarSetup::axial;
  throw InputError(
      fmt::format("bar set-up '{}' is unknown (expected radial, tangential or axial)", s));
}

Vec3 bar_direction(const FiveAxisMachine& m, const RotaryBallbarTest& t) {
  check_test(t);
  const RotaryAxis& r = m.rotary[axis_index(m, t.axis)];
  const Vector3d d = unit_of(t.axis);
  if (t.setup == BarSetup::axial) return arr(d);
  Vector3d rho = vec(t.table_ball_mm) - vec(r.pivot_mm);
  rho -= rho.dot(d) * d;
  if (rho.norm() < kMinRadiusMm) {
    throw InputError(fmt::format(
        "test {}: the table ball is {:.3f} mm from the {} axis line: a {} set-up needs it at "
        "least {} mm off the line",
        t.name, rho.norm(), to_string(t.axis), to_string(t.setup), kMinRadiusMm));
  }
  rho.normalize();
  return arr(t.setup == BarSetup::radial ? rho : Vector3d(d.cross(rho)));
}

Vec3 tool_ball_mm(const FiveAxisMachine& m, const RotaryBallbarTest& t) {
  return arr(vec(t.table_ball_mm) + t.length_mm * vec(bar_direction(m, t)));
}

Vec3 rotary_ballbar_command_mm(const FiveAxisMachine& control, const RotaryBallbarTest& t,
                               double angle_deg) {
  const std::size_t index = axis_index(control, t.axis);
  return probed_centre_mm(control, tool_ball_mm(control, t), angles_at(control, index, angle_deg));
}

std::vector<double> rotary_ballbar_readings_um(const FiveAxisMachine& truth,
                                               const FiveAxisMachine& control,
                                               const RotaryBallbarTest& t) {
  const std::size_t index = axis_index(truth, t.axis);
  (void)axis_index(control, t.axis);
  const Vector3d table = vec(t.table_ball_mm);
  std::vector<double> out;
  out.reserve(t.angles_deg.size());
  for (double deg : t.angles_deg) {
    const auto angles = angles_at(truth, index, deg);
    const Vector3d linear =
        vec(rotary_ballbar_command_mm(control, t, deg)) - vec(control.linear.tool_offset_mm);
    // Where the truth puts the spindle ball in the workpiece frame at that command.
    const Vector3d actual =
        vec(five_axis_nominal_tip_mm(truth, arr(linear), angles)) +
        1e-3 * vec(five_axis_error(truth, arr(linear), angles, Method::htm).translation_um);
    out.push_back(1e3 * ((actual - table).norm() - t.length_mm));
  }
  return out;
}

std::vector<std::array<double, 4>> rotary_ballbar_sensitivity(const FiveAxisMachine& m,
                                                              const RotaryBallbarTest& t) {
  const RotaryAxis& r = m.rotary[axis_index(m, t.axis)];
  const Vector3d u = vec(bar_direction(m, t));
  const Vector3d v = vec(tool_ball_mm(m, t)) - vec(r.pivot_mm);
  const Vector3d d = unit_of(t.axis);
  const auto slots = cross_slots(t.axis);
  std::vector<std::array<double, 4>> out;
  for (double deg : t.angles_deg) {
    const Matrix3d rt = Eigen::AngleAxisd(-deg * kRadPerDeg, d).toRotationMatrix();
    const Matrix3d i_rt = Matrix3d::Identity() - rt;
    std::array<double, 4> s{};
    for (std::size_t k = 0; k < 2; ++k) {
      const Vector3d col = i_rt.col(static_cast<Eigen::Index>(slots.at(k)));
      s.at(k) = u.dot(col);                      // um per um of position
      s.at(k + 2) = 1e-3 * col.dot(v.cross(u));  // um per urad: (w x v).u = w.(v x u), v in mm
    }
    out.push_back(s);
  }
  return out;
}

FiveAxisMachine with_location_errors(const FiveAxisMachine& m, RotaryLetter axis,
                                     const std::array<double, 4>& value) {
  FiveAxisMachine out = m;
  RotaryAxis& r = out.rotary[axis_index(out, axis)];
  const auto slots = cross_slots(axis);
  for (std::size_t k = 0; k < 2; ++k) {
    r.location_position_um.at(slots.at(k)) = value.at(k);
    r.location_orientation_urad.at(slots.at(k)) = value.at(k + 2);
  }
  return out;
}

RotaryBallbarFit fit_rotary_ballbar(const FiveAxisMachine& control, RotaryLetter axis,
                                    std::span<const RotaryBallbarRun> runs, double reading_u_um) {
  if (runs.empty()) throw InputError("ballbar fit: no test");
  if (!(reading_u_um >= 0.0) || !std::isfinite(reading_u_um)) {
    throw InputError(
        fmt::format("ballbar fit: reading uncertainty {} um must be >= 0", reading_u_um));
  }
  (void)axis_index(control, axis);
  std::size_t rows = 0;
  for (const auto& run : runs) {
    if (run.test.axis != axis) {
      throw InputError(fmt::format("ballbar fit of the {} axis: test {} turns the {} axis",
                                   to_string(axis), run.test.name, to_string(run.test.axis)));
    }
    check_test(run.test);
    if (run.reading_um.size() != run.test.angles_deg.size()) {
      throw InputError(fmt::format("test {}: {} readings for {} angles", run.test.name,
                                   run.reading_um.size(), run.test.angles_deg.size()));
    }
    for (double x : run.reading_um) {
      if (!std::isfinite(x))
        throw InputError(fmt::format("test {}: a reading is not finite", run.test.name));
    }
    rows += run.reading_um.size();
  }
  const auto cols = static_cast<Eigen::Index>(4 + runs.size());
  // The design matrix: the four sensitivities, one offset column per run.
  MatrixXd j = MatrixXd::Zero(static_cast<Eigen::Index>(rows), cols);
  Eigen::Index row = 0;
  for (std::size_t n = 0; n < runs.size(); ++n) {
    for (const auto& s : rotary_ballbar_sensitivity(control, runs[n].test)) {
      for (Eigen::Index k = 0; k < 4; ++k) j(row, k) = s.at(static_cast<std::size_t>(k));
      j(row, 4 + static_cast<Eigen::Index>(n)) = 1.0;
      ++row;
    }
  }
  const Eigen::JacobiSVD<MatrixXd> svd(j, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const VectorXd sv = svd.singularValues();
  if (static_cast<Eigen::Index>(rows) < cols || sv(sv.size() - 1) <= kSeparableRatio * sv(0)) {
    const auto names = location_error_names(axis);
    throw InputError(fmt::format(
        "ballbar fit of the {} axis: these {} test(s) cannot separate {}, {}, {}, {} and each "
        "test's offset (e.g. radial tests at one height cannot tell {} from {}): add an axial "
        "test, or a radial one at another height",
        to_string(axis), runs.size(), names[0], names[1], names[2], names[3], names[0], names[3]));
  }
  // Gauss-Newton: predicted readings from the exact model with the current estimate.
  const auto axis_now = control.rotary[axis_index(control, axis)];
  const auto slots = cross_slots(axis);
  std::array<double, 4> value{};
  for (std::size_t k = 0; k < 2; ++k) {
    value.at(k) = axis_now.location_position_um.at(slots.at(k));
    value.at(k + 2) = axis_now.location_orientation_urad.at(slots.at(k));
  }
  VectorXd offsets = VectorXd::Zero(static_cast<Eigen::Index>(runs.size()));
  VectorXd residual(static_cast<Eigen::Index>(rows));
  const auto compute_residual = [&] {
    const FiveAxisMachine guess = with_location_errors(control, axis, value);
    Eigen::Index at = 0;
    for (std::size_t n = 0; n < runs.size(); ++n) {
      const auto predicted = rotary_ballbar_readings_um(guess, control, runs[n].test);
      for (std::size_t k = 0; k < predicted.size(); ++k) {
        residual(at++) =
            runs[n].reading_um[k] - predicted[k] - offsets(static_cast<Eigen::Index>(n));
      }
    }
  };
  for (int it = 0; it < 4; ++it) {
    compute_residual();
    const VectorXd step = svd.solve(residual);
    for (std::size_t k = 0; k < 4; ++k) value.at(k) += step(static_cast<Eigen::Index>(k));
    offsets += step.tail(static_cast<Eigen::Index>(runs.size()));
    if (step.norm() < 1e-9) break;
  }
  compute_residual();
  RotaryBallbarFit fit;
  fit.axis = axis;
  fit.value = value;
  fit.dof = static_cast<int>(rows) - static_cast<int>(cols);
  fit.rms_um = std::sqrt(residual.squaredNorm() / static_cast<double>(rows));
  fit.sigma_um = reading_u_um > 0.0 ? reading_u_um
                 : fit.dof > 0      ? std::sqrt(residual.squaredNorm() / fit.dof)
                                    : std::numeric_limits<double>::quiet_NaN();
  // Covariance sigma^2 (J^T J)^-1 from the SVD: V diag(1/s^2) V^T.
  const MatrixXd vs = svd.matrixV() * sv.cwiseInverse().asDiagonal();
  const MatrixXd cov = fit.sigma_um * fit.sigma_um * vs * vs.transpose();
  for (std::size_t k = 0; k < 4; ++k) {
    fit.uncertainty.at(k) =
        std::sqrt(cov(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(k)));
  }
  Eigen::Index at = 0;
  for (std::size_t n = 0; n < runs.size(); ++n) {
    const auto c = static_cast<Eigen::Index>(4 + n);
    fit.offset_um.push_back(offsets(static_cast<Eigen::Index>(n)));
    fit.offset_u_um.push_back(std::sqrt(cov(c, c)));
    std::vector<double> res;
    for (std::size_t k = 0; k < runs[n].reading_um.size(); ++k) res.push_back(residual(at++));
    fit.residual_um.push_back(std::move(res));
  }
  return fit;
}

}  // namespace cal::kinematics
