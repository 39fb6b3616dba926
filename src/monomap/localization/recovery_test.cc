#include "monomap/localization/recovery.h"

#include <gtest/gtest.h>

#include "monomap/util/error.h"

namespace monomap {
namespace {

TEST(RecoveryEstimator, InjectsAShareAndMoreWithMcc) {
  const RecoveryOptions o;  // 2 %, at least 4 with MCC
  const RecoveryEstimator mcl(o, false, 1000, 0.05);
  EXPECT_EQ(mcl.Plan(1000).replaced, 20);
  EXPECT_EQ(mcl.Plan(1000).appended, 0);
  EXPECT_EQ(mcl.Plan(10).replaced, 0);
  const RecoveryEstimator mcc(o, true, 1000, 0.05);
  EXPECT_EQ(mcc.Plan(10).replaced, 4);
  // Never more than half the set.
  EXPECT_EQ(mcc.Plan(5).replaced, 2);
}

TEST(RecoveryEstimator, RelocalizesOnADropOfTheBestLikelihood) {
  RecoveryOptions o;  // drop 0.035 NCC = 0.7 log units at sigma 0.05
  RecoveryEstimator r(o, true, 1000, 0.05);
  for (int i = 0; i < 50; ++i) EXPECT_FALSE(r.Update(-2.0 + 0.1 * (i % 2)));
  // A drop of 0.6 log units: the fast average falls ~0.3-0.45 below.
  EXPECT_FALSE(r.Update(-2.6));
  EXPECT_FALSE(r.Update(-2.6));
  // A drop of 3 log units (0.15 NCC): relocalizing at once.
  r.Reset();
  for (int i = 0; i < 50; ++i) r.Update(-2.0);
  EXPECT_TRUE(r.Update(-5.0));
  // 10 % of the budget: up to the budget appended, beyond it replacing
  // (at most half the set), plus the injection.
  EXPECT_EQ(r.Plan(200).appended, 100);
  EXPECT_EQ(r.Plan(200).replaced, 4);
  EXPECT_EQ(r.Plan(950).appended, 50);
  EXPECT_EQ(r.Plan(950).replaced, 19 + 50);
  // Off with a zero threshold.
  o.relocalize_ncc_drop = 0.0;
  RecoveryEstimator off(o, true, 1000, 0.05);
  for (int i = 0; i < 50; ++i) off.Update(-2.0);
  EXPECT_FALSE(off.Update(-50.0));
  EXPECT_EQ(off.Plan(200).appended, 0);
}

TEST(RecoveryEstimator, RefusesBadOptions) {
  RecoveryOptions o;
  o.injection_fraction = 1.0;
  EXPECT_THROW(RecoveryEstimator(o, false, 100, 0.05), OptionsError);
  EXPECT_THROW(RecoveryEstimator(RecoveryOptions(), false, 0, 0.05),
               OptionsError);
}

}  // namespace
}  // namespace monomap
