#include "cal/analysis/iso230_2.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "cal/analysis/error.hpp"

namespace {

using cal::iso230_2::Direction;
using cal::iso230_2::evaluate;
using cal::iso230_2::Measurement;
using cal::iso230_2::Standard;

void add(std::vector<Measurement>& d, double target, Direction dir, std::vector<double> xs) {
  int run = 1;
  for (double x : xs) d.push_back({target, run++, dir, x});
}

// A small data set with easy numbers, where up and down differ so that B, R and E are each
// non-trivial. Three targets, three runs each way (deviations in um):
//   target   0: up 1 2 3  (x̄↑ 2, s↑ 1)   down -2 -1 0 (x̄↓ -1, s↓ 1)   B 3, x̄ 0.5
//   target 100: up 4 4 4  (x̄↑ 4, s↑ 0)   down 1 3 5   (x̄↓ 3,  s↓ 2)   B 1, x̄ 3.5
//   target 200: up 0 2 4  (x̄↑ 2, s↑ 2)   down -3 -3 -3 (x̄↓ -3, s↓ 0)  B 5, x̄ -0.5
std::vector<Measurement> hand_data() {
  std::vector<Measurement> d;
  add(d, 0, Direction::up, {1, 2, 3});
  add(d, 0, Direction::down, {-2, -1, 0});
  add(d, 100, Direction::up, {4, 4, 4});
  add(d, 100, Direction::down, {1, 3, 5});
  add(d, 200, Direction::up, {0, 2, 4});
  add(d, 200, Direction::down, {-3, -3, -3});
  return d;
}

TEST(Iso230_2, HandCalculation2014) {
  const auto e = evaluate(hand_data(), Standard::iso230_2_2014);
  ASSERT_EQ(e.targets.size(), 3u);
  EXPECT_TRUE(e.bidirectional);
  EXPECT_EQ(e.runs, 3);
  EXPECT_EQ(e.standard.title, "ISO 230-2:2014");
  // Ri = max(2 s↑ + 2 s↓ + |Bi|; 4 s↑; 4 s↓): T0 max(7,4,4) = 7, T100 max(5,0,8) = 8,
  // T200 max(9,8,0) = 9.
  const auto& ri = e.per_target_at("R_i_bi").values_um;
  EXPECT_DOUBLE_EQ(ri[0], 7.0);
  EXPECT_DOUBLE_EQ(ri[1], 8.0);
  EXPECT_DOUBLE_EQ(ri[2], 9.0);
  EXPECT_DOUBLE_EQ(e.per_target_at("B_i").values_um[2], 5.0);
  EXPECT_DOUBLE_EQ(e.per_target_at("mean_bi").values_um[1], 3.5);
  EXPECT_DOUBLE_EQ(e.at("B").value_um, 5.0);       // max |Bi|
  EXPECT_DOUBLE_EQ(e.at("B_mean").value_um, 3.0);  // (3 + 1 + 5) / 3
  EXPECT_DOUBLE_EQ(e.at("R_up").value_um, 8.0);    // 4 x 2
  EXPECT_DOUBLE_EQ(e.at("R_down").value_um, 8.0);
  EXPECT_DOUBLE_EQ(e.at("R_bi").value_um, 9.0);
  EXPECT_DOUBLE_EQ(e.at("E_up").value_um, 2.0);    // 4 - 2
  EXPECT_DOUBLE_EQ(e.at("E_down").value_um, 6.0);  // 3 - (-3)
  EXPECT_DOUBLE_EQ(e.at("E_bi").value_um, 7.0);    // 4 - (-3)
  EXPECT_DOUBLE_EQ(e.at("M").value_um, 4.0);       // 3.5 - (-0.5)
  // A↑ = max(2+2, 4+0, 2+4) - min(2-2, 4-0, 2-4) = 6 - (-2) = 8
  EXPECT_DOUBLE_EQ(e.at("A_up").value_um, 8.0);
  // A↓ = max(-1+2, 3+4, -3) - min(-1-2, 3-4, -3) = 7 - (-3) = 10
  EXPECT_DOUBLE_EQ(e.at("A_down").value_um, 10.0);
  EXPECT_DOUBLE_EQ(e.at("A_bi").value_um, 10.0);  // max(6, 7) - min(-2, -3)
  EXPECT_FALSE(e.warnings.empty());  // 3 runs and 3 targets are below the ISO minimum of 5
}

TEST(Iso230_2, Editions1997And2006AndNationalAdoptionsMatch2014) {
  const auto ref = evaluate(hand_data(), Standard::iso230_2_2014);
  for (auto s : {Standard::iso230_2_2006, Standard::iso230_2_1997, Standard::jis_b6190_2_2008,
                 Standard::gbt_17421_2_2016, Standard::gbt_17421_2_2000}) {
    const auto e = evaluate(hand_data(), s);
    ASSERT_EQ(e.axis.size(), ref.axis.size()) << e.standard.title;
    for (std::size_t k = 0; k < ref.axis.size(); ++k) {
      EXPECT_EQ(e.axis[k].key, ref.axis[k].key);
      EXPECT_DOUBLE_EQ(e.axis[k].value_um, ref.axis[k].value_um) << e.standard.title;
    }
  }
}

TEST(Iso230_2, Edition1988UsesThreeSigma) {
  const auto e = evaluate(hand_data(), Standard::iso230_2_1988);
  // Ri↑ = 6 s: 6, 0, 12; Ri = max(3 s↑ + 3 s↓ + |Bi|; 6 s↑; 6 s↓) = 9, 12, 12.
  EXPECT_DOUBLE_EQ(e.at("R_up").value_um, 12.0);
  EXPECT_DOUBLE_EQ(e.at("R_bi").value_um, 12.0);
  EXPECT_DOUBLE_EQ(e.per_target_at("R_i_bi").values_um[0], 9.0);
  // A↑ = max(2+3, 4, 2+6) - min(2-3, 4, 2-6) = 8 + 4 = 12
  EXPECT_DOUBLE_EQ(e.at("A_up").value_um, 12.0);
  // A↓ = max(-1+3, 3+6, -3) - min(-1-3, 3-6, -3) = 9 + 4 = 13;  A = max(8, 9) - min(-4, -4)
  EXPECT_DOUBLE_EQ(e.at("A_down").value_um, 13.0);
  EXPECT_DOUBLE_EQ(e.at("A_bi").value_um, 13.0);
  EXPECT_DOUBLE_EQ(e.at("B").value_um, 5.0);
  EXPECT_THROW(e.at("E_bi"), std::out_of_range);  // E and M came with the 1997 edition
}

TEST(Iso230_2, Vdi3441HandCalculation) {
  const auto e = evaluate(hand_data(), Standard::vdi_3441_1977);
  // Uj = 3, 1, 5; Psj = 6 (s↑ + s↓)/2 = 6, 6, 6; x̄j = 0.5, 3.5, -0.5
  // upper: 0.5 + 4.5 = 5, 3.5 + 3.5 = 7, -0.5 + 5.5 = 5 -> 7
  // lower: 0.5 - 4.5 = -4, 3.5 - 3.5 = 0, -0.5 - 5.5 = -6 -> -6;  P = 13
  EXPECT_DOUBLE_EQ(e.at("P").value_um, 13.0);
  EXPECT_DOUBLE_EQ(e.at("Pa").value_um, 4.0);
  EXPECT_DOUBLE_EQ(e.at("Ps_max").value_um, 6.0);
  EXPECT_DOUBLE_EQ(e.at("Ps_mean").value_um, 6.0);
  EXPECT_DOUBLE_EQ(e.at("U_max").value_um, 5.0);
  EXPECT_DOUBLE_EQ(e.at("U_mean").value_um, 3.0);
  EXPECT_EQ(e.standard.title, "VDI/DGQ 3441:1977");
}

// Published example: paulscherrerinstitute/ecmccfg, examples/test/fat_sat/report.md
// (commit 072a917e), 5 targets x 5 runs, reference positions in mm; deviation = ref - target.
// Expected per-target values and B, B̄, R↑, R↓, E↑, E↓, M, A↑, A↓, A are the report's. Its
// bidirectional E (2.46e-5 mm) and R (6.29e-5 mm) are wrong in that tool (E compares the
// wrong minima; R takes max(R↑, R↓) though its own R(5) is 6.882e-5); the values used here
// for E and R were recomputed independently with Python's statistics module.
TEST(Iso230_2, EcmcPublishedExample) {
  const double targets[5] = {-10.0, -4.88, 0.24, 5.36, 10.48};
  const double fwd[5][5] = {{-10.00008102, -10.00010202, -10.00008702, -10.00009202, -10.00010002},
                            {-4.88008702, -4.88009702, -4.88009702, -4.88009502, -4.88008202},
                            {0.23992798, 0.23990998, 0.23991198, 0.23991298, 0.23991298},
                            {5.35989798, 5.35991398, 5.35991398, 5.35990698, 5.35992198},
                            {10.47989998, 10.47988798, 10.47987098, 10.47989098, 10.47990298}};
  const double bwd[5][5] = {{-10.00009902, -10.00009402, -10.00008202, -10.00009102, -10.00009402},
                            {-4.88010302, -4.88010402, -4.88009502, -4.88011102, -4.88009302},
                            {0.23991398, 0.23989798, 0.23990898, 0.23992398, 0.23990098},
                            {5.35992798, 5.35990798, 5.35990498, 5.35989698, 5.35991898},
                            {10.47989598, 10.47987398, 10.47986998, 10.47985898, 10.47989298}};
  std::vector<Measurement> d;
  for (int i = 0; i < 5; ++i) {
    for (int j = 0; j < 5; ++j) {
      d.push_back({targets[i], j + 1, Direction::up, (fwd[i][j] - targets[i]) * 1000.0});
      d.push_back({targets[i], j + 1, Direction::down, (bwd[i][j] - targets[i]) * 1000.0});
    }
  }
  const auto e = evaluate(d, Standard::iso230_2_2014);
  EXPECT_TRUE(e.warnings.empty());
  // Report values in mm, printed to 3-4 significant digits: compare to 0.1 % (plus 1e-6 um).
  auto near = [](double got_um, double expected_mm) {
    EXPECT_NEAR(got_um, expected_mm * 1000.0, std::abs(expected_mm) * 1000.0 * 1e-3 + 1e-6);
  };
  const double s_fwd[5] = {8.79e-06, 6.77e-06, 7.26e-06, 9e-06, 1.258e-05};
  const double s_bwd[5] = {6.28e-06, 7.29e-06, 1.043e-05, 1.218e-05, 1.573e-05};
  const double r_i[5] = {3.517e-05, 3.772e-05, 4.17e-05, 4.871e-05, 6.882e-05};
  const double b_i[5] = {-4e-07, 9.6e-06, 6e-06, -4e-07, 1.22e-05};
  for (int i = 0; i < 5; ++i) {
    near(e.targets[i].s_up_um, s_fwd[i]);
    near(e.targets[i].s_down_um, s_bwd[i]);
    near(e.targets[i].reversal_um, b_i[i]);
    near(e.per_target_at("R_i_bi").values_um[i], r_i[i]);
  }
  near(e.targets[4].mean_up_um, -0.00010942);
  near(e.targets[1].mean_down_um, -0.00010122);
  near(e.at("B").value_um, 1.22e-05);
  near(e.at("B_mean").value_um, 5.4e-06);
  near(e.at("R_up").value_um, 5.033e-05);
  near(e.at("R_down").value_um, 6.29e-05);
  near(e.at("R_bi").value_um, 6.8815e-05);  // recomputed, see above
  near(e.at("E_up").value_um, 2.46e-05);
  near(e.at("E_down").value_um, 3.3e-05);
  near(e.at("E_bi").value_um, 3.68e-05);  // recomputed, see above
  near(e.at("M").value_um, 2.77e-05);
  near(e.at("A_up").value_um, 6.428e-05);
  near(e.at("A_down").value_um, 8.881e-05);
  near(e.at("A_bi").value_um, 8.881e-05);
}

TEST(Iso230_2, UnidirectionalTestHasOnlyUpResults) {
  std::vector<Measurement> d;
  add(d, 0, Direction::up, {1, 2, 3});
  add(d, 50, Direction::up, {5, 5, 8});  // mean 6, s = sqrt(3)
  const auto e = evaluate(d, Standard::iso230_2_2014);
  EXPECT_FALSE(e.bidirectional);
  EXPECT_DOUBLE_EQ(e.at("E_up").value_um, 4.0);
  EXPECT_NEAR(e.at("R_up").value_um, 4 * std::sqrt(3.0), 1e-12);
  EXPECT_THROW(e.at("B"), std::out_of_range);
  EXPECT_THROW(evaluate(d, Standard::vdi_3441_1977), cal::InputError);
}

TEST(Iso230_2, TargetsMatchedDespiteRoundingAndOrder) {
  auto d = hand_data();
  std::reverse(d.begin(), d.end());
  d[0].target_mm += 1e-9;
  const auto e = evaluate(d, Standard::iso230_2_2014);
  EXPECT_EQ(e.targets.size(), 3u);
  EXPECT_NEAR(e.targets[0].target_mm, 0.0, 1e-6);
  EXPECT_DOUBLE_EQ(e.at("R_bi").value_um, 9.0);
}

// Asserts that evaluating throws InputError whose message contains `needle`.
void expect_error(const std::vector<Measurement>& d, const std::string& needle) {
  try {
    evaluate(d, Standard::iso230_2_2014);
    ADD_FAILURE() << "no error for: " << needle;
  } catch (const cal::InputError& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(Iso230_2, BadInputsGiveClearErrors) {
  expect_error({}, "no measurements");

  std::vector<Measurement> one_run;
  add(one_run, 0, Direction::up, {1});
  add(one_run, 0, Direction::down, {1});
  expect_error(one_run, "target 0 mm has 1 run(s) in direction up");

  auto missing_direction = hand_data();
  std::erase_if(missing_direction, [](const Measurement& m) {
    return m.target_mm == 100 && m.direction == Direction::down;
  });
  expect_error(missing_direction, "target 100 mm has 0 run(s) in direction down");

  auto nan = hand_data();
  nan[4].deviation_um = std::numeric_limits<double>::quiet_NaN();
  expect_error(nan, "measurement 5");

  auto twice = hand_data();
  twice.push_back(twice.front());
  expect_error(twice, "measured twice");

  auto bad_run = hand_data();
  bad_run[0].run = 0;
  expect_error(bad_run, "run = 0");

  EXPECT_THROW(cal::iso230_2::standard_from_string("iso9999"), cal::InputError);
  EXPECT_EQ(cal::iso230_2::standard_from_string("iso230-2"), Standard::iso230_2_2014);
  EXPECT_EQ(cal::iso230_2::standard_from_string("vdi3441"), Standard::vdi_3441_1977);
}

// An axis of 3000 mm measured once in each direction (ISO 230-2:2014, 6.2), targets every
// 750 mm: up 0, 2, 5, 3, 1 um; down 2, 3, 6, 5, 2 um. By hand: B_i = up - down = -2, -1, -1,
// -2, -1: B = 2, B mean = -1.4; E up = 5 - 0 = 5, E down = 6 - 2 = 4, E = 6 - 0 = 6; mean
// bidirectional 1, 2.5, 5.5, 4, 1.5: M = 4.5. No s, no repeatability, no accuracy A.
TEST(Iso230_2, LongAxisWithOneRunPerDirection) {
  const double up[] = {0, 2, 5, 3, 1}, down[] = {2, 3, 6, 5, 2};
  std::vector<Measurement> data;
  for (int i = 0; i < 5; ++i) {
    data.push_back({750.0 * i, 1, Direction::up, up[i]});
    data.push_back({750.0 * i, 1, Direction::down, down[i]});
  }
  const auto e = evaluate(data, Standard::iso230_2_2014);
  EXPECT_TRUE(e.single_run_long_axis);
  EXPECT_EQ(e.runs, 1);
  EXPECT_DOUBLE_EQ(e.at("B").value_um, 2.0);
  EXPECT_DOUBLE_EQ(e.at("B_mean").value_um, -1.4);
  EXPECT_DOUBLE_EQ(e.at("E_up").value_um, 5.0);
  EXPECT_DOUBLE_EQ(e.at("E_down").value_um, 4.0);
  EXPECT_DOUBLE_EQ(e.at("E_bi").value_um, 6.0);
  EXPECT_DOUBLE_EQ(e.at("M").value_um, 4.5);
  for (const char* key : {"R_up", "R_down", "R_bi", "A_up", "A_down", "A_bi"})
    EXPECT_THROW(e.at(key), std::out_of_range) << key;
  EXPECT_THROW(e.per_target_at("s_up"), std::out_of_range);
  ASSERT_EQ(e.notes.size(), 1u);
  EXPECT_TRUE(e.warnings.empty());
  // The rule is ISO 230-2:2014's: other standards still need two runs, and so does a short axis.
  EXPECT_THROW(evaluate(data, Standard::vdi_3441_1977), cal::InputError);
  EXPECT_THROW(evaluate(data, Standard::iso230_2_2006), cal::InputError);
  std::vector<Measurement> short_axis;
  for (const auto& m : data)
    short_axis.push_back({m.target_mm / 2, m.run, m.direction, m.deviation_um});
  EXPECT_THROW(evaluate(short_axis, Standard::iso230_2_2014), cal::InputError);
}

}  // namespace
