#include "monomap/eval/report_json.h"

#include <cstdio>

namespace monomap {

nlohmann::json ToJson(const ErrorStats& s) {
  return {{"count", s.count}, {"mean", s.mean}, {"median", s.median},
          {"p90", s.p90},     {"max", s.max},   {"rms", s.rms}};
}

nlohmann::json ToJson(const PointAccuracy& a) {
  return {{"absolute_m", ToJson(a.absolute_m)},
          {"relative_percent", ToJson(a.relative_percent)}};
}

nlohmann::json ToJson(const TrajectoryErrors& e) {
  return {{"matched", e.matched},
          {"scale", e.scale},
          {"translation_m", ToJson(e.translation_m)},
          {"rotation_deg", ToJson(e.rotation_deg)}};
}

namespace {

std::string Header() {
  char buf[160];
  std::snprintf(buf, sizeof(buf), "%-20s %8s %10s %10s %10s %10s %10s\n",
                "", "count", "mean", "median", "p90", "max", "rms");
  return buf;
}

// One row with every statistic multiplied by `unit`.
std::string Row(const char* name, const ErrorStats& s, double unit) {
  char buf[160];
  std::snprintf(buf, sizeof(buf),
                "%-20s %8zu %10.3f %10.3f %10.3f %10.3f %10.3f\n", name,
                s.count, s.mean * unit, s.median * unit, s.p90 * unit,
                s.max * unit, s.rms * unit);
  return buf;
}

}  // namespace

std::string FormatTable(const PointAccuracy& a) {
  return Header() + Row("abs error (mm)", a.absolute_m, 1e3) +
         Row("rel error (%)", a.relative_percent, 1.0);
}

std::string FormatTable(const TrajectoryErrors& e) {
  char buf[96];
  std::snprintf(buf, sizeof(buf), "matched %zu, scale %.6f\n", e.matched,
                e.scale);
  return buf + Header() + Row("translation (mm)", e.translation_m, 1e3) +
         Row("rotation (deg)", e.rotation_deg, 1.0);
}

}  // namespace monomap
