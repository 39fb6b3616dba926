#include "monomap/util/stats.h"

#include <gtest/gtest.h>

#include "monomap/util/angles.h"

namespace monomap {
namespace {

TEST(StatsTest, MedianConventions) {
  EXPECT_EQ(Median({}), 0.0);
  EXPECT_EQ(UpperMedian({}), 0.0);
  EXPECT_EQ(Median({7.0}), 7.0);
  EXPECT_EQ(Median({5.0, 1.0, 3.0}), 3.0);
  EXPECT_EQ(UpperMedian({5.0, 1.0, 3.0}), 3.0);
  // Even count: the mean of the middle two, or the upper one.
  EXPECT_EQ(Median({4.0, 1.0, 2.0, 10.0}), 3.0);
  EXPECT_EQ(UpperMedian({4.0, 1.0, 2.0, 10.0}), 4.0);
  float v[] = {3.0f, 1.0f, 2.0f, 8.0f};
  EXPECT_EQ(MedianInPlace(v, v + 4), 2.5f);
}

TEST(AnglesTest, RoundTripAndConstants) {
  EXPECT_DOUBLE_EQ(DegToRad(180.0), M_PI);
  EXPECT_DOUBLE_EQ(RadToDeg(M_PI / 2), 90.0);
  EXPECT_EQ(DegToRad(0.02), 0.02 * (M_PI / 180.0));  // the bit convention
  EXPECT_NEAR(RadToDeg(DegToRad(37.5)), 37.5, 1e-12);
}

}  // namespace
}  // namespace monomap
