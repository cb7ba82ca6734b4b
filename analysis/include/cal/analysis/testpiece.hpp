#pragma once
// A machining test piece after ISO 10791-7 (the finishing test piece of machining centres): its
// side faces and bores predicted from the kinematic model, and the same features evaluated from
// CMM points with the same reference fits, so prediction and measurement compare one to one.
// Derivations and the reference fits: docs/testpiece.md.
//
// The part's frame: origin at the centre of the piece, X and Y along the machine's axes, the
// features cut at one height. The layout is a square boss with four side faces and five bores
// (one in the centre, four on the diagonals); its dimensions are parameters: the standard's
// drawing was not available to us, so no dimension of it is assumed.
#include <array>
#include <span>
#include <string>
#include <vector>

#include "cal/analysis/kinematics.hpp"

namespace cal::testpiece {

struct Layout {
  double side_mm = 100.0;       // the square's side
  double face_margin_mm = 5.0;  // left unevaluated at each end of a face
  double centre_bore_diameter_mm = 30.0;
  double corner_bore_diameter_mm = 16.0;
  double corner_bore_offset_mm = 30.0;  // corner bores at (+-offset, +-offset)
  int points_per_face = 21;
  int points_per_bore = 72;
};

struct Cutting {
  // Where the part's origin is in machine coordinates when cut: x, y of the centre and z, the
  // commanded height of the tool tip (the cutting height).
  kinematics::Vec3 origin_mm{};
  double tool_radius_mm = 5.0;
};

// The features, by name: "face+X", "face-X", "face+Y", "face-Y", "bore0" (centre), "bore1" ..
// "bore4" (at (+c, +c), (-c, +c), (-c, -c), (+c, -c)).
struct Profile {
  std::string feature;
  // Faces: position along the face (mm) and the deviation in the + direction of the axis
  // normal to the face (um); bores: angle from +X (deg) and the radial deviation (um).
  std::vector<double> position, deviation_um;
};

struct Point {  // a CMM point in the part's frame
  std::string feature;
  double x_mm = 0.0, y_mm = 0.0;
};

struct FaceResult {
  std::string feature;
  double straightness_um = 0.0;  // minimum zone
  double slope_um_per_m = 0.0;   // least-squares line, after alignment
};

struct BoreResult {
  std::string feature;
  double circularity_um = 0.0;     // about the least-squares circle
  double diameter_error_um = 0.0;  // least-squares diameter minus nominal
  double position_x_um = 0.0;      // least-squares centre minus nominal, after alignment
  double position_y_um = 0.0;
};

struct Result {
  std::vector<FaceResult> faces;
  std::vector<BoreResult> bores;
  // Squareness of the faces, "positive when the angle exceeds 90 deg" between the +X and +Y
  // directions of an X face and a Y face (least-squares lines); one per corner present.
  std::vector<std::pair<std::string, double>> squareness_um_per_m;
  // Parallelism of the opposite faces: the difference of their least-squares slopes.
  std::vector<std::pair<std::string, double>> parallelism_um_per_m;
  bool aligned = false;  // positions are relative to the centre bore and face-Y (both present)
};

// The profiles the model predicts: each point of a face or bore is cut by the tool's edge at
// the tool radius; its deviation is the model's volumetric error (exact model) at the commanded
// tool-centre position, with the tool offset extended by the edge's lateral offset, projected
// on the surface normal. Throws InputError for a bad layout or setup or where the model cannot
// be evaluated.
std::vector<Profile> predict_profiles(const kinematics::Machine& m, const Layout& l,
                                      const Cutting& s);

// The profiles of CMM points (part frame, mm): assigned to the named features; throws
// InputError for an unknown feature name or a feature with too few points (faces 2, bores 3).
std::vector<Profile> measured_profiles(const Layout& l, std::span<const Point> points);

// The reference fits: minimum-zone straightness and least-squares lines of the faces,
// least-squares circles of the bores; alignment (when face-Y and bore0 are present) turns the
// part so face-Y runs along X and moves the origin to the centre of bore0.
Result evaluate(const Layout& l, std::span<const Profile> profiles);

void validate(const Layout& l);

}  // namespace cal::testpiece
