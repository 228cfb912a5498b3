// The command-line parser: bad input is refused with a message naming the option.
#include <gtest/gtest.h>

#include "model/base/error.hpp"
#include "tool/cli.hpp"

TEST(Cli, ParsesOptionsFlagsAndPositionals) {
  cli::Parser p("ranging x", "test");
  p.option("--n", "N", "a number", "3");
  p.flag("--json", "json");
  p.positional("FILE", "a file");
  ASSERT_TRUE(p.parse({"a.yaml", "--json", "--n=7"}));
  EXPECT_TRUE(p.has("--json"));
  EXPECT_EQ(p.integer("--n", 0, 0, 10), 7);
  EXPECT_EQ(p.positionals().at(0), "a.yaml");
}

TEST(Cli, DefaultsApply) {
  cli::Parser p("ranging x", "test");
  p.option("--f", "HZ", "a frequency", "200000");
  ASSERT_TRUE(p.parse({}));
  EXPECT_DOUBLE_EQ(p.number("--f", 0, 0, 1e9), 200000.0);
  EXPECT_FALSE(p.has("--f"));
}

TEST(Cli, RejectsUnknownMissingAndOutOfRange) {
  {
    cli::Parser p("ranging x", "test");
    EXPECT_THROW(p.parse({"--bogus"}), ranging::InputError);
  }
  {
    cli::Parser p("ranging x", "test");
    p.option("--n", "N", "n");
    EXPECT_THROW(p.parse({"--n"}), ranging::InputError);
  }
  {
    cli::Parser p("ranging x", "test");
    p.option("--n", "N", "n");
    ASSERT_TRUE(p.parse({"--n", "65"}));
    try {
      p.integer("--n", 0, 1, 64);
      FAIL() << "no throw";
    } catch (const ranging::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("--n"), std::string::npos);
      EXPECT_NE(std::string(e.what()).find("[1, 64]"), std::string::npos);
    }
  }
  {
    cli::Parser p("ranging x", "test");
    p.option("--x", "X", "x");
    ASSERT_TRUE(p.parse({"--x", "nan"}));
    EXPECT_THROW(p.number("--x", 0, -1, 1), ranging::InputError);
  }
  {
    cli::Parser p("ranging x", "test");
    p.option("--x", "X", "x");
    ASSERT_TRUE(p.parse({"--x", "12abc"}));
    EXPECT_THROW(p.number("--x", 0, -100, 100), ranging::InputError);
  }
}
