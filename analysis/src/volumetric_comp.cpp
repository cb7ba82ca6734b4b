// Volumetric compensation from the model (see volumetric_comp.hpp and
// docs/compensation-tables.md).
#include "cal/analysis/volumetric_comp.hpp"

#include <fmt/format.h>

#include <cmath>

#include "cal/analysis/error.hpp"

namespace cal::volcomp {
namespace {

using kinematics::Method;
using kinematics::X;
using kinematics::Y;
using kinematics::Z;

constexpr double kUmPerUradMm = 1e-3;  // urad * mm = 1e-3 um
constexpr std::array kAxisNames{'X', 'Y', 'Z'};

// The correction of the squareness terms alone, on their carriers (kinematics.hpp: the error
// is (-E_C0Y y + E_B0Z z, -E_A0Z z, 0); minus that, moved to the carrier):
//   E_C0Y: by Y, x += c y;   by X, y += c x   (X turned to (1, c), square to Y = (-c, 1));
//   E_B0Z: by Z, x -= b z;   by X, z -= b x   (X turned to (1, 0, -b), square to Z = (b, 0, 1));
//   E_A0Z: by Z, y += a z;   by Y, z += a y   (Y turned to (0, 1, a), square to Z = (0, -a, 1)).
Vec3 squareness_correction_um(const kinematics::Squareness& s, const Carriers& c, const Vec3& p) {
  Vec3 k{};
  if (c.xy == Y) {
    k[X] += s.c0y_urad * p[Y];
  } else {
    k[Y] += s.c0y_urad * p[X];
  }
  if (c.xz == Z) {
    k[X] -= s.b0z_urad * p[Z];
  } else {
    k[Z] -= s.b0z_urad * p[X];
  }
  if (c.yz == Z) {
    k[Y] += s.a0z_urad * p[Z];
  } else {
    k[Z] += s.a0z_urad * p[Y];
  }
  for (double& v : k) v *= kUmPerUradMm;
  return k;
}

Machine without_squareness(const Machine& m) {
  Machine r = m;
  r.squareness = {};
  return r;
}

void check_grid(const std::array<AxisGrid, 3>& grid, const Vec3& reference) {
  for (std::size_t i = 0; i < 3; ++i) {
    const AxisGrid& g = grid[i];
    if (!std::isfinite(g.start_mm) || !std::isfinite(g.interval_mm) || !(g.interval_mm > 0)) {
      throw InputError(
          fmt::format("cross tables, axis {}: start {} mm, interval {} mm (expected "
                      "finite numbers and an interval > 0)",
                      kAxisNames[i], g.start_mm, g.interval_mm));
    }
    if (g.points < 2 || g.points > 100000) {
      throw InputError(fmt::format("cross tables, axis {}: {} points (expected 2 to 100000)",
                                   kAxisNames[i], g.points));
    }
    if (!(reference[i] >= g.start_mm - 1e-9 && reference[i] <= g.end_mm() + 1e-9)) {
      throw InputError(fmt::format(
          "cross tables: the reference position {} mm of axis {} is outside its grid {} .. {} mm",
          reference[i], kAxisNames[i], g.start_mm, g.end_mm()));
    }
  }
}

double interpolate(const CrossTable& t, double q_mm) {
  const double last = t.position_mm(t.correction_um.size() - 1);
  if (!(q_mm >= t.start_mm - 1e-9 && q_mm <= last + 1e-9)) {
    throw InputError(
        fmt::format("cross table {} -> {}: position {} mm is outside the table {} .. {} mm",
                    kAxisNames[t.input], kAxisNames[t.output], q_mm, t.start_mm, last));
  }
  const double u = (q_mm - t.start_mm) / t.interval_mm;
  const auto n = t.correction_um.size();
  const auto i = std::min(static_cast<std::size_t>(std::max(0.0, std::floor(u))), n - 2);
  const double f = u - static_cast<double>(i);
  return t.correction_um[i] + f * (t.correction_um[i + 1] - t.correction_um[i]);
}

}  // namespace

void validate(const Carriers& c) {
  for (Plane p : {Plane::xy, Plane::xz, Plane::yz}) {
    const std::string_view name = kinematics::to_string(p);
    const char carrier = kAxisNames.at(c.of(p));
    if (name.find(carrier) == std::string_view::npos) {
      throw InputError(fmt::format(
          "the {} squareness ({}) is carried by {}, which is not an axis of the {} plane", name,
          kinematics::location_error_name(p), carrier, name));
    }
  }
}

Vec3 correction_um(const Machine& m, const Vec3& p_mm, const Carriers& carriers) {
  validate(carriers);
  const Vec3 e = kinematics::volumetric_error_um(without_squareness(m), p_mm, Method::first_order);
  const Vec3 s = squareness_correction_um(m.squareness, carriers, p_mm);
  return {s[0] - e[0], s[1] - e[1], s[2] - e[2]};
}

Vec3 residual_um(const Machine& m, const Vec3& p_mm, const Vec3& correction) {
  const Vec3 driven{p_mm[0] + correction[0] * 1e-3, p_mm[1] + correction[1] * 1e-3,
                    p_mm[2] + correction[2] * 1e-3};
  // At the end of a measured table the correction can drive an axis a few micrometres past it,
  // where the model says nothing: there the table's end value holds (the axis is evaluated at
  // p), which changes the residual by the error's slope times the correction, ~1e-4 * 10 um.
  // Fewest axes held first; the last try holds all three and fails like any evaluation at p.
  for (unsigned held : {0u, 1u, 2u, 4u, 3u, 5u, 6u, 7u}) {
    Vec3 q = driven;
    for (std::size_t i = 0; i < 3; ++i)
      if (held & (1u << i)) q[i] = p_mm[i];
    try {
      const Vec3 e = kinematics::volumetric_error_um(m, q, Method::htm);
      return {correction[0] + e[0], correction[1] + e[1], correction[2] + e[2]};
    } catch (const InputError&) {
      if (held == 7u) throw;
    }
  }
  return {};  // not reached
}

CrossTables cross_tables(const Machine& m, const std::array<AxisGrid, 3>& grid,
                         const Vec3& reference_mm, const Carriers& carriers) {
  validate(carriers);
  check_grid(grid, reference_mm);
  const Machine bare = without_squareness(m);
  const Vec3 at_reference =
      kinematics::volumetric_error_um(bare, reference_mm, Method::first_order);
  CrossTables out;
  out.reference_mm = reference_mm;
  out.tables.resize(9);
  for (std::size_t i = 0; i < 3; ++i) {
    for (std::size_t o = 0; o < 3; ++o) {
      CrossTable& t = out.tables[3 * i + o];
      t.input = static_cast<Axis>(i);
      t.output = static_cast<Axis>(o);
      t.start_mm = grid[i].start_mm;
      t.interval_mm = grid[i].interval_mm;
      t.correction_um.assign(static_cast<std::size_t>(grid[i].points), 0.0);
    }
    for (std::size_t n = 0; n < static_cast<std::size_t>(grid[i].points); ++n) {
      Vec3 p = reference_mm;
      p[i] = out.tables[3 * i].position_mm(n);
      // G_i(q) = e(r with r_i = q) - e(r): what moving axis i alone adds; minus it corrects it.
      const Vec3 e = kinematics::volumetric_error_um(bare, p, Method::first_order);
      Vec3 only_i{};
      only_i[i] = p[i];
      const Vec3 s = squareness_correction_um(m.squareness, carriers, only_i);
      for (std::size_t o = 0; o < 3; ++o) {
        double c = -(e[o] - at_reference[o]) + s[o];
        if (o == i) c -= at_reference[o];  // the constant error at the reference point
        out.tables[3 * i + o].correction_um[n] = c;
      }
    }
  }
  return out;
}

Vec3 table_correction_um(const CrossTables& t, const Vec3& p_mm) {
  Vec3 c{};
  for (const CrossTable& table : t.tables) c[table.output] += interpolate(table, p_mm[table.input]);
  return c;
}

}  // namespace cal::volcomp
