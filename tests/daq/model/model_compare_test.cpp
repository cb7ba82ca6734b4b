// daq model compare (model/model_compare.hpp) against hand calculations.
#include "model/model_compare.hpp"

#include <gtest/gtest.h>

#include "cal/analysis/error.hpp"
#include "sim_volumetric.hpp"

namespace {

namespace kin = cal::kinematics;
namespace mdl = cal::daq::model;

const mdl::ComponentDifference& entry(const mdl::Comparison& c, std::string_view name) {
  for (const auto& d : c.components)
    if (d.name == name) return d;
  throw std::runtime_error("no entry " + std::string(name));
}

TEST(ModelCompare, AModelAgainstItselfDiffersByNothing) {
  const auto truth = daq::volumetric_truth_model(kin::Topology::yfxz);
  const auto c = mdl::compare(truth, truth, {5, 5, 5});
  ASSERT_EQ(c.components.size(), 21u);
  for (const auto& d : c.components) EXPECT_EQ(d.max_abs, 0.0) << d.name;
  EXPECT_EQ(c.volumetric_max_um, 0.0);
  EXPECT_EQ(c.range_mm[1][1], 400.0);  // the simulated travel, Y 0 .. 400 mm
}

// E_C0Y 10 urad larger: every translation and angle the same, the squareness 10 urad apart; the
// x error of Y travel is -E_C0Y y (docs/kinematics.md), so at y = 400 mm the tool is 10e-6 x
// 400 mm = 4.000 um further off in x, the largest over the volume.
TEST(ModelCompare, ASquarenessChangeIsItsAngleTimesTheTravel) {
  const auto truth = daq::volumetric_truth_model(kin::Topology::yfxz);
  auto other = truth;
  other.machine.squareness.c0y_urad += 10.0;
  const auto c = mdl::compare(truth, other, {3, 3, 3});
  EXPECT_NEAR(entry(c, "E_C0Y").max_abs, 10.0, 1e-12);
  EXPECT_EQ(entry(c, "E_B0Z").max_abs, 0.0);
  EXPECT_EQ(entry(c, "E_YX").max_abs, 0.0);
  EXPECT_NEAR(c.volumetric_max_um, 4.0, 1e-3);
  EXPECT_EQ(c.volumetric_at_mm[1], 400.0);
}

// A table that differs by 0.5 um at its point 200 mm, linear in between: the largest difference
// is there, found because every table point is compared (not only the even steps).
TEST(ModelCompare, ATableIsComparedAtEachOfItsPoints) {
  auto a = daq::volumetric_truth_model(kin::Topology::yfxz);
  const std::vector<double> q{0, 123.4, 200, 300, 400}, zero(5, 0.0), bump{0, 0, 0.5, 0, 0};
  kin::component(a.machine, kin::Component::E_XY) = kin::ErrorFunction::table(q, zero);
  auto b = a;
  kin::component(b.machine, kin::Component::E_XY) = kin::ErrorFunction::table(q, bump);
  const auto c = mdl::compare(a, b, {2, 2, 2}, 2);  // even steps only at 0 and 400 mm
  EXPECT_NEAR(entry(c, "E_XY").max_abs, 0.5, 1e-12);
  EXPECT_EQ(entry(c, "E_XY").at_mm, 200.0);
}

TEST(ModelCompare, ModelsWithNoCommonTravelAreRefusedNamingTheAxis) {
  auto a = daq::volumetric_truth_model(kin::Topology::yfxz);
  auto b = a;
  (*b.travel_mm)[2] = {400.0, 500.0};  // Z 400 .. 500 against 0 .. 300
  try {
    mdl::compare(a, b, {2, 2, 2});
    FAIL() << "no error";
  } catch (const cal::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("axis Z"), std::string::npos) << e.what();
  }
}

}  // namespace
