#pragma once

#include <exception>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "dynid/common/error.hpp"

namespace dynid::testing {

/// Runs f, expects dynid::Error, and returns its message ("" and a test failure otherwise).
template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected dynid::Error, got std::exception: " << e.what();
    return "";
  }
  ADD_FAILURE() << "no exception thrown";
  return "";
}

/// Expects f to throw dynid::Error whose message is exactly `expected`.
template <class F>
void expect_message(F&& f, const std::string& expected) {
  EXPECT_EQ(error_of(std::forward<F>(f)), expected);
}

}  // namespace dynid::testing
