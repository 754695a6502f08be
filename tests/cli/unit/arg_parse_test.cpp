// hfp-style list arguments: every accepted form, and the message for each malformed one.
#include "arg_parse.h"

#include <gtest/gtest.h>

#include "exit_codes.h"

using namespace frep::cli;

namespace {

// The message of the CliError that fn throws (and that it is a bad-argument error).
template <typename Fn>
std::string badArgsMessage(Fn fn) {
  try {
    fn();
  } catch (const CliError& e) {
    EXPECT_EQ(e.code, kExitBadArgs);
    return e.what();
  }
  ADD_FAILURE() << "no CliError thrown";
  return "";
}

}  // namespace

TEST(ArgParse, BoundsAllHfpForms) {
  Box one = parseBounds("-b", "2");
  EXPECT_EQ(one.lo, (std::array<double, 3>{-2, -2, -2}));
  EXPECT_EQ(one.hi, (std::array<double, 3>{2, 2, 2}));
  Box negative = parseBounds("-b", "-2");
  EXPECT_EQ(negative.hi, (std::array<double, 3>{2, 2, 2}));
  Box two = parseBounds("-b", "-1,3");
  EXPECT_EQ(two.lo, (std::array<double, 3>{-1, -1, -1}));
  EXPECT_EQ(two.hi, (std::array<double, 3>{3, 3, 3}));
  Box three = parseBounds("-b", "1,2,3");
  EXPECT_EQ(three.lo, (std::array<double, 3>{-1, -2, -3}));
  EXPECT_EQ(three.hi, (std::array<double, 3>{1, 2, 3}));
  Box six = parseBounds("-b", "0,1,2,3,4,5.5");
  EXPECT_EQ(six.lo, (std::array<double, 3>{0, 1, 2}));
  EXPECT_EQ(six.hi, (std::array<double, 3>{3, 4, 5.5}));
  Box def;
  EXPECT_EQ(def.lo, (std::array<double, 3>{-10, -10, -10}));
}

TEST(ArgParse, BoundsErrorsNameTheFieldAndQuoteTheInput) {
  EXPECT_EQ(badArgsMessage([] { parseBounds("--bounds", "1,2,3,4"); }),
            "--bounds: expected 1, 2, 3 or 6 comma-separated numbers, got '1,2,3,4'");
  EXPECT_EQ(badArgsMessage([] { parseBounds("--bounds", "a,b"); }),
            "--bounds: expected 1, 2, 3 or 6 comma-separated numbers, got 'a,b' ('a' is not a number)");
  EXPECT_EQ(badArgsMessage([] { parseBounds("--bounds", "1,"); }),
            "--bounds: expected 1, 2, 3 or 6 comma-separated numbers, got '1,' ('' is not a number)");
  EXPECT_EQ(badArgsMessage([] { parseBounds("--bounds", "0"); }),
            "--bounds: the x range is empty (max must exceed min), got '0'");
  EXPECT_EQ(badArgsMessage([] { parseBounds("--bounds", "0,0,0,1,-1,1"); }),
            "--bounds: the y range is empty (max must exceed min), got '0,0,0,1,-1,1'");
  EXPECT_NE(badArgsMessage([] { parseBounds("--bounds", "inf"); }).find("'inf' is not a number"), std::string::npos);
  // Issue 31: `-b 1e308` gave a grid of one voxel of size inf (exit 0).
  EXPECT_EQ(badArgsMessage([] { parseBounds("-b", "1e308"); }),
            "-b: the x range is wider than the largest finite number (its width overflows to inf), got '1e308'");
  EXPECT_NE(badArgsMessage([] { parseBounds("-b", "0,0,-1e308,1,1,1e308"); }).find("the z range is wider"),
            std::string::npos);
  EXPECT_NO_THROW(parseBounds("-b", "8e307"));
}

TEST(ArgParse, Cells) {
  EXPECT_EQ(parseCells("-g", "30"), (std::array<int, 3>{30, 30, 30}));
  EXPECT_EQ(parseCells("-g", "10,20,30"), (std::array<int, 3>{10, 20, 30}));
  EXPECT_EQ(badArgsMessage([] { parseCells("-g", "10,20"); }),
            "-g: expected 1 or 3 comma-separated integers, got '10,20'");
  EXPECT_EQ(badArgsMessage([] { parseCells("-g", "2.5"); }),
            "-g: expected 1 or 3 comma-separated integers, got '2.5' ('2.5' is not an integer from 1 to 65535)");
  EXPECT_NE(badArgsMessage([] { parseCells("-g", "0"); }).find("'0' is not an integer"), std::string::npos);
}

TEST(ArgParse, AxisAndMapping) {
  EXPECT_EQ(parseAxis("--axis", "x"), 0);
  EXPECT_EQ(parseAxis("--axis", "Z"), 2);
  EXPECT_EQ(badArgsMessage([] { parseAxis("--axis", "w"); }), "--axis: expected x, y or z, got 'w'");

  AxisMapping m = parseMapping("-x", "X,y,Z,0.5,-2");
  EXPECT_EQ(m.axis, (std::vector<int>{0, 1, 2, -1, -1}));
  EXPECT_EQ(m.constant[3], 0.5);
  EXPECT_EQ(m.constant[4], -2.0);
  EXPECT_EQ(m.viewDims, 3);
  EXPECT_EQ(parseMapping("-x", "1,X,Y").viewDims, 2);
  EXPECT_EQ(badArgsMessage([] { parseMapping("-x", "X,X"); }), "-x: axis X is mapped twice in 'X,X'");
  EXPECT_EQ(badArgsMessage([] { parseMapping("-x", "X,Y,foo"); }),
            "-x: expected comma-separated X, Y, Z or numbers, got 'X,Y,foo' ('foo' is neither)");
}

TEST(ArgParse, FormatNumberRoundTrips) {
  EXPECT_EQ(formatNumber(0.75), "0.75");
  EXPECT_EQ(formatNumber(-0.0), "0");
  EXPECT_EQ(formatNumber(0.1 + 0.2), "0.30000000000000004");
  EXPECT_EQ(formatNumber(1e-300), "1e-300");
}
