#include "dynid/io/csv_reader.hpp"

#include <gtest/gtest.h>

#include "io/io_test_support.hpp"

namespace dynid {
namespace {

using test::error_of;
using test::TempDir;

const std::string kFixtures = std::string(DYNID_SOURCE_DIR) + "/tests/data/csv/";

TEST(CsvReader, ReadsHeaderCommentsCrlfBlankLinesSpacesQuotesAndSigns) {
  const CsvTable t = read_csv(kFixtures + "valid_crlf.csv");
  const std::vector<std::string> names{"t", "q1", "q2", "dq1", "dq2", "ddq1", "ddq2", "extra"};
  EXPECT_EQ(t.columns, names);
  ASSERT_EQ(t.rows(), 3);
  ASSERT_EQ(t.data.cols(), 8);
  // Oracle: the decimal literals written in the fixture.
  EXPECT_EQ(t.data(1, 1), 1.5707963267948966);
  EXPECT_EQ(t.data(1, 2), -0.5);
  EXPECT_EQ(t.data(1, 3), 1e-3);
  EXPECT_EQ(t.data(1, 4), 250.0);
  EXPECT_EQ(t.data(2, 0), 0.2);
  EXPECT_EQ(t.data(2, 7), 9.0);
  EXPECT_EQ(t.lines, (std::vector<long>{4, 6, 7}));
}

TEST(CsvReader, LastLineWithoutNewlineIsAcceptedWhenComplete) {
  const CsvTable t = parse_csv("a,b\n1,2\n3,4", "mem");
  ASSERT_EQ(t.rows(), 2);
  EXPECT_EQ(t.data(1, 0), 3.0);
  EXPECT_EQ(t.data(1, 1), 4.0);
}

TEST(CsvReader, MissingFile) {
  const std::string m = error_of([] { read_csv("/nonexistent/dir/states.csv"); });
  EXPECT_HAS(m, "/nonexistent/dir/states.csv: cannot open");
  EXPECT_HAS(m, "check the path");
}

TEST(CsvReader, EmptyFileAndOnlyComments) {
  TempDir dir;
  EXPECT_HAS(error_of([&] { read_csv(dir.write("e.csv", "")); }), "e.csv: file is empty");
  EXPECT_HAS(error_of([&] { read_csv(dir.write("c.csv", "# only\n\n  \r\n")); }),
             "c.csv: file is empty");
  EXPECT_HAS(error_of([&] { parse_csv("t,q1\n# no data\n", "h.csv"); }),
             "h.csv: header but no data rows");
}

TEST(CsvReader, NoHeader) {
  const std::string m = error_of([] { parse_csv("# c\n0.1,2,3\n4,5,6\n", "s.csv"); });
  EXPECT_HAS(m, "s.csv:2: first line is numbers, not a header; add a header row");
}

TEST(CsvReader, DuplicateAndEmptyColumnNames) {
  EXPECT_HAS(error_of([] { parse_csv("t,q1,q1\n1,2,3\n", "d.csv"); }),
             "d.csv:1: duplicate column name 'q1'");
  EXPECT_HAS(error_of([] { parse_csv("t,q1,\n1,2,3\n", "d.csv"); }),
             "d.csv:1: header field 3 is empty");
}

TEST(CsvReader, RaggedRows) {
  EXPECT_HAS(error_of([] { parse_csv("a,b,c\n1,2,3\n1,2\n4,5,6\n", "r.csv"); }),
             "r.csv:3: row has 2 fields but the header has 3");
  EXPECT_HAS(error_of([] { parse_csv("a,b,c\n1,2,3,4\n", "r.csv"); }),
             "r.csv:2: row has 4 fields but the header has 3");
}

TEST(CsvReader, NonNumericField) {
  EXPECT_HAS(error_of([] { parse_csv("t,q1,q2\n0,1,2\n0.1,abc,2\n", "n.csv"); }),
             "n.csv:3: column 'q1' (field 2): 'abc' is not a number");
  EXPECT_HAS(error_of([] { parse_csv("t,q1,q2\n0,1.5x,2\n", "n.csv"); }),
             "n.csv:2: column 'q1' (field 2): '1.5x' is not a number");
  EXPECT_HAS(error_of([] { parse_csv("t,q1,q2\n0,,2\n", "n.csv"); }),
             "n.csv:2: column 'q1' (field 2): empty field");
  EXPECT_HAS(error_of([] { parse_csv("t,q1,q2\n0,1,2,\n", "n.csv"); }), "row has 4 fields");
}

TEST(CsvReader, NanAndInfNameRowAndColumn) {
  const std::string m = error_of([] { parse_csv("t,q1,q2\n0,1,2\n# c\n0.1,2,nan\n", "x.csv"); });
  EXPECT_HAS(m, "x.csv:4: column 'q2' (field 3) of data row 2 is NaN");
  EXPECT_HAS(error_of([] { parse_csv("t,q1\n0,-inf\n", "x.csv"); }),
             "x.csv:2: column 'q1' (field 2) of data row 1 is infinite");
  EXPECT_HAS(error_of([] { parse_csv("t,q1\n0,1e999\n", "x.csv"); }), "is infinite");
}

TEST(CsvReader, TruncatedLastLine) {
  EXPECT_HAS(error_of([] { parse_csv("a,b,c\n1,2,3\n4,5", "tr.csv"); }),
             "tr.csv:3: truncated last line (2 of 3 fields, no final newline)");
  EXPECT_HAS(error_of([] { parse_csv("a,b,c\n1,2,3\n4,5,6e", "tr.csv"); }),
             "tr.csv:3: truncated last line");
  // The same row with a newline is a ragged row, not a truncation.
  EXPECT_HAS(error_of([] { parse_csv("a,b,c\n1,2,3\n4,5\n", "tr.csv"); }), "row has 2 fields");
}

// Issue 10: a UTF-8 byte-order mark hid the `t` column (its name became "\xEF\xBB\xBFt").
TEST(CsvReader, ByteOrderMarkIsSkipped) {
  const CsvTable t = parse_csv("\xEF\xBB\xBFt,q1\n0,1\n0.1,2\n", "bom.csv");
  EXPECT_EQ(t.columns, (std::vector<std::string>{"t", "q1"}));
  ASSERT_EQ(t.rows(), 2);
  TempDir dir;
  const CsvTable f = read_csv(dir.write("bom.csv", "\xEF\xBB\xBF# comment\nt,q1\n0,1\n"));
  EXPECT_EQ(f.columns, (std::vector<std::string>{"t", "q1"}));
}

// Issue 10: CR-only line ends (classic Mac) were read as one header line.
TEST(CsvReader, CrOnlyLineEnds) {
  const CsvTable t = parse_csv("t,q1\r# c\r0,1\r0.1,2.5\r", "mac.csv");
  EXPECT_EQ(t.columns, (std::vector<std::string>{"t", "q1"}));
  ASSERT_EQ(t.rows(), 2);
  EXPECT_EQ(t.data(1, 1), 2.5);
  EXPECT_EQ(t.lines, (std::vector<long>{3, 4}));
}

// Issue 10: /dev/zero was read until memory ran out; a device is now refused before it is opened
// (issue 27 item 4: readers take regular files only).
TEST(CsvReader, SizeLimits) {
  std::string m = error_of([] { read_csv("/dev/zero"); });
  EXPECT_HAS(m, "CSV file '/dev/zero' is not a regular file (a device)");
  std::string wide = "c0";
  for (std::size_t c = 1; c <= kMaxCsvColumns; ++c) wide += ",c" + std::to_string(c);
  m = error_of([&] { parse_csv(wide + "\n", "wide.csv"); });
  EXPECT_HAS(m, "wide.csv:1: header has " + std::to_string(kMaxCsvColumns + 1) + " columns");
  TempDir dir;
  // A sparse file one byte over the in-memory limit: refused from its size, nothing is read.
  const std::string big = dir.write("big.csv", "t\n");
  std::filesystem::resize_file(big, kMaxCsvFileBytes + 1);
  m = error_of([&] { read_csv(big); });
  EXPECT_HAS(m, "larger than 256 MiB");
  EXPECT_HAS(m, "--stream");
  m = error_of([&] { read_csv(dir.path().string()); });
  EXPECT_HAS(m, "is a directory");
}

}  // namespace
}  // namespace dynid
