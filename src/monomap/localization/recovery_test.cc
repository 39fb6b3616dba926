#include "monomap/localization/recovery.h"

#include <gtest/gtest.h>

#include "monomap/util/error.h"

namespace monomap {
namespace {

TEST(RecoveryEstimator, InjectsAShareAndMoreWithMcc) {
  const RecoveryOptions o;  // 2 %, at least 4 with MCC
  const RecoveryEstimator mcl(o, false, 1000);
  EXPECT_EQ(mcl.Plan(1000).replaced, 20);
  EXPECT_EQ(mcl.Plan(1000).appended, 0);
  EXPECT_EQ(mcl.Plan(10).replaced, 0);
  const RecoveryEstimator mcc(o, true, 1000);
  EXPECT_EQ(mcc.Plan(10).replaced, 4);
  // Never more than half the set.
  EXPECT_EQ(mcc.Plan(5).replaced, 2);
}

TEST(RecoveryEstimator, RelocalizesOnAPersistentDropOfTheBestNcc) {
  RecoveryOptions o;  // drop 0.035, coverage >= 0.3, 2 updates in a row
  RecoveryEstimator r(o, true, 1000);
  for (int i = 0; i < 50; ++i)
    EXPECT_FALSE(r.Update(0.9 + 0.01 * (i % 2), 0.8));
  // A drop of 0.03: the fast average falls ~0.015-0.025 below.
  EXPECT_FALSE(r.Update(0.875, 0.8));
  EXPECT_FALSE(r.Update(0.875, 0.8));
  // A drop of 0.15: the first update is not enough, the second is.
  r.Reset();
  for (int i = 0; i < 50; ++i) r.Update(0.9, 0.8);
  EXPECT_FALSE(r.Update(0.75, 0.8));
  EXPECT_TRUE(r.Update(0.75, 0.8));
  // 10 % of the budget: up to the budget appended, beyond it replacing
  // (at most half the set), plus the injection.
  EXPECT_EQ(r.Plan(200).appended, 100);
  EXPECT_EQ(r.Plan(200).replaced, 4);
  EXPECT_EQ(r.Plan(950).appended, 50);
  EXPECT_EQ(r.Plan(950).replaced, 19 + 50);
  // It ends when the NCC comes back.
  for (int i = 0; i < 5; ++i) r.Update(0.9, 0.8);
  EXPECT_FALSE(r.relocalizing());
  // One bad frame between good ones is not a kidnapping.
  r.Reset();
  for (int i = 0; i < 50; ++i) r.Update(0.9, 0.8);
  EXPECT_FALSE(r.Update(0.5, 0.8));
  EXPECT_FALSE(r.Update(0.9, 0.8));
  EXPECT_FALSE(r.Update(0.9, 0.8));
  // Off with a zero threshold.
  o.relocalize_ncc_drop = 0.0;
  RecoveryEstimator off(o, true, 1000);
  for (int i = 0; i < 50; ++i) off.Update(0.9, 0.8);
  EXPECT_FALSE(off.Update(0.0, 0.8));
  EXPECT_FALSE(off.Update(0.0, 0.8));
  EXPECT_EQ(off.Plan(200).appended, 0);
}

// A view that shows little map is not judged: its NCC neither fires the
// trigger nor enters the averages, and the state holds across it.
TEST(RecoveryEstimator, IgnoresViewsWithLittleMap) {
  RecoveryEstimator r(RecoveryOptions(), true, 1000);
  for (int i = 0; i < 50; ++i) r.Update(0.95, 0.9);
  for (int i = 0; i < 20; ++i) EXPECT_FALSE(r.Update(0.6, 0.2));
  // Back on the map: the averages are those of before (no drop).
  EXPECT_FALSE(r.Update(0.95, 0.9));
  EXPECT_FALSE(r.Update(0.95, 0.9));
  // Relocalizing when the map leaves the view: it stays so.
  for (int i = 0; i < 3; ++i) r.Update(0.7, 0.9);
  ASSERT_TRUE(r.relocalizing());
  EXPECT_TRUE(r.Update(0.95, 0.1));
}

TEST(RecoveryEstimator, RefusesBadOptions) {
  RecoveryOptions o;
  o.injection_fraction = 1.0;
  EXPECT_THROW(RecoveryEstimator(o, false, 100), OptionsError);
  EXPECT_THROW(RecoveryEstimator(RecoveryOptions(), false, 0), OptionsError);
  o = RecoveryOptions();
  o.relocalize_min_updates = 0;
  EXPECT_THROW(RecoveryEstimator(o, false, 100), OptionsError);
  o = RecoveryOptions();
  o.relocalize_min_coverage = 1.0;
  EXPECT_THROW(RecoveryEstimator(o, false, 100), OptionsError);
}

}  // namespace
}  // namespace monomap
