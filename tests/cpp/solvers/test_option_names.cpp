// The names users write for the solvers' methods and stopping criteria (core/enum_names.hpp):
// every value's name reads back as that value, and an unknown name is refused with the value
// and every accepted name.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "solvers/static_options.hpp"
#include "problem/stopping.hpp"

using namespace snede;

TEST(OptionNames, EveryMethodAndCriterionReadsBackFromItsName) {
  for (const auto& [method, name] : static_method_names) {
    EXPECT_EQ(static_method_name(method), name);
    EXPECT_EQ(static_method(std::string(name)), method);
  }
  for (const auto& [criterion, name] : stopping_criterion_names) {
    EXPECT_EQ(criterion_name(criterion), name);
    EXPECT_EQ(stopping_criterion(std::string(name)), criterion);
  }
  EXPECT_EQ(static_method("ncg"), StaticMethod::nonlinear_cg);
  EXPECT_EQ(criterion_name(StoppingCriterion::with_reactions), "6.9");
}

TEST(OptionNames, AnUnknownNameIsRefusedWithEveryAcceptedName) {
  try {
    static_method("gmres");
    FAIL() << "gmres was accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_STREQ(error.what(), "method must be 'cg', 'ncg' or 'newton', got 'gmres'");
  }
  EXPECT_THROW(stopping_criterion("6.7"), std::invalid_argument);
}
