// test_expressions.cpp — formulas in specs: the functions and constants the
// contract promises, natural log, constant folding, and clear errors.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "expression.hpp"

namespace hmpm::api {
namespace {

double eval_xyz(const std::string& text, Vec3 x = {0, 0, 0}) {
  std::string error;
  auto f = compile_field_of_position(text, error);
  EXPECT_TRUE(f.has_value()) << error;
  return f ? (*f)(x) : std::nan("");
}

TEST(Expressions, ContractFunctionsAndConstants) {
  EXPECT_DOUBLE_EQ(eval_xyz("pi"), std::numbers::pi);
  EXPECT_DOUBLE_EQ(eval_xyz("2^10"), 1024);
  EXPECT_DOUBLE_EQ(eval_xyz("log(exp(2))"), 2);  // natural logarithm
  EXPECT_DOUBLE_EQ(eval_xyz("sqrt(16) + abs(-3)"), 7);
  EXPECT_DOUBLE_EQ(eval_xyz("min(x, y) + max(x, z)", {1, 2, 3}), 4);
  EXPECT_NEAR(eval_xyz("sin(pi/2) + cos(0) + tan(pi/4)"), 3, 1e-15);
  EXPECT_DOUBLE_EQ(eval_xyz("x + 10*y + 100*z", {1, 2, 3}), 321);
}

TEST(Expressions, FunctionsOfTime) {
  std::string error;
  auto f = compile_field_of_time("100*min(t, 1)", error);
  ASSERT_TRUE(f) << error;
  EXPECT_DOUBLE_EQ((*f)(0.25), 25);
  EXPECT_DOUBLE_EQ((*f)(5), 100);
  // Position variables do not exist in a function of time.
  EXPECT_FALSE(compile_field_of_time("x + t", error));
  EXPECT_NE(error.find("x + t"), std::string::npos);
}

TEST(Expressions, CopiesShareOneCompiledFormula) {
  std::string error;
  auto f = compile_field_of_position("x*x", error);
  ASSERT_TRUE(f);
  FieldOfPosition copy = *f;
  f.reset();  // the copy keeps the parser and its variables alive
  EXPECT_DOUBLE_EQ(copy({3, 0, 0}), 9);
}

TEST(Expressions, ErrorsSayWhatIsWrong) {
  std::string error;
  EXPECT_FALSE(compile_field_of_position("sin(", error));
  EXPECT_NE(error.find("sin("), std::string::npos);
  EXPECT_FALSE(compile_field_of_position("foo(1)", error));
  EXPECT_NE(error.find("foo"), std::string::npos);
  EXPECT_FALSE(compile_field_of_position("t", error));
  EXPECT_FALSE(compile_field_of_position("", error));
  EXPECT_FALSE(compile_field_of_position("x = 2", error));
  EXPECT_NE(error.find("assignment"), std::string::npos);
  EXPECT_FALSE(compile_field_of_position("1, 2", error));
  EXPECT_TRUE(compile_field_of_position("x <= 2", error));
  EXPECT_FALSE(compile_field_of_position(std::string(5000, '1'), error));
}

}  // namespace
}  // namespace hmpm::api
