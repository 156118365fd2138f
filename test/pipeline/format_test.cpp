// kfd::format and kfd::plural (kfd/pipeline/format.h): counts printed with their noun in the right
// number.
#include "kfd/pipeline/format.h"

#include <gtest/gtest.h>

#include <string>

TEST(Plural, OneTakesTheSingularEveryOtherCountThePlural) {
    EXPECT_EQ(kfd::plural(1, "scan"), "1 scan");
    EXPECT_EQ(kfd::plural(0, "scan"), "0 scans");
    EXPECT_EQ(kfd::plural(2, "topic"), "2 topics");
    EXPECT_EQ(kfd::plural(224, "dropped scan"), "224 dropped scans");
}

TEST(Plural, AnIrregularPluralIsGivenWhole) {
    EXPECT_EQ(kfd::plural(1, "entry", "entries"), "1 entry");
    EXPECT_EQ(kfd::plural(3, "entry", "entries"), "3 entries");
    EXPECT_EQ(kfd::plural(1, "line that is", "lines that are"), "1 line that is");
    EXPECT_EQ(kfd::noun(1, "sensor"), "sensor");
    EXPECT_EQ(kfd::noun(5, "sensor"), "sensors");
}

TEST(Format, PrintsLikePrintfWithoutATruncatingBuffer) {
    EXPECT_EQ(kfd::format("%zu in, %.1f %%", static_cast<std::size_t>(3), 12.34), "3 in, 12.3 %");
    EXPECT_EQ(kfd::format("%.0f", 1e300).size(), 301u);
}
