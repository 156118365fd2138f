// kfd::ScanCsvWriter: the per-scan CSV of kfd-filter (--stats) and kfd-icp-slam (scans.csv).
#include "kfd/io/scan_csv.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "test_files.h"

namespace {

// The fields of every record of an RFC 4180 CSV text (quoted fields, doubled quotes, line
// breaks inside quotes), written here from the RFC, independent of the writer.
std::vector<std::vector<std::string>> parseCsv(const std::string& text) {
    std::vector<std::vector<std::string>> rows(1);
    std::string field;
    bool quoted = false;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (quoted) {
            if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') {
                field += '"';
                ++i;
            } else if (c == '"') {
                quoted = false;
            } else {
                field += c;
            }
        } else if (c == '"') {
            quoted = true;
        } else if (c == ',') {
            rows.back().push_back(field);
            field.clear();
        } else if (c == '\n') {
            rows.back().push_back(field);
            field.clear();
            rows.emplace_back();
        } else {
            field += c;
        }
    }
    if (rows.back().empty()) rows.pop_back();
    return rows;
}

// Issue 38: a sensor label with a comma, a quote or a line break broke the rows.
TEST(ScanCsv, ASensorLabelWithACommaQuoteOrLineBreakStaysOneField) {
    kfd::test::TempDir dir("kfd_scan_csv_");
    const std::string path = dir / "s.csv";
    kfd::ScanCsvWriter w;
    w.open(path, "s.csv", kfd::StageOutputs{});
    const std::vector<std::string> labels = {"laser", "front,left", "say \"hi\"", "two\nlines",
                                             "a,\"b\"\r\nc"};
    for (std::size_t i = 0; i < labels.size(); ++i) {
        kfd::ScanRecord r;
        r.index = i;
        r.sensor = labels[i];
        r.reason = "kept";
        r.kept = true;
        w.write(r, std::nullopt);
    }
    w.close();
    std::ifstream in(path, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    const auto rows = parseCsv(text.str());
    ASSERT_EQ(rows.size(), labels.size() + 1) << text.str();
    for (std::size_t i = 0; i < labels.size(); ++i) {
        ASSERT_EQ(rows[i + 1].size(), rows[0].size()) << "row " << i << ": " << text.str();
        EXPECT_EQ(rows[i + 1][2], labels[i]);
        EXPECT_EQ(rows[i + 1][0], std::to_string(i));
        EXPECT_EQ(rows[i + 1][3], "1");
    }
    EXPECT_NE(text.str().find(",laser,"), std::string::npos);
}

}  // namespace
