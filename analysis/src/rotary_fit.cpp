// Several rotary axes' location errors fitted together to sphere centres probed at any poses:
// rotary_fit.hpp; derivation and tests: docs/kinematics.md, "Several rotary axes fitted
// together".
#include "cal/analysis/rotary_fit.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "cal/analysis/error.hpp"

namespace cal::kinematics {
namespace {

using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::VectorXd;

constexpr double kMmPerUm = 1e-3;
constexpr double kRadPerUrad = 1e-6;
// Central-difference step on parameters in mm and rad: the model is smooth; the truncation error
// is far below a probed centre's rounding.
constexpr double kStep = 1e-6;
// Unit-column design: below this share of the largest singular value the poses do not tell the
// parameters apart. Dependent columns differ only by the model's second-order terms, about the
// errors' size in rad (1e-5 for tens of urad): well-posed programs give 1e-2 and more.
constexpr double kSeparable = 1e-4;
// A parameter that moves no centre by more than this (mm per mm or per rad) is not seen at all:
// its column is rounding noise, which scaling to unit length would make look independent.
constexpr double kUnseenMmPer = 1e-6;

Vector3d vec(const Vec3& v) { return {v[0], v[1], v[2]}; }
Vec3 arr(const Vector3d& v) { return {v.x(), v.y(), v.z()}; }

// The two slots across an axis's direction, by increasing index.
std::array<std::size_t, 2> across(RotaryLetter l) {
  const std::size_t own = direction_index(l);
  return own == 0   ? std::array<std::size_t, 2>{1, 2}
         : own == 1 ? std::array<std::size_t, 2>{0, 2}
                    : std::array<std::size_t, 2>{0, 1};
}

struct Problem {
  FiveAxisMachine truth;    // the candidate: its fitted axes take the parameters
  FiveAxisMachine control;  // what reported the centres
  std::vector<std::size_t> axes;
};

void set_parameters(Problem& p, const VectorXd& q) {
  for (std::size_t a = 0; a < p.axes.size(); ++a) {
    RotaryAxis& r = p.truth.rotary[p.axes[a]];
    const auto slots = across(r.letter);
    r.location_position_um = {};
    r.location_orientation_urad = {};
    for (std::size_t k = 0; k < 2; ++k) {
      const auto i = static_cast<Eigen::Index>(3 + 4 * a + k);
      r.location_position_um[slots[k]] = q[i] / kMmPerUm;
      r.location_orientation_urad[slots[k]] = q[i + 2] / kRadPerUrad;
    }
  }
}

// reported - predicted, 3 per pose, mm.
VectorXd residuals(Problem& p, std::span<const ProbedPose> poses, const VectorXd& q) {
  set_parameters(p, q);
  const Vec3 sphere{q[0], q[1], q[2]};
  VectorXd r(3 * static_cast<Eigen::Index>(poses.size()));
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const Vector3d want = vec(probed_centre_mm(p.truth, p.control, sphere, poses[k].angles_deg));
    r.segment<3>(3 * static_cast<Eigen::Index>(k)) = vec(poses[k].centre_mm) - want;
  }
  return r;
}

MatrixXd jacobian(Problem& p, std::span<const ProbedPose> poses, const VectorXd& q) {
  MatrixXd j(3 * static_cast<Eigen::Index>(poses.size()), q.size());
  for (Eigen::Index c = 0; c < q.size(); ++c) {
    VectorXd hi = q, lo = q;
    hi[c] += kStep;
    lo[c] -= kStep;
    j.col(c) = (residuals(p, poses, hi) - residuals(p, poses, lo)) / (2.0 * kStep);
  }
  return j;
}

void check_input(const FiveAxisMachine& control, std::span<const std::size_t> axes,
                 std::span<const ProbedPose> poses, double probe_u_um) {
  if (axes.empty()) throw InputError("no rotary axis to fit");
  for (std::size_t a = 0; a < axes.size(); ++a) {
    if (axes[a] >= control.rotary.size()) {
      throw InputError(
          fmt::format("rotary axis {} to fit: the chain has {}", axes[a], control.rotary.size()));
    }
    if (std::count(axes.begin(), axes.end(), axes[a]) > 1) {
      throw InputError(fmt::format("rotary axis {} given twice", axes[a]));
    }
  }
  if (!(std::isfinite(probe_u_um) && probe_u_um >= 0.0)) {
    throw InputError(
        fmt::format("probe_u_um = {}: expected a finite value >= 0 (0: estimate the "
                    "uncertainty from the residuals)",
                    probe_u_um));
  }
  const std::size_t n_par = 3 + 4 * axes.size();
  if (3 * poses.size() < n_par + 1) {
    throw InputError(fmt::format(
        "{} probed pose(s) for {} parameters (the sphere and 4 location errors per axis): "
        "give at least {}",
        poses.size(), n_par, n_par / 3 + 1));
  }
  for (std::size_t k = 0; k < poses.size(); ++k) {
    if (poses[k].angles_deg.size() != control.rotary.size()) {
      throw InputError(fmt::format("probed pose {}: {} angle(s) for {} rotary axis/axes", k,
                                   poses[k].angles_deg.size(), control.rotary.size()));
    }
    for (double a : poses[k].angles_deg) {
      if (!std::isfinite(a)) {
        throw InputError(fmt::format("probed pose {}: angle {}: expected a finite number", k, a));
      }
    }
    for (double x : poses[k].centre_mm) {
      if (!std::isfinite(x)) {
        throw InputError(fmt::format("probed pose {}: centre {}: expected a finite number", k, x));
      }
    }
  }
}

// The start: where the nominal machine puts the sphere for each centre (the control's tip is
// affine in the linear position: solve it, then read the nominal tip in the workpiece frame),
// averaged. The location errors start at 0.
Vector3d initial_sphere(const FiveAxisMachine& nominal, std::span<const ProbedPose> poses) {
  Vector3d sum = Vector3d::Zero();
  for (const ProbedPose& pose : poses) {
    const auto tip = [&](const Vector3d& p) {
      return vec(control_tip_mm(nominal, arr(p), pose.angles_deg));
    };
    const Vector3d b = tip(Vector3d::Zero());
    Eigen::Matrix3d a;
    for (Eigen::Index i = 0; i < 3; ++i) a.col(i) = tip(Vector3d::Unit(i)) - b;
    const Vector3d p = a.partialPivLu().solve(vec(pose.centre_mm) - b);
    sum += vec(five_axis_nominal_tip_mm(nominal, arr(p), pose.angles_deg));
  }
  return sum / static_cast<double>(poses.size());
}

}  // namespace

