// Issue 28 item 4: the identify section leads with the parameter table (values with units and
// intervals, open), draws every parameter's %σ on a log axis (nothing saturates) and the intervals
// only of the parameters determined to within 20 %σ, naming the others. Each chart's data are
// checked against the result it draws, read back from the page's own data block.
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "dynid/report/html_report.hpp"

namespace dynid {
namespace {

// The JSON the page's renderer reads (<script id="dynid-data">), as html_report embedded it.
nlohmann::json page_data(const std::string& html) {
  const std::string open = "id=\"dynid-data\">";
  const auto begin = html.find(open);
  EXPECT_NE(begin, std::string::npos);
  const auto end = html.find("</script>", begin);
  return nlohmann::json::parse(html.substr(begin + open.size(), end - begin - open.size()));
}

const nlohmann::json* chart_titled(const nlohmann::json& section, const std::string& start) {
  for (const auto& c : section["charts"]) {
    if (c["title"].get<std::string>().rfind(start, 0) == 0) return &c;
  }
  return nullptr;
}

TEST(ParameterCharts, TableLeadsWithUnitsAndChartsDrawWhatTheResultHolds) {
  const nlohmann::json result = {{"rank", 3},
                                 {"condition_number", 12.0},
                                 {"confidence_level", 0.999},
                                 {"parameters",
                                  {{{"name", "ZZ1R"},
                                    {"value", 2.0},
                                    {"std", 0.04},
                                    {"relative_std_percent", 2.0},
                                    {"ci_low", 1.87},
                                    {"ci_high", 2.13},
                                    {"unit", "kg·m²"}},
                                   {{"name", "Fv1"},
                                    {"value", 0.1},
                                    {"std", 0.05},
                                    {"relative_std_percent", 50.0},
                                    {"ci_low", -0.06},
                                    {"ci_high", 0.26},
                                    {"unit", "N·m·s/rad"}},
                                   {{"name", "Fo1"},
                                    {"value", nullptr},
                                    {"std", nullptr},
                                    {"relative_std_percent", nullptr},
                                    {"ci_low", nullptr},
                                    {"ci_high", nullptr},
                                    {"unit", "N·m"}}}}};
  const nlohmann::json page = page_data(html_report({{"id.json", result}}, {}));
  ASSERT_EQ(page["sections"].size(), 1u);
  const nlohmann::json& s = page["sections"][0];
  EXPECT_EQ(s["kind"], "identify");

  const nlohmann::json& table = s["tables"][0];
  EXPECT_TRUE(table.value("open", false));
  EXPECT_EQ(table["columns"][2], "unit");
  ASSERT_EQ(table["rows"].size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(table["rows"][i][0], result["parameters"][i]["name"]);
    EXPECT_EQ(table["rows"][i][2], result["parameters"][i]["unit"]);
  }

  const nlohmann::json* sigma = chart_titled(s, "Relative standard deviation");
  ASSERT_NE(sigma, nullptr);
  EXPECT_TRUE(sigma->value("log", false));
  EXPECT_EQ((*sigma)["labels"], nlohmann::json({"ZZ1R", "Fv1", "Fo1"}));
  EXPECT_EQ((*sigma)["series"][0]["y"], nlohmann::json({2.0, 50.0, nullptr}));

  const nlohmann::json* intervals = chart_titled(s, "The 1 parameters within 20");
  ASSERT_NE(intervals, nullptr);
  EXPECT_EQ((*intervals)["labels"], nlohmann::json({"ZZ1R"}));
  // Drawn relative to |estimate|: the estimate at 1, the interval at ci / |value|.
  EXPECT_NEAR((*intervals)["value"][0].get<double>(), 1.0, 1e-12);
  EXPECT_NEAR((*intervals)["low"][0].get<double>(), 1.87 / 2.0, 1e-6);
  EXPECT_NEAR((*intervals)["high"][0].get<double>(), 2.13 / 2.0, 1e-6);

  bool named = false;
  for (const auto& f : s["facts"]) {
    if (f[0].get<std::string>().rfind("%σ ≥ 20", 0) == 0) {
      named = true;
      EXPECT_EQ(f[1], "Fv1, Fo1");
    }
  }
  EXPECT_TRUE(named);
}

}  // namespace
}  // namespace dynid
