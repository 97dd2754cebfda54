// SPDX-License-Identifier: GPL-3.0-or-later
// ExactSigns (src/core/exact_signs.h): the sign of a sum of doubles, the same
// for any order of the terms and any grouping into merged parts.
#include "exact_signs.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

using pcl_ms::detail::ExactSigns;

namespace {

/// The sign ExactSigns gives sum 0 of `terms`, added in `parts` parts that
/// are merged in order.
int signOf(const std::vector<double> &terms, std::size_t parts, bool &went_exact) {
  ExactSigns whole(1);
  for (std::size_t part = 0; part < parts; ++part) {
    ExactSigns piece(1);
    for (std::size_t i = part * terms.size() / parts; i < (part + 1) * terms.size() / parts; ++i)
      piece.add(0, terms[i]);
    whole.merge(piece);
  }
  went_exact = whole.needsExactPass();
  if (went_exact)
    for (double term : terms)
      whole.addExactly(0, term);
  return whole.sign(0);
}

/// Pairs +x, -x of random magnitudes, plus `rest`: their exact sum is rest.
std::vector<double> cancellingTerms(double rest, std::mt19937 &random) {
  std::uniform_real_distribution<double> mantissa(1.0, 2.0);
  std::uniform_int_distribution<int> exponent(-20, 40);
  std::vector<double> terms;
  for (int i = 0; i < 500; ++i) {
    const double x = std::ldexp(mantissa(random), exponent(random));
    terms.push_back(x);
    terms.push_back(-x);
  }
  terms.push_back(rest);
  return terms;
}

} // namespace

TEST(ExactSigns, CancellingTermsGiveTheExactSignInAnyOrderAndGrouping) {
  std::mt19937 random(20261202);
  int float_sign_wrong = 0;
  for (double rest : {std::ldexp(1.0, -60), -std::ldexp(1.0, -60), 0.0}) {
    const int expected = rest > 0 ? 1 : rest < 0 ? -1 : 0;
    std::vector<double> terms = cancellingTerms(rest, random);
    for (int order = 0; order < 20; ++order) {
      std::shuffle(terms.begin(), terms.end(), random);
      double rounded = 0;
      for (double term : terms)
        rounded += term;
      float_sign_wrong += (rounded > 0 ? 1 : rounded < 0 ? -1 : 0) != expected;
      for (std::size_t parts : {std::size_t(1), std::size_t(3), std::size_t(64)}) {
        bool went_exact = false;
        EXPECT_EQ(signOf(terms, parts, went_exact), expected)
            << "rest " << rest << ", order " << order << ", " << parts << " parts";
        EXPECT_TRUE(went_exact) << "a sum this close to zero needs the exact pass";
      }
    }
  }
  // The case is a real one: adding in order got the sign wrong somewhere.
  EXPECT_GT(float_sign_wrong, 0);
}

TEST(ExactSigns, ClearSumsNeedNoExactPassAndKeepTheirSign) {
  // The summands of a closed surface's signed volume: all of one sign with
  // a little noise; and three small, nearly cancelling sums beside them.
  ExactSigns sums(3);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> noise(-1e-3, 1e-3);
  std::vector<double> first;
  for (int i = 0; i < 10000; ++i) {
    first.push_back(1.0 + noise(random));
    sums.add(0, first.back());
    sums.add(1, -first.back());
  }
  sums.add(2, 0.0);
  EXPECT_FALSE(sums.needsExactPass());
  EXPECT_EQ(sums.sign(0), 1);
  EXPECT_EQ(sums.sign(1), -1);
  EXPECT_EQ(sums.sign(2), 0) << "only zeros: zero, without an exact pass";

  // Only the uncertain sum goes exact; the others keep their signs.
  ExactSigns mixed(2);
  const std::vector<double> tiny = {1e16, 1.0, -1e16};
  for (double term : first)
    mixed.add(0, term);
  for (double term : tiny)
    mixed.add(1, term);
  ASSERT_TRUE(mixed.needsExactPass());
  for (double term : first)
    mixed.addExactly(0, term);
  for (double term : tiny)
    mixed.addExactly(1, term);
  EXPECT_EQ(mixed.sign(0), 1);
  EXPECT_EQ(mixed.sign(1), 1) << "1e16 + 1 - 1e16 is 1, not the 0 of rounding";
}
