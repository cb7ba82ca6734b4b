#pragma once
// Volumetric compensation from the kinematic model (kinematics.hpp): the correction a controller
// must add to the commanded position so that the tool tip lands where commanded, either as a
// full volumetric correction (what a controller that evaluates the ISO 230 model itself does,
// e.g. ISG's volumetric compensation) or as one-dimensional cross-axis tables (one table per
// input axis and output axis, what SINUMERIK CEC, ISG cross compensation, HEIDENHAIN .COM and
// pitch tables hold). Derivations, the residual and its bound: docs/compensation-tables.md,
// "Volumetric compensation from the model".
//
// Units as in kinematics.hpp: positions mm, translations um, angles urad.
#include <array>
#include <cstddef>
#include <vector>

#include "cal/analysis/kinematics.hpp"

namespace cal::volcomp {

using kinematics::Axis;
using kinematics::Machine;
using kinematics::Plane;
using kinematics::Vec3;

// Which axis carries the correction of each squareness. The plane's non-reference axis (Y for
// XY, Z for XZ and YZ) carrying it corrects the other axis in proportion to its own travel
// (E_C0Y carried by Y: x += E_C0Y y): the reference axis stays as it is, the carrier is turned
// square to it. The reference axis carrying it turns the reference instead (E_C0Y carried by X:
// y += E_C0Y x): the axes become square, but the whole machine frame turns by the squareness,
// which the workpiece alignment takes up. The default follows the advice to decide by the
// spindle: Z (the spindle axis, ISO 841) carries the XZ and YZ squareness, so the feed along the
// spindle follows the spindle; Y carries XY, so X (usually aligned with the table's T-slots)
// stays the reference.
struct Carriers {
  Axis xy = kinematics::Y;  // X or Y
  Axis xz = kinematics::Z;  // X or Z
  Axis yz = kinematics::Z;  // Y or Z
  Axis of(Plane p) const { return p == Plane::xy ? xy : p == Plane::xz ? xz : yz; }
};
// Throws InputError naming the plane when a carrier is not one of the plane's axes.
void validate(const Carriers& c);

// The first-order correction at commanded position p: minus the first-order volumetric error,
// with each squareness term moved to its carrier. Adding it to the commanded position leaves a
// residual of second order in the errors (see residual_um).
Vec3 correction_um(const Machine& m, const Vec3& p_mm, const Carriers& carriers = {});

// What the tool tip does relative to the commanded position p when the machine is driven to
// p + correction(p): correction + e_htm(p + correction), um. For the default carriers this is
// second order in the errors (|e| |de/dp| + |htm - first order|); a carrier on a reference
// axis adds the rigid turn of the machine frame that it makes. Where the correction drives an
// axis a few micrometres past the end of a table, that axis is evaluated at p (the table's end
// value holds). Throws InputError where the model cannot be evaluated at p.
Vec3 residual_um(const Machine& m, const Vec3& p_mm, const Vec3& correction_um);

// One-dimensional cross-axis tables on a regular grid per axis.
struct AxisGrid {
  double start_mm = 0.0;
  double interval_mm = 10.0;
  int points = 2;
  double end_mm() const { return start_mm + interval_mm * (points - 1); }
};

// The correction of `output` as a function of the position of `input` (input == output is the
// axis's own positioning table).
struct CrossTable {
  Axis input = kinematics::X;
  Axis output = kinematics::X;
  double start_mm = 0.0;
  double interval_mm = 10.0;
  std::vector<double> correction_um;  // one per grid point
  double position_mm(std::size_t i) const {
    return start_mm + interval_mm * static_cast<double>(i);
  }
};

struct CrossTables {
  Vec3 reference_mm{};             // where the product terms are frozen (see cross_tables)
  std::vector<CrossTable> tables;  // nine: input X, Y, Z (in that order) by output X, Y, Z
  // The table of an input and output axis.
  const CrossTable& at(Axis input, Axis output) const { return tables.at(3 * input + output); }
};

// Splits the first-order correction into nine one-dimensional tables. The first-order error is
// a sum of functions of one axis each, plus the products of a change of one axis's angular
// error with the travel of an axis it carries, eps_i(q_i) x q_j e_j. One-dimensional tables
// cannot hold a product: it is frozen at `reference_mm`, so the tables are exact on the three
// lines through the reference point and leave elsewhere
//   sum over pairs (i before j in the chain) [eps_i(q_i) - eps_i(r_i)] x (q_j - r_j) e_j
// (first order in the angular errors' variation times the distance from the reference; shown
// by residual maps, see docs). The constant error at the reference point goes into the axes'
// own tables. Throws InputError for a bad grid (interval <= 0, fewer than 2 points, not
// finite), a reference outside the grid, or a model that cannot be evaluated on the grid.
CrossTables cross_tables(const Machine& m, const std::array<AxisGrid, 3>& grid,
                         const Vec3& reference_mm, const Carriers& carriers = {});

// The sum of the tables at p (linear interpolation in each, as the controllers do between
// their points), um. Throws InputError when p is outside a table.
Vec3 table_correction_um(const CrossTables& t, const Vec3& p_mm);

}  // namespace cal::volcomp
