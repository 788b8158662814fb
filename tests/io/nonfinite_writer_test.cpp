// The final guard of "no NaN or Inf leaves dynid" (issue 10): the CSV and JSON writers refuse a
// non-finite number, naming it, before anything is written; JSON text is valid UTF-8 even when a
// name from the input is not. Oracle: the values are placed by hand.

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "dynid/io/csv_writer.hpp"
#include "dynid/io/json_writer.hpp"
#include "support/error_of.hpp"

namespace dynid {
namespace {

namespace fs = std::filesystem;

std::string fresh(const std::string& name) {
  const std::string path = ::testing::TempDir() + "/nonfinite_" + name;
  fs::remove(path);
  return path;
}

TEST(NonFiniteWriters, CsvRefusesNanAndInfNamingColumnAndRow) {
  const std::string path = fresh("out.csv");
  Eigen::MatrixXd data = Eigen::MatrixXd::Ones(3, 2);
  data(2, 1) = std::numeric_limits<double>::infinity();
  std::string e = testing::error_of([&] { write_csv(path, {"t", "tau1"}, data); });
  EXPECT_NE(e.find("non-finite value of tau1 in data row 3"), std::string::npos) << e;
  EXPECT_FALSE(fs::exists(path));
  data(2, 1) = 1.0;
  data(0, 0) = NAN;
  e = testing::error_of([&] { format_csv({"t", "tau1"}, data); });
  EXPECT_NE(e.find("non-finite value of t in data row 1"), std::string::npos) << e;
}

TEST(NonFiniteWriters, JsonRefusesRawNonFiniteNumbersButKeepsDeclaredNulls) {
  const std::string path = fresh("out.json");
  nlohmann::json j = {{"parameters", {{{"name", "ZZ1R"}, {"value", 1.0}}, {{"value", NAN}}}}};
  const std::string e = testing::error_of([&] { write_json(path, j); });
  EXPECT_NE(e.find("'parameters[1].value'"), std::string::npos) << e;
  EXPECT_FALSE(fs::exists(path));
  j["parameters"][1]["value"] = json_number(NAN);  // an undefined quantity, declared as such
  write_json(path, j);
  std::ifstream in(path);
  EXPECT_TRUE(nlohmann::json::parse(in)["parameters"][1]["value"].is_null());
}

TEST(NonFiniteWriters, JsonReplacesInvalidUtf8InsteadOfThrowing) {
  const std::string path = fresh("utf8.json");
  write_json(path, {{"robot", "arm\xff\xfe"}, {"data", "run\xc3.csv"}});
  std::ifstream in(path);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["robot"], "arm\xEF\xBF\xBD\xEF\xBF\xBD");
  EXPECT_EQ(j["data"], "run\xEF\xBF\xBD.csv");
}

}  // namespace
}  // namespace dynid