double fit_sigma_mm(double sum_sq_mm2, int dof, double probe_u_um) {
  if (probe_u_um > 0.0) return probe_u_um * kMmPerUm;
  if (dof > 0) return std::sqrt(sum_sq_mm2 / dof);
  return std::numeric_limits<double>::quiet_NaN();
}

LocationFit fit_location_errors(const FiveAxisMachine& control, std::span<const std::size_t> axes,
                                std::span<const ProbedPose> poses, double probe_u_um,
                                bool with_linear_errors) {
  check_input(control, axes, poses, probe_u_um);
  Problem pr;
  pr.control = control_kinematics(control);
  pr.truth = pr.control;
  if (with_linear_errors) pr.truth.linear = control.linear;
  pr.axes.assign(axes.begin(), axes.end());
  const auto n_par = static_cast<Eigen::Index>(3 + 4 * axes.size());

  VectorXd q = VectorXd::Zero(n_par);
  q.head<3>() = initial_sphere(nominal_kinematics(control), poses);
  for (int it = 0; it < 20; ++it) {
    const MatrixXd j = jacobian(pr, poses, q);
    const VectorXd step = j.colPivHouseholderQr().solve(-residuals(pr, poses, q));
    q += step;
    // 1e-10 mm or rad: far below what the fit resolves (the noise-free recovery is tested to
    // 1e-7 mm); with noise the steps stall at the solver's rounding, not at 0.
    if (step.norm() < 1e-10) break;
  }
  const MatrixXd j = jacobian(pr, poses, q);
  const VectorXd r = residuals(pr, poses, q);

  MatrixXd scaled = j;
  for (Eigen::Index c = 0; c < n_par; ++c) {
    const double n = scaled.col(c).norm();
    if (!(n > kUnseenMmPer)) {
      const std::string what =
          c < 3 ? std::string("the sphere's position")
                : fmt::format("a location error of the {} axis",
                              to_string(control.rotary[pr.axes[(c - 3) / 4]].letter));
      throw InputError(fmt::format(
          "the {} probed poses do not see {} at all (the centres move {:.1e} mm per unit of it): "
          "an axis that never turns in the program cannot be fitted",
          poses.size(), what, n));
    }
    scaled.col(c) /= n;
  }
  const Eigen::JacobiSVD<MatrixXd> svd(scaled);
  const VectorXd sv = svd.singularValues();
  if (!(sv[n_par - 1] > kSeparable * sv[0])) {
    throw InputError(fmt::format(
        "the {} probed poses cannot separate the fitted location errors (the design's smallest "
        "singular value is {:.2e} of its largest): a position and an orientation that move the "
        "probe alike, as when the probe tip is on a head axis's line (it cannot tell the line's "
        "position from its orientation), or too few distinct angles; probe with the tip off the "
        "line, at more angles",
        poses.size(), sv[n_par - 1] / sv[0]));
  }

  LocationFit fit;
  fit.axes = pr.axes;
  fit.separability = sv[n_par - 1] / sv[0];
  fit.dof = static_cast<int>(r.size() - n_par);
  const double ss = r.squaredNorm();
  fit.rms_um = std::sqrt(ss / static_cast<double>(r.size())) / kMmPerUm;
  const double sigma_mm = fit_sigma_mm(ss, fit.dof, probe_u_um);
  fit.sigma_um = sigma_mm / kMmPerUm;
  const MatrixXd cov = sigma_mm * sigma_mm * (j.transpose() * j).inverse();
  fit.covariance.assign(cov.data(), cov.data() + cov.size());  // symmetric: any order
  const auto u = [&](Eigen::Index i) { return std::sqrt(cov(i, i)); };
  for (Eigen::Index i = 0; i < 3; ++i) {
    fit.sphere_mm[static_cast<std::size_t>(i)] = q[i];
    fit.sphere_u_um[static_cast<std::size_t>(i)] = u(i) / kMmPerUm;
  }
  for (std::size_t a = 0; a < axes.size(); ++a) {
    const auto slots = across(control.rotary[axes[a]].letter);
    Vec3 pos{}, pos_u{}, ori{}, ori_u{};
    for (std::size_t k = 0; k < 2; ++k) {
      const auto i = static_cast<Eigen::Index>(3 + 4 * a + k);
      pos[slots[k]] = q[i] / kMmPerUm;
      pos_u[slots[k]] = u(i) / kMmPerUm;
      ori[slots[k]] = q[i + 2] / kRadPerUrad;
      ori_u[slots[k]] = u(i + 2) / kRadPerUrad;
    }
    fit.position_um.push_back(pos);
    fit.position_u_um.push_back(pos_u);
    fit.orientation_urad.push_back(ori);
    fit.orientation_u_urad.push_back(ori_u);
  }
  for (std::size_t k = 0; k < poses.size(); ++k) {
    fit.residual_um.push_back(arr(r.segment<3>(3 * static_cast<Eigen::Index>(k)) / kMmPerUm));
  }
  return fit;
}

