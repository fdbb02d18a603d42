// The CSV field helpers shared by the captured-motion reader and the
// recording readers of the problems.
#include <cmath>

#include <gtest/gtest.h>

#include "diffpd/csv_fields.h"

namespace diffpd {
namespace {

TEST(CsvFieldsTest, TrimRemovesBlanksOnBothSidesOnly) {
  EXPECT_EQ(TrimCsvField(" \t a b \r\n"), "a b");
  EXPECT_EQ(TrimCsvField(" \t\r\n"), "");
  EXPECT_EQ(TrimCsvField("x"), "x");
}

TEST(CsvFieldsTest, SplitKeepsEmptyFieldsAndATrailingOne) {
  EXPECT_EQ(SplitCsvLine(" 1 , a b,,x "), (std::vector<std::string>{"1", "a b", "", "x"}));
  EXPECT_EQ(SplitCsvLine("a,"), (std::vector<std::string>{"a", ""}));
  EXPECT_EQ(SplitCsvLine(",a"), (std::vector<std::string>{"", "a"}));
  EXPECT_TRUE(SplitCsvLine("").empty());
  EXPECT_EQ(SplitCsvLine("0.5,1\r"), (std::vector<std::string>{"0.5", "1"}));
}

TEST(CsvFieldsTest, ANumberMustBeTheWholeField) {
  double v = 0;
  EXPECT_TRUE(ParseCsvNumber("-1.5e3", &v));
  EXPECT_EQ(v, -1500.0);
  EXPECT_FALSE(ParseCsvNumber("", &v));
  EXPECT_FALSE(ParseCsvNumber("2x", &v));
  EXPECT_FALSE(ParseCsvNumber("1 2", &v));
  EXPECT_FALSE(ParseCsvNumber("M1 x", &v));
  EXPECT_TRUE(ParseCsvNumber("nan", &v));  // accepted here; callers check finiteness
  EXPECT_TRUE(std::isnan(v));
}

}  // namespace
}  // namespace diffpd
