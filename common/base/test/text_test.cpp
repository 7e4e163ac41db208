#include "rigger/base/text.hpp"

#include <limits>

#include <gtest/gtest.h>

namespace rigger {
namespace {

TEST(NumberText, ShortestReadableForm) {
  EXPECT_EQ(number_text(1.0), "1");
  EXPECT_EQ(number_text(0.1), "0.1");
  EXPECT_EQ(number_text(2.5), "2.5");
  EXPECT_EQ(number_text(1200.0), "1200");
  EXPECT_EQ(number_text(-0.02), "-0.02");
  EXPECT_EQ(number_text(3.14159265), "3.14159");
  EXPECT_EQ(number_text(std::numeric_limits<double>::quiet_NaN()), "nan");
  EXPECT_EQ(number_text(-std::numeric_limits<double>::infinity()), "-inf");
}

}  // namespace
}  // namespace rigger