namespace {

// The signed offset of the second line from the first (rotary_fit.hpp), mm, for the parameters
// of the two axes: positions (mm) and orientations (rad) in their slots.
double offset_mm(const RotaryAxis& r1, const RotaryAxis& r2, const std::array<double, 8>& p) {
  const auto line = [](const RotaryAxis& r, const double* q, Vector3d& point, Vector3d& dir) {
    const auto slots = across(r.letter);
    Vector3d pos = Vector3d::Zero(), ori = Vector3d::Zero();
    for (std::size_t k = 0; k < 2; ++k) {
      pos[static_cast<Eigen::Index>(slots[k])] = q[k];
      ori[static_cast<Eigen::Index>(slots[k])] = q[2 + k];
    }
    point = vec(r.pivot_mm) + pos;
    Vector3d d = Vector3d::Zero();
    d[static_cast<Eigen::Index>(direction_index(r.letter))] = 1.0;
    // R(e) = Rz Ry Rx, as the model builds the actual direction (rotary.hpp).
    dir = (Eigen::AngleAxisd(ori.z(), Vector3d::UnitZ()) *
           Eigen::AngleAxisd(ori.y(), Vector3d::UnitY()) *
           Eigen::AngleAxisd(ori.x(), Vector3d::UnitX())) *
          d;
  };
  Vector3d p1, d1, p2, d2;
  line(r1, p.data(), p1, d1);
  line(r2, p.data() + 4, p2, d2);
  const Vector3d n = d1.cross(d2);
  if (n.norm() < 1e-9) return ((p2 - p1) - (p2 - p1).dot(d1) * d1).norm();
  return (p2 - p1).dot(n.normalized());
}

}  // namespace

