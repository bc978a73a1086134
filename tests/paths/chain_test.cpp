// Tests for chain.hpp: validateChain and coordinateScale.
//
// The reference for "which vertex is the first offending one" is a brute-force scan written
// here (firstOffendingVertex); error messages must name that vertex's 0-based index and its
// offending value (chain.hpp: "naming the first offending vertex (0-based index and value)").

#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <random>
#include <regex>
#include <string>
#include <vector>

#include "scallop/paths/chain.hpp"
#include "scallop/error.hpp"

namespace {

using scallop::Chain;
using scallop::Point2;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// The message of the scallop::Error thrown by validateChain, or nullopt if nothing was thrown.
// Any other exception type is a failure (one error channel, error.hpp).
std::optional<std::string> validationMessage(const Chain& chain) {
  try {
    scallop::validateChain(chain);
  } catch (const scallop::Error& e) {
    return std::string(e.what());
  } catch (const std::exception& e) {
    ADD_FAILURE() << "validateChain threw a non-scallop exception: " << e.what();
    return std::string(e.what());
  }
  return std::nullopt;
}

// True if `message` contains `index` as a whole number (not as part of a longer number
// such as 17 or 2.75), which is how a 0-based vertex index must appear.
bool namesIndex(const std::string& message, std::size_t index) {
  const std::regex token("(^|[^0-9.])" + std::to_string(index) + "([^0-9.]|$)");
  return std::regex_search(message, token);
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// Brute-force reference: the first vertex that violates the chain invariant, scanning in
// order: a non-finite coordinate, or x smaller than the previous vertex's x.
std::optional<std::size_t> firstOffendingVertex(const Chain& chain) {
  for (std::size_t i = 0; i < chain.size(); ++i) {
    if (!std::isfinite(chain[i].x) || !std::isfinite(chain[i].z)) return i;
    if (i > 0 && chain[i].x < chain[i - 1].x) return i;
  }
  return std::nullopt;
}

TEST(ValidateChain, RejectsFewerThanTwoPoints) {
  for (const Chain& chain : {Chain{}, Chain{{1.5, 2.5}}}) {
    const auto message = validationMessage(chain);
    ASSERT_TRUE(message.has_value()) << "chain of " << chain.size() << " points accepted";
    EXPECT_FALSE(message->empty());
  }
}

TEST(ValidateChain, RejectsNaNNamingIndexAndValue) {
  // NaN in x, then in z, at index 7 of a 10-point chain (values chosen so that "7" cannot
  // appear inside any other number of the message).
  for (int coordinate = 0; coordinate < 2; ++coordinate) {
    Chain chain;
    for (int i = 0; i < 10; ++i) chain.push_back({0.5 * i, 0.25});
    (coordinate == 0 ? chain[7].x : chain[7].z) = kNaN;
    const auto message = validationMessage(chain);
    ASSERT_TRUE(message.has_value()) << "NaN in coordinate " << coordinate << " accepted";
    EXPECT_TRUE(namesIndex(*message, 7)) << *message;
    EXPECT_NE(lower(*message).find("nan"), std::string::npos) << *message;
  }
}

TEST(ValidateChain, RejectsInfinityNamingIndexAndValue) {
  const double values[] = {kInf, -kInf};
  for (const double value : values) {
    for (int coordinate = 0; coordinate < 2; ++coordinate) {
      Chain chain{{0.0, 0.0}, {1.0, 1.0}, {2.0, 0.5}, {3.0, 0.0}};
      (coordinate == 0 ? chain[3].x : chain[3].z) = value;
      const auto message = validationMessage(chain);
      ASSERT_TRUE(message.has_value()) << value << " in coordinate " << coordinate;
      EXPECT_TRUE(namesIndex(*message, 3)) << *message;
      EXPECT_NE(lower(*message).find("inf"), std::string::npos) << *message;
      if (value < 0) {
        EXPECT_NE(lower(*message).find("-inf"), std::string::npos) << *message;
      }
    }
  }
}

TEST(ValidateChain, RejectsDecreasingXNamingIndexAndValue) {
  // x goes 0, 1, 2, 1.5: vertex 3 (x = 1.5) is the first offending one.
  const Chain chain{{0.0, 0.0}, {1.0, 4.0}, {2.0, 4.0}, {1.5, 4.0}, {9.0, 4.0}};
  const auto message = validationMessage(chain);
  ASSERT_TRUE(message.has_value());
  EXPECT_TRUE(namesIndex(*message, 3)) << *message;
  EXPECT_NE(message->find("1.5"), std::string::npos) << *message;

  // A decrease by one ulp is still a decrease.
  const Chain ulp{{0.0, 0.0}, {1.0, 0.0}, {std::nextafter(1.0, 0.0), 0.0}};
  const auto ulpMessage = validationMessage(ulp);
  ASSERT_TRUE(ulpMessage.has_value());
  EXPECT_TRUE(namesIndex(*ulpMessage, 2)) << *ulpMessage;
}

TEST(ValidateChain, NamesTheFirstOffenderWhenSeveral) {
  // Decreasing x at 4, NaN at 6: 4 is named.
  Chain chain{{0, 0}, {1, 0}, {2, 0}, {3, 0}, {-2.75, 0}, {5, 0}, {kNaN, 0}, {8, 0}};
  auto message = validationMessage(chain);
  ASSERT_TRUE(message.has_value());
  EXPECT_TRUE(namesIndex(*message, 4)) << *message;
  EXPECT_NE(message->find("-2.75"), std::string::npos) << *message;
  // Infinite z at 2 comes before both.
  chain[2].z = kInf;
  message = validationMessage(chain);
  ASSERT_TRUE(message.has_value());
  EXPECT_TRUE(namesIndex(*message, 2)) << *message;
}

TEST(ValidateChain, AcceptsVerticalEdgesDuplicatesAndExtremes) {
  const std::vector<Chain> valid = {
      {{0, 0}, {0, 0}},                                 // one repeated point
      {{0, 0}, {0, 5}, {0, -3}, {0, 7}},                // all vertical, up and down
      {{1, 1}, {1, 1}, {1, 1}, {2, 1}, {2, 1}},         // duplicates
      {{0, 0}, {0, 5}, {3, 5}, {3, 0}},                 // vertical first and last edge
      {{-1e300, 1e300}, {1e300, -1e300}},               // huge finite values
      {{0.0, 0.0}, {-0.0, 1.0}, {0.0, 2.0}},            // -0 == +0: not decreasing
      {{std::numeric_limits<double>::denorm_min(), 0}, {2e-308, 0}},  // subnormal x
      {{-std::numeric_limits<double>::max(), 0}, {std::numeric_limits<double>::max(), 0}},
  };
  for (const Chain& chain : valid) {
    const auto message = validationMessage(chain);
    EXPECT_FALSE(message.has_value()) << *message;
  }
}

// Thousands of random chains, valid or with exactly one planted defect; the library must
// agree with the brute-force scan on acceptance and name the same vertex.
TEST(ValidateChain, AgreesWithBruteForceOnRandomChains) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int rejected = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const std::size_t n = 2 + rng() % 40;
    Chain chain;
    double x = (unit(rng) - 0.5) * 100.0;
    for (std::size_t i = 0; i < n; ++i) {
      if (i > 0 && unit(rng) > 0.2) x += unit(rng) * 3.0;  // 20 % vertical edges
      chain.push_back({x, (unit(rng) - 0.5) * 50.0});
    }
    const int defect = static_cast<int>(rng() % 5);  // 0: none, 1: NaN, 2: +inf, 3: -inf, 4: x back
    const std::size_t at = rng() % n;
    const double bad = defect == 1 ? kNaN : defect == 2 ? kInf : -kInf;
    if (defect >= 1 && defect <= 3) (rng() % 2 ? chain[at].x : chain[at].z) = bad;
    if (defect == 4 && at > 0) chain[at].x = chain[at - 1].x - 0.5 - unit(rng);
    const auto expected = firstOffendingVertex(chain);
    const auto message = validationMessage(chain);
    ASSERT_EQ(expected.has_value(), message.has_value())
        << "trial " << trial << (message ? ": " + *message : std::string());
    if (expected) {
      ++rejected;
      EXPECT_TRUE(namesIndex(*message, *expected))
          << "trial " << trial << " expected index " << *expected << ": " << *message;
    }
  }
  EXPECT_GT(rejected, 2000);  // the planted defects were actually exercised
}

