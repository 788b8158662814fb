#include "flag_checks.hpp"

#include <cmath>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "dynid/common/error.hpp"

namespace dynid::cli {
namespace {

enum class Sign { kNonNegative, kPositive };

struct SignRule {
  const char* command;  // subcommand name
  const char* flag;     // long flag name
  Sign sign;
};

// Flags whose negative (or zero) values have no meaning. "Auto" sentinels (0, or −1 for --trim)
// stay allowed: --trim is left out for that reason, and the -1e300 default of --z-min is a value.
const SignRule kSignRules[] = {
    {"identify", "--cutoff", Sign::kNonNegative},
    {"identify", "--decimate", Sign::kNonNegative},
    {"identify", "--rate", Sign::kNonNegative},
    {"identify", "--zero-velocity", Sign::kNonNegative},
    {"identify", "--coulomb-width", Sign::kNonNegative},
    {"identify", "--threads", Sign::kNonNegative},
    {"simulate", "--wrench-noise", Sign::kNonNegative},
    {"validate", "--cutoff", Sign::kNonNegative},
    {"validate", "--rate", Sign::kNonNegative},
    {"validate", "--zero-velocity", Sign::kNonNegative},
    {"payload", "--rate", Sign::kNonNegative},
    {"average", "--rate", Sign::kNonNegative},
    {"excite", "--harmonics", Sign::kPositive},
    {"excite", "--f0", Sign::kPositive},
    {"excite", "--fmax", Sign::kNonNegative},
    {"excite", "--rate", Sign::kPositive},
    {"excite", "--velocity-limit", Sign::kPositive},
    {"excite", "--acceleration-limit", Sign::kPositive},
    {"excite", "--torque-limit", Sign::kPositive},
    {"excite", "--limit-fraction", Sign::kPositive},
    {"excite", "--starts", Sign::kPositive},
    {"excite", "--max-evaluations", Sign::kPositive},
    {"excite", "--max-time", Sign::kNonNegative},
    {"simulate", "--periods", Sign::kPositive},
    {"simulate", "--position-noise", Sign::kNonNegative},
    {"simulate", "--torque-noise", Sign::kNonNegative},
    {"simulate", "--counts-per-rev", Sign::kNonNegative},
    {"simulate", "--delay", Sign::kNonNegative},
    {"demo", "--periods", Sign::kPositive},
};

// The value as a double, or NaN when it is not a number at all (CLI11 reports those itself).
double as_number(const std::string& text) {
  char* end = nullptr;
  const double x = std::strtod(text.c_str(), &end);
  return end != text.c_str() && *end == '\0' ? x : NAN;
}

bool is_numeric(const CLI::Option& option) {
  const std::string type = option.get_type_name();
  return type == "FLOAT" || type == "INT" || type == "UINT";
}

}  // namespace

void check_numeric_flags(CLI::App& app) {
  for (CLI::App* cmd : app.get_subcommands({})) {
    for (CLI::Option* option : cmd->get_options()) {
      if (!is_numeric(*option)) continue;
      const std::string flag = option->get_name();
      option->check(CLI::Validator(
          [flag](std::string& text) -> std::string {
            char* end = nullptr;
            const double x = std::strtod(text.c_str(), &end);
            if (end == text.c_str() || *end != '\0' || std::isfinite(x)) return {};
            return "'" + text + "' is not a finite number; give a plain number";
          },
          "", "finite"));
    }
  }
  for (const SignRule& rule : kSignRules) {
    CLI::App* cmd = nullptr;
    try {
      cmd = app.get_subcommand(rule.command);
    } catch (const CLI::OptionNotFound&) {
      continue;
    }
    CLI::Option* option = cmd->get_option_no_throw(rule.flag);
    if (option == nullptr) continue;
    const Sign sign = rule.sign;
    option->check(CLI::Validator(
        [sign](std::string& text) -> std::string {
          const double x = as_number(text);
          if (std::isnan(x)) return {};
          if (sign == Sign::kPositive && !(x > 0.0)) return "must be > 0, not " + text;
          if (sign == Sign::kNonNegative && x < 0.0) return "must be >= 0, not " + text;
          return {};
        },
        "", sign == Sign::kPositive ? "positive" : "non-negative"));
  }
}

std::vector<double> flag_numbers(const std::string& text, std::size_t count, const char* flag,
                                 const char* meaning) {
  std::istringstream in(text);
  std::vector<double> v;
  std::string word;
  while (in >> word) {
    try {
      std::size_t used = 0;
      v.push_back(std::stod(word, &used));
      if (used != word.size() || !std::isfinite(v.back())) throw std::invalid_argument(word);
    } catch (const std::exception&) {
      throw UsageError(std::string(flag) + " \"" + text + "\": '" + word +
                       "' is not a finite number; give " + meaning);
    }
  }
  if (v.size() != count) {
    throw UsageError(std::string(flag) + " \"" + text + "\" has " + std::to_string(v.size()) +
                     " numbers; give " + meaning);
  }
  return v;
}

void require_same_robot(const std::string& file_robot, const std::string& robot,
                        const std::string& what, const std::string& fix) {
  if (file_robot.empty() || file_robot == robot) return;
  throw Error(what + " was identified on robot '" + file_robot + "' but --robot gives '" + robot +
              "'; " + fix);
}

}  // namespace dynid::cli