LineOffset line_offset(const FiveAxisMachine& control, const LocationFit& fit, std::size_t first,
                       std::size_t second) {
  if (first >= fit.axes.size() || second >= fit.axes.size() || first == second) {
    throw InputError(
        fmt::format("line_offset: axes {} and {} of a fit of {}", first, second, fit.axes.size()));
  }
  const RotaryAxis& r1 = control.rotary.at(fit.axes[first]);
  const RotaryAxis& r2 = control.rotary.at(fit.axes[second]);
  std::array<double, 8> p{};
  std::array<Eigen::Index, 8> index{};
  for (std::size_t half = 0; half < 2; ++half) {
    const std::size_t a = half == 0 ? first : second;
    const auto slots = across(control.rotary.at(fit.axes[a]).letter);
    for (std::size_t k = 0; k < 2; ++k) {
      p[4 * half + k] = fit.position_um[a][slots[k]] * kMmPerUm;
      p[4 * half + 2 + k] = fit.orientation_urad[a][slots[k]] * kRadPerUrad;
      index[4 * half + k] = static_cast<Eigen::Index>(3 + 4 * a + k);
      index[4 * half + 2 + k] = static_cast<Eigen::Index>(3 + 4 * a + 2 + k);
    }
  }
  LineOffset out;
  out.distance_mm = offset_mm(r1, r2, p);
  Eigen::Matrix<double, 8, 1> g;
  for (std::size_t k = 0; k < 8; ++k) {
    auto hi = p, lo = p;
    hi[k] += kStep;
    lo[k] -= kStep;
    g[static_cast<Eigen::Index>(k)] = (offset_mm(r1, r2, hi) - offset_mm(r1, r2, lo)) / (2 * kStep);
  }
  const auto n = static_cast<Eigen::Index>(std::sqrt(static_cast<double>(fit.covariance.size())));
  const Eigen::Map<const MatrixXd> cov(fit.covariance.data(), n, n);
  double var = 0.0;
  for (Eigen::Index i = 0; i < 8; ++i)
    for (Eigen::Index k = 0; k < 8; ++k) var += g[i] * cov(index[i], index[k]) * g[k];
  out.u_um = std::sqrt(var) / kMmPerUm;
  return out;
}

}  // namespace cal::kinematics
