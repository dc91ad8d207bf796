// The fault vocabulary (diag/faults/fault_kind.hpp): one name per kind, aliases on input only.
#include "diag/faults/fault_kind.hpp"

#include <gtest/gtest.h>

#include <set>
#include <string>

#include "diag/error.hpp"

namespace {

TEST(FaultKind, EveryKindHasOneDistinctNameThatParsesBack) {
  std::set<std::string> names;
  for (diag::FaultKind k : diag::all_fault_kinds()) {
    const std::string name(diag::to_string(k));
    EXPECT_TRUE(names.insert(name).second) << "duplicate name " << name;
    ASSERT_TRUE(diag::fault_kind_from_string(name).has_value()) << name;
    EXPECT_EQ(*diag::fault_kind_from_string(name), k) << name;
  }
  EXPECT_EQ(names.size(), 18u);
}

TEST(FaultKind, AliasesMapToTheOneKindAndAreNeverWritten) {
  EXPECT_EQ(diag::fault_kind_from_string("ball"), diag::FaultKind::kRollingElement);
  EXPECT_EQ(diag::fault_kind_from_string("root_crack"), diag::FaultKind::kCrack);
  EXPECT_EQ(diag::fault_kind_from_string("broken_tooth"), diag::FaultKind::kMissing);
  EXPECT_EQ(diag::to_string(diag::FaultKind::kRollingElement), "rolling_element");
  EXPECT_EQ(diag::to_string(diag::FaultKind::kMissing), "missing");
}

TEST(FaultKind, SitesSortTheKinds) {
  EXPECT_EQ(diag::site_of(diag::FaultKind::kChip), diag::FaultSite::kGear);
  EXPECT_EQ(diag::site_of(diag::FaultKind::kEccentricity), diag::FaultSite::kShaft);
  EXPECT_EQ(diag::site_of(diag::FaultKind::kCage), diag::FaultSite::kBearing);
  EXPECT_EQ(diag::site_of(diag::FaultKind::kNone), diag::FaultSite::kNone);
}

TEST(FaultKind, AnUnknownNameIsAnInputErrorNamingTheField) {
  EXPECT_FALSE(diag::fault_kind_from_string("Ball").has_value());  // exact, lower case
  try {
    diag::parse_fault_kind("scuffing", "scenario.json", "faults[0].type");
    FAIL() << "no error";
  } catch (const diag::InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("scenario.json: faults[0].type: 'scuffing'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("rolling_element"), std::string::npos) << msg;
  }
}

}  // namespace
