#include "monomap/eval/report_json.h"

#include <gtest/gtest.h>

namespace monomap {
namespace {

TEST(ReportJsonTest, ErrorStatsFields) {
  const nlohmann::json j = ToJson(ComputeErrorStats({1.0, 2.0, 3.0, 4.0}));
  EXPECT_EQ(j["count"].get<size_t>(), 4u);
  EXPECT_DOUBLE_EQ(j["mean"].get<double>(), 2.5);
  EXPECT_DOUBLE_EQ(j["median"].get<double>(), 2.5);
  EXPECT_DOUBLE_EQ(j["p90"].get<double>(), 4.0);
  EXPECT_DOUBLE_EQ(j["max"].get<double>(), 4.0);
  EXPECT_DOUBLE_EQ(j["rms"].get<double>(), std::sqrt(7.5));
}

TEST(ReportJsonTest, PointAccuracyAndTrajectory) {
  PointAccuracy acc;
  acc.absolute_m = ComputeErrorStats({0.001, 0.003});
  acc.relative_percent = ComputeErrorStats({0.1, 0.3});
  const nlohmann::json j = ToJson(acc);
  EXPECT_DOUBLE_EQ(j["absolute_m"]["mean"].get<double>(), 0.002);
  EXPECT_DOUBLE_EQ(j["relative_percent"]["max"].get<double>(), 0.3);
  const std::string table = FormatTable(acc);
  EXPECT_NE(table.find("abs error (mm)"), std::string::npos);
  EXPECT_NE(table.find("2.000"), std::string::npos);  // mean in mm
  EXPECT_NE(table.find("rel error (%)"), std::string::npos);

  TrajectoryErrors t;
  t.matched = 12;
  t.scale = 2.0;
  t.translation_m = ComputeErrorStats({0.01});
  t.rotation_deg = ComputeErrorStats({0.5});
  const nlohmann::json jt = ToJson(t);
  EXPECT_EQ(jt["matched"].get<size_t>(), 12u);
  EXPECT_DOUBLE_EQ(jt["scale"].get<double>(), 2.0);
  EXPECT_DOUBLE_EQ(jt["translation_m"]["rms"].get<double>(), 0.01);
  EXPECT_DOUBLE_EQ(jt["rotation_deg"]["median"].get<double>(), 0.5);
  const std::string tt = FormatTable(t);
  EXPECT_NE(tt.find("matched 12"), std::string::npos);
  EXPECT_NE(tt.find("10.000"), std::string::npos);  // 1 cm in mm
}

}  // namespace
}  // namespace monomap
