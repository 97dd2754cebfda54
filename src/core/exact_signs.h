// SPDX-License-Identifier: GPL-3.0-or-later
// Signs of sums of doubles that do not depend on the order of the terms.
// Internal to the library: not installed.
#pragma once

#include <CGAL/Gmpzf.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace pcl_ms {
namespace detail {

/// The signs of several sums of doubles, each that of the exact sum of its
/// terms (-1, 0 or +1), so that any order of adding them, or parts of them
/// added apart and then merged, decides alike (docs/algorithm.md, section 4,
/// "Orientation"). The terms are added in floating point with their
/// magnitudes; a sum within its rounding bound of zero needs a second pass
/// that adds its terms exactly (CGAL::Gmpzf, a GMP integer times a power of
/// two, exact for sums of doubles).
class ExactSigns {
public:
  /// A sum's terms added so far, in floating point: what another process
  /// sends for merging (trivially copyable).
  struct Partial {
    double value = 0;
    double magnitude = 0;
    std::uint64_t terms = 0;
  };

  explicit ExactSigns(std::size_t sums) : rounded_(sums) {}

  void add(std::size_t k, double term) {
    Partial &sum = rounded_[k];
    sum.value += term;
    sum.magnitude += std::abs(term);
    ++sum.terms;
  }

  const Partial &partial(std::size_t k) const { return rounded_[k]; }

  /// Adds partial sums of sum k made elsewhere.
  void merge(std::size_t k, const Partial &other) {
    rounded_[k].value += other.value;
    rounded_[k].magnitude += other.magnitude;
    rounded_[k].terms += other.terms;
  }

  /// Adds another set of partial sums of the same sums.
  void merge(const ExactSigns &other) {
    for (std::size_t k = 0; k < rounded_.size(); ++k)
      merge(k, other.rounded_[k]);
  }

  /// Whether some sum's sign needs addExactly() with all of its terms.
  bool needsExactPass() {
    exact_slot_.assign(rounded_.size(), no_slot);
    exact_.clear();
    for (std::size_t k = 0; k < rounded_.size(); ++k)
      if (certainSign(rounded_[k]) == 0 && rounded_[k].magnitude > 0) {
        exact_slot_[k] = exact_.size();
        exact_.emplace_back();
      }
    return !exact_.empty();
  }

  /// After needsExactPass(): whether sum k's sign needs its terms again.
  bool needsExactly(std::size_t k) const { return exact_slot_[k] != no_slot; }

  /// The exact pass, after needsExactPass(): the same terms again.
  void addExactly(std::size_t k, double term) {
    if (exact_slot_[k] != no_slot)
      exact_[exact_slot_[k]] += CGAL::Gmpzf(term);
  }

  /// Sum k's sign, once needsExactPass() has been asked (and, if it was
  /// true, the exact pass made).
  int sign(std::size_t k) const {
    if (!exact_slot_.empty() && exact_slot_[k] != no_slot)
      return static_cast<int>(exact_[exact_slot_[k]].sign());
    return certainSign(rounded_[k]);
  }

private:
  /// +1 or -1 when the exact sum surely has that sign, 0 otherwise. Adding
  /// n terms in any order (and in any grouping) is off the exact sum by at
  /// most gamma(n - 1) times the sum of their magnitudes, gamma(k) = k u /
  /// (1 - k u) with u the unit roundoff, and the computed magnitude is at
  /// least 1 - gamma(n - 1) of the true one (Higham, "Accuracy and Stability
  /// of Numerical Algorithms", section 4.2). For n u <= 0.01 the error is
  /// then below 1.03 n u times the computed magnitude: twice n u leaves room
  /// for the rounding of the bound itself.
  static int certainSign(const Partial &sum) {
    const double unit_roundoff = std::numeric_limits<double>::epsilon() / 2;
    const double count_roundoff = static_cast<double>(sum.terms) * unit_roundoff;
    if (count_roundoff > 0.01)
      return 0;
    const double bound = 2 * count_roundoff * sum.magnitude;
    return sum.value > bound ? 1 : sum.value < -bound ? -1 : 0;
  }

  static constexpr std::size_t no_slot = static_cast<std::size_t>(-1);
  std::vector<Partial> rounded_;
  std::vector<std::size_t> exact_slot_;
  std::vector<CGAL::Gmpzf> exact_;
};

} // namespace detail
} // namespace pcl_ms
