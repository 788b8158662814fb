#pragma once

// Checks of numeric flag values shared by every command: CLI11 parses "nan", "inf" and 1e999 into
// a double without complaint, and most physical settings are meaningless below zero.

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace dynid::cli {

/// Adds to every numeric option of every subcommand of `app` a check that its value (each value
/// of a list) is a finite number, and to the options listed in flag_checks.cpp a sign check
/// (non-negative or positive). A failed check is a usage error naming the flag. Call once, after
/// all subcommands are registered.
void check_numeric_flags(CLI::App& app);

/// A result file must come from the robot it is used with: Error "WHAT was identified on robot
/// 'FILE_ROBOT' but --robot gives 'ROBOT'; FIX" unless file_robot is empty (older files) or equal.
void require_same_robot(const std::string& file_robot, const std::string& robot,
                        const std::string& what, const std::string& fix);

/// "a b c ..." (a flag's text, e.g. --sensor-pose "x y z roll pitch yaw") → exactly `count` finite
/// numbers. Throws UsageError naming the flag, the bad word or the count, and `meaning` (what to
/// give instead).
std::vector<double> flag_numbers(const std::string& text, std::size_t count, const char* flag,
                                 const char* meaning);

}  // namespace dynid::cli