TEST(CoordinateScale, IsLargestAbsoluteCoordinate) {
  EXPECT_EQ(scallop::coordinateScale(Chain{{-3, 2}, {1, -7.5}}), 7.5);
  EXPECT_EQ(scallop::coordinateScale(Chain{{0, 0}, {0, 0}}), 0.0);
  EXPECT_EQ(scallop::coordinateScale(Chain{{-0.0, -0.0}, {0, 0}}), 0.0);
  EXPECT_EQ(scallop::coordinateScale(Chain{{-1e6, 1}, {1e6 - 1, 2}}), 1e6);   // x dominates
  EXPECT_EQ(scallop::coordinateScale(Chain{{1, -2e-300}, {1, 3e300}}), 3e300); // z dominates

  // Brute force over random chains: exact equality (max and fabs round nothing).
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 2000; ++trial) {
    const std::size_t n = 2 + rng() % 50;
    const double magnitude = std::pow(10.0, static_cast<double>(rng() % 13) - 6.0);
    Chain chain;
    double x = unit(rng) * magnitude;
    double expected = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      x += std::fabs(unit(rng)) * magnitude;
      const double z = unit(rng) * magnitude * 3.0;
      chain.push_back({x, z});
      expected = std::max({expected, std::fabs(x), std::fabs(z)});
    }
    ASSERT_EQ(scallop::coordinateScale(chain), expected) << "trial " << trial;
  }
}

}  // namespace
