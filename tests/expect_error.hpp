#pragma once
// Bad-input tests assert on the message: one line matching a regular expression.
#include <gtest/gtest.h>

#include <regex>
#include <string>

#include "impactdeck/common/error.hpp"

namespace impactdeck::test {

/// Expects `f()` to throw an InputError whose one-line message matches `re`.
template <class F>
void expect_input_error(F&& f, const std::string& re) {
  try {
    f();
    ADD_FAILURE() << "no InputError, expected /" << re << "/";
  } catch (const InputError& e) {
    EXPECT_TRUE(std::regex_search(std::string(e.what()), std::regex(re))) << e.what() << "\n  expected /" << re << "/";
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << "message must be one line";
  }
}

}  // namespace impactdeck::test
