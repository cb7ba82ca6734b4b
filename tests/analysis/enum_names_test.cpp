// The enum name tables (enum_names.hpp) and the names read through them: the shown name of each
// value, its accepted spellings, and the message of a name no value has.
#include "cal/analysis/enum_names.hpp"

#include <gtest/gtest.h>

#include <array>
#include <string>
#include <string_view>

#include "cal/analysis/air.hpp"
#include "cal/analysis/iso230_2_targets.hpp"
#include "cal/analysis/straightness.hpp"

namespace {

enum class Colour { red, green, blue, unnamed };
constexpr cal::EnumName<Colour> kColours[] = {
    {Colour::red, "red"}, {Colour::red, "rouge"}, {Colour::green, "green"}, {Colour::blue, "blue"}};

// The message of the InputError `f` throws ("" if it throws none).
template <class F>
std::string error_of(F f) {
  try {
    f();
  } catch (const cal::InputError& e) {
    return e.what();
  }
  return "";
}

TEST(EnumNames, TheFirstNameIsShownAndEverySpellingIsRead) {
  EXPECT_EQ(cal::name_of(kColours, Colour::red), "red");
  EXPECT_EQ(cal::name_of(kColours, Colour::blue), "blue");
  EXPECT_EQ(cal::name_of(kColours, Colour::unnamed), "?");
  EXPECT_EQ(cal::name_of(kColours, Colour::unnamed, "unknown"), "unknown");
  EXPECT_EQ(cal::value_named(kColours, "rouge"), Colour::red);
  EXPECT_EQ(cal::value_named(kColours, "green"), Colour::green);
  EXPECT_EQ(cal::value_named(kColours, "Green"), std::nullopt);
  EXPECT_EQ(cal::value_named(kColours, ""), std::nullopt);
}

TEST(EnumNames, AnUnknownNameListsTheShownNamesNotTheAliases) {
  EXPECT_EQ(cal::parse_name(kColours, "blue", "colour"), Colour::blue);
  EXPECT_EQ(error_of([] { cal::parse_name(kColours, "mauve", "colour"); }),
            "unknown colour 'mauve': expected red, green or blue");
}

// The names the analysis reads and prints, as they were when each had its own switch.
TEST(EnumNames, AnalysisNamesReadBothWays) {
  using cal::air::Equation;
  EXPECT_EQ(cal::air::to_string(Equation::shop_floor), "shop-floor");
  EXPECT_EQ(cal::air::equation_from_string("edlen-birch-downs"), Equation::edlen);
  EXPECT_EQ(cal::air::equation_from_string("nist-shop-floor"), Equation::shop_floor);
  EXPECT_EQ(cal::air::equation_from_string("ciddor"), Equation::ciddor);
  EXPECT_EQ(error_of([] { cal::air::equation_from_string("birch"); }),
            "unknown refractive-index equation 'birch': expected edlen, ciddor or shop-floor");
  using cal::iso230_2::Cycle;
  EXPECT_EQ(cal::iso230_2::to_string(Cycle::pilgrim_step), "pilgrim-step");
  EXPECT_EQ(cal::iso230_2::cycle_from_string("step"), Cycle::pilgrim_step);
  EXPECT_EQ(error_of([] { cal::iso230_2::cycle_from_string("Linear"); }),
            "unknown test cycle 'Linear': expected linear, pendulum or pilgrim-step");
  using cal::straightness::Reference;
  EXPECT_EQ(cal::straightness::to_string(Reference::minimum_zone), "minimum zone");
  EXPECT_EQ(cal::straightness::reference_from_string("end-point"), Reference::end_point);
  EXPECT_EQ(error_of([] { cal::straightness::reference_from_string("minimum zone"); }),
            "unknown reference line 'minimum zone' (expected lsq, endpoint or minzone)");
}

// The compile-time checks beside every table: the compiler's own list of an enum's values.
enum class Sparse { first = 0, fifth = 5, last = 63 };  // numbered with gaps, up to the limit
constexpr cal::EnumName<Sparse> kSparseAll[] = {
    {Sparse::first, "first"}, {Sparse::fifth, "fifth"}, {Sparse::last, "last"}};
constexpr cal::EnumName<Sparse> kSparseNoFifth[] = {{Sparse::first, "first"},
                                                    {Sparse::last, "last"}};
constexpr cal::EnumName<Colour> kColoursAll[] = {{Colour::red, "red"},
                                                 {Colour::green, "green"},
                                                 {Colour::blue, "blue"},
                                                 {Colour::unnamed, "unnamed"}};
enum class Dense { a, b, c };
constexpr std::array<std::string_view, 3> kDense{"A", "B", "C"};
constexpr std::array<std::string_view, 3> kDenseShort{"A", "B"};  // the third is empty
constexpr std::array<const char*, 3> kDenseShortPointers{"A", "B"};
constexpr std::array<std::string_view, 2> kDenseTooFew{"A", "B"};
constexpr std::array<double, 3> kDenseNumbers{1.0, -1.0, 0.0};  // a 0.0 is a value, not a gap

TEST(EnumNames, TheCompilerCountsTheValuesAndFindsOneWithoutAName) {
  static_assert(cal::enumerator_count<Colour>() == 4);  // red, green, blue, unnamed
  static_assert(cal::enumerator_count<Sparse>() == 3);
  static_assert(cal::enumerator_count<Dense>() == 3);
  static_assert(!cal::names_every_value(kColours));  // Colour::unnamed has none
  static_assert(cal::names_every_value(kColoursAll));
  static_assert(cal::names_every_value(kSparseAll));
  static_assert(!cal::names_every_value(kSparseNoFifth));
  static_assert(cal::one_per_value<Dense>(kDense));
  static_assert(cal::one_per_value<Dense>(kDenseNumbers));
  static_assert(!cal::one_per_value<Dense>(kDenseShort));
  static_assert(!cal::one_per_value<Dense>(kDenseShortPointers));
  static_assert(!cal::one_per_value<Dense>(kDenseTooFew));
  static_assert(!cal::one_per_value<Sparse>(std::array<int, 3>{1, 2, 3}));  // not 0, 1, 2
  // The same, evaluated when the test runs (a constexpr function gives the same answer).
  EXPECT_EQ(cal::enumerator_count<Colour>(), 4u);
  EXPECT_FALSE(cal::names_every_value(kColours));
  EXPECT_FALSE(cal::names_every_value(kSparseNoFifth));
  EXPECT_TRUE(cal::names_every_value(kSparseAll));
}

}  // namespace
