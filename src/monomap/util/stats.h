// Order statistics used across the project. Two median conventions for an
// even count, named apart because results depend on them:
//  * Median: the mean of the two middle values (the statistical one);
//  * UpperMedian: the upper of the two (the value std::nth_element puts at
//    n / 2), always one of the values; what bundle adjustment, the
//    triangulation report and plane fitting's spacing estimate use.
// Empty input gives 0.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace monomap {

// Median of [begin, end) (mean of the two middle values for an even
// count), reordering the range. Undefined for an empty range.
template <typename T>
T MedianInPlace(T* begin, T* end) {
  const std::ptrdiff_t n = end - begin;
  T* mid = begin + n / 2;
  std::nth_element(begin, mid, end);
  T m = *mid;
  if (n % 2 == 0) m = T(0.5) * (m + *std::max_element(begin, mid));
  return m;
}

// Mean of the two middle values for an even count; 0 if empty.
inline double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  return MedianInPlace(values.data(), values.data() + values.size());
}

// Element n / 2 of the sorted values (the upper middle one for an even
// count); 0 if empty.
inline double UpperMedian(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto mid = values.begin() + values.size() / 2;
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

}  // namespace monomap
