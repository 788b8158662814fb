#include "dynid/io/csv_writer.hpp"

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>

#include <gtest/gtest.h>

#include "dynid/io/atomic_file.hpp"
#include "dynid/io/csv_reader.hpp"
#include "dynid/io/json_writer.hpp"
#include "io/io_test_support.hpp"

namespace dynid {
namespace {

using test::error_of;
using test::TempDir;

bool same_bits(double a, double b) {
  return std::memcmp(&a, &b, sizeof(double)) == 0;
}

TEST(CsvWriter, RoundTripIsBitExact) {
  TempDir dir;
  std::mt19937_64 rng(20240611);
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-300, 300);
  Eigen::MatrixXd data(500, 4);
  for (Eigen::Index i = 0; i < data.rows(); ++i) {
    for (Eigen::Index c = 0; c < data.cols(); ++c) {
      data(i, c) = std::ldexp(mantissa(rng), exponent(rng) / 4) * (c == 3 ? 1e-300 : 1.0);
    }
  }
  data(0, 0) = -0.0;
  data(0, 1) = std::numeric_limits<double>::denorm_min();
  data(0, 2) = std::numeric_limits<double>::max();
  data(0, 3) = 0.1;
  const std::string path = dir.file("out.csv");
  write_csv(path, {"t", "q1", "q2", "tau1"}, data);
  const CsvTable back = read_csv(path);
  EXPECT_EQ(back.columns, (std::vector<std::string>{"t", "q1", "q2", "tau1"}));
  ASSERT_EQ(back.rows(), data.rows());
  ASSERT_EQ(back.data.cols(), data.cols());
  for (Eigen::Index i = 0; i < data.rows(); ++i) {
    for (Eigen::Index c = 0; c < data.cols(); ++c) {
      ASSERT_TRUE(same_bits(back.data(i, c), data(i, c)))
          << i << "," << c << ": " << back.data(i, c) << " vs " << data(i, c);
    }
  }
  EXPECT_EQ(dir.entries(), 1);  // no temporary file left
}

TEST(CsvWriter, FormatMatchesHandWrittenText) {
  Eigen::MatrixXd data(2, 2);
  data << 0.5, -2, 1e-20, 3;
  EXPECT_EQ(format_csv({"a", "b"}, data), "a,b\n0.5,-2\n1e-20,3\n");
  EXPECT_HAS(error_of([&] { format_csv({"a"}, data); }), "1 column names for 2 data columns");
  EXPECT_HAS(error_of([&] { format_csv({"a", "b,c"}, data); }), "column name 'b,c'");
}

TEST(AtomicFile, FailureLeavesNothingAndKeepsOldContent) {
  TempDir dir;
  const std::string path = dir.file("result.json");
  EXPECT_THROW(write_file_atomic(path,
                                 [](std::ostream& out) {
                                   out << "half";
                                   throw std::runtime_error("boom");
                                 }),
               std::runtime_error);
  EXPECT_EQ(dir.entries(), 0);

  write_text_atomic(path, "old\n");
  EXPECT_THROW(write_file_atomic(path,
                                 [](std::ostream& out) {
                                   out << "new";
                                   throw Error("bad");
                                 }),
               Error);
  EXPECT_EQ(dir.entries(), 1);
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  EXPECT_EQ(s.str(), "old\n");
}

TEST(AtomicFile, MissingDirectoryIsAnError) {
  TempDir dir;
  const std::string m = error_of([&] { write_text_atomic(dir.file("no/such/x.csv"), "x"); });
  EXPECT_HAS(m, "x.csv: cannot write");
  EXPECT_HAS(m, "no/such' exists and is writable");
  EXPECT_EQ(dir.entries(), 0);
}

TEST(JsonWriter, WritesParsableJsonWithNullForNonFinite) {
  TempDir dir;
  nlohmann::json j;
  j["a"] = 1.25;
  j["lim"] = json_number(std::numeric_limits<double>::infinity());
  j["x"] = json_number(-2.0);
  write_json(dir.file("r.json"), j);
  std::ifstream in(dir.file("r.json"));
  const nlohmann::json back = nlohmann::json::parse(in);
  EXPECT_EQ(back["a"].get<double>(), 1.25);
  EXPECT_TRUE(back["lim"].is_null());
  EXPECT_EQ(back["x"].get<double>(), -2.0);
  EXPECT_EQ(dir.entries(), 1);
}

}  // namespace
}  // namespace dynid
