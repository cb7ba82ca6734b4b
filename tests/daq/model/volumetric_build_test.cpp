// The test kinds' arithmetic and the model build, against hand calculations (in the comments).
#include <gtest/gtest.h>

#include <cmath>

#include "cal/analysis/error.hpp"
#include "kinds/kind.hpp"
#include "model/model_build.hpp"

namespace {

namespace kin = cal::kinematics;
namespace mdl = cal::daq::model;
using daq::kinds::Source;

cal::daq::LinearTestConfig angular(std::string axis, std::string about,
                                   std::array<double, 3> separation) {
  cal::daq::LinearTestConfig l;
  l.axis = axis;
  l.measure.kind = "angular";
  l.measure.direction = about;
  l.measure.separation_mm = separation;
  return l;
}

// Beams along +X, reflectors 100 mm apart. Pitch, separation (0, 0, 100): dr x u =
// (0,0,100) x (1,0,0) = (0, 100, 0) = +100 e_y, so E_BX = +(d_a - d_b) / 100 mm: a difference
// of 1 um is 10 urad. Yaw, separation (0, 100, 0): dr x u = (0, 0, -100), E_CX = -(d_a - d_b)
// / 100 mm = -10 urad.
TEST(TestKinds, AngularFromTwoBeamsBySeparationWithItsSign) {
  const auto& k = daq::kinds::kind("angular");
  auto pitch = k.reader(angular("X", "B", {0, 0, 100}));
  EXPECT_FALSE(pitch->add(Source::laser, 1, 5, 1e-6));  // beam a alone: no pair yet
  const auto v = pitch->add(Source::laser, 2, 5, 0.0);
  ASSERT_TRUE(v);
  EXPECT_NEAR(*v, 10.0, 1e-9);
  EXPECT_FALSE(pitch->add(Source::laser, 2, 6, 0.0));  // a beam b of another time: no pair
  auto yaw = k.reader(angular("X", "C", {0, 100, 0}));
  yaw->add(Source::laser, 1, 7, 1e-6);
  EXPECT_NEAR(*yaw->add(Source::laser, 2, 7, 0.0), -10.0, 1e-9);
  EXPECT_EQ(k.component(angular("Y", "A", {0, 0, 100})), "E_AY");
}

TEST(TestKinds, AngularSetUpThatCannotSeeTheAngleIsRefused) {
  const auto& k = daq::kinds::kind("angular");
  EXPECT_THROW(k.validate(angular("X", "B", {100, 0, 0})), cal::InputError);  // along the travel
  EXPECT_THROW(k.validate(angular("X", "C", {0, 0, 100})), cal::InputError);  // sees B, not C
  EXPECT_THROW(k.validate(angular("X", "A", {0, 100, 0})), cal::InputError);  // roll: not angular
  EXPECT_NO_THROW(k.validate(angular("Z", "A", {0, 50, 0})));
}

TEST(TestKinds, ComponentsAndReadingsOfEachKind) {
  cal::daq::LinearTestConfig l;
  l.axis = "Z";
  EXPECT_EQ(daq::kinds::kind("positioning").component(l), "E_ZZ");
  EXPECT_EQ(daq::kinds::kind("positioning").reader(l), nullptr);  // the sequencer's deviation
  l.axis = "Y";
  EXPECT_EQ(daq::kinds::kind("roll").component(l), "E_BY");
  l.measure.sign = -1;
  // A level reads 2e-6 rad mounted the other way round: -2 urad.
  EXPECT_NEAR(*daq::kinds::kind("roll").reader(l)->add(Source::probe, 0, 1, 2e-6), -2.0, 1e-12);
  l.axis = "X";
  l.measure.direction = "Y";
  l.measure.sign = 1;
  EXPECT_EQ(daq::kinds::kind("straightness").component(l), "E_YX");
  // An indicator's 1.5e-6 m is 1.5 um; the laser is not its source.
  auto s = daq::kinds::kind("straightness").reader(l);
  EXPECT_NEAR(*s->add(Source::probe, 0, 1, 1.5e-6), 1.5, 1e-12);
  EXPECT_FALSE(s->add(Source::laser, 0, 1, 1.0));
  EXPECT_THROW(daq::kinds::kind("flatness"), cal::InputError);
}

mdl::MeasuredProfile profile(const char* component, const char* kind, std::vector<double> q,
                             std::vector<double> v) {
  return {.run_id = 1, .component = component, .kind = kind, .position_mm = q, .value = v};
}

// FXYZ, a pitch E_BX = 0.01 x urad and no positioning error. Positioning measured at z0 = 200
// with the reflector 100 mm below the spindle (t_z = -100): e_x = E_XX + E_BX (z + t_z) =
// 0.01 x urad * 100 mm = 1e-3 x um: 0.5 um at 500 mm. The build removes it: E_XX = 0.
TEST(ModelBuild, AbbeTermOfTheMeasuredPitchIsRemovedFromPositioning) {
  std::vector<double> q{0, 100, 200, 300, 400, 500}, pitch, measured;
  for (double x : q) pitch.push_back(0.01 * x), measured.push_back(1e-3 * x);
  auto xx = profile("E_XX", "positioning", q, measured);
  xx.stationary_mm = {0, 0, 200};
  xx.probe_offset_mm = {0, 0, -100};
  const auto r = mdl::build({profile("E_BX", "angular", q, pitch), xx},
                            {.machine = "m", .allow_missing = true});
  for (double x : q) {
    EXPECT_NEAR(kin::component(r.model.machine, kin::Component::E_XX)(x), 0.0, 1e-12) << x;
    EXPECT_NEAR(kin::component(r.model.machine, kin::Component::E_BX)(x), 0.01 * x, 1e-12);
  }
  EXPECT_EQ(r.missing.size(), 21u - 2u);
}

// Squareness from a pair against one square turned by theta = 5 urad: the X run reads the Y
// deviation -theta x (slope -5 um/m), the Y run reads x deviation (-E_C0Y + theta) y; with
// E_C0Y = 12: slope -7 um/m. E_C0Y = -(s_YX + s_XY) = -(-5 - 7) = 12; both tables are left
// with their lines removed (zero).
TEST(ModelBuild, SquarenessFromTheSlopesOfAPairAgainstOneSquare) {
  std::vector<double> q{0, 100, 200, 300, 400}, yx, xy;
  for (double x : q) yx.push_back(-5e-3 * x + 0.7), xy.push_back(-7e-3 * x - 0.2);
  auto a = profile("E_YX", "straightness", q, yx);
  auto b = profile("E_XY", "straightness", q, xy);
  a.square = b.square = true;
  const auto r = mdl::build({a, b}, {.machine = "m", .allow_missing = true});
  EXPECT_NEAR(r.model.machine.squareness.c0y_urad, 12.0, 1e-9);
  EXPECT_TRUE(r.model.squareness[0].given);
  EXPECT_EQ(r.model.squareness[0].method, "straightness");
  for (double x : q) EXPECT_NEAR(kin::component(r.model.machine, kin::Component::E_YX)(x), 0, 1e-9);
  // Not against a square: no squareness, and said so.
  a.square = false;
  const auto r2 = mdl::build({a, b}, {.machine = "m", .allow_missing = true});
  EXPECT_FALSE(r2.model.squareness[0].given);
  EXPECT_EQ(r2.notes.size(), 1u);
}

TEST(ModelBuild, MissingComponentsAreNamedNotSilentlyZero) {
  std::vector<double> q{0, 100};
  try {
    mdl::build({profile("E_XX", "positioning", q, {0, 1})}, {.machine = "VMC"});
    FAIL() << "a partial model was built without being allowed";
  } catch (const cal::InputError& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("20 of the 21"), std::string::npos) << w;
    EXPECT_NE(w.find("E_YX"), std::string::npos) << w;
    EXPECT_NE(w.find("E_C0Y"), std::string::npos) << w;
  }
  EXPECT_THROW(mdl::build({profile("E_XX", "positioning", {0}, {0})},
                          {.machine = "VMC", .allow_missing = true}),
               cal::InputError);  // one target: no table
}

}  // namespace
