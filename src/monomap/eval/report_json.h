// JSON and plain-text renderings of the evaluation figures. Every figure
// the project reports goes through these, so field names are stable:
// ErrorStats -> {count, mean, median, p90, max, rms}.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "monomap/eval/point_accuracy.h"
#include "monomap/eval/trajectory_metrics.h"

namespace monomap {

nlohmann::json ToJson(const ErrorStats& stats);
// {"absolute_m": {...}, "relative_percent": {...}}
nlohmann::json ToJson(const PointAccuracy& accuracy);
// {"matched": n, "scale": s, "translation_m": {...}, "rotation_deg": {...}}
nlohmann::json ToJson(const TrajectoryErrors& errors);

// Fixed-width tables, one row per quantity, columns count mean median p90
// max rms; each ends with a newline. Point errors in mm and %.
std::string FormatTable(const PointAccuracy& accuracy);
// Translation in mm, rotation in degrees, plus the matched count and scale.
std::string FormatTable(const TrajectoryErrors& errors);

}  // namespace monomap
