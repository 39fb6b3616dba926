// JSON and plain-text renderings of the evaluation figures. Every figure
// the project reports goes through these, so field names are stable:
// ErrorStats -> {count, mean, median, p90, max, rms}.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "monomap/eval/point_accuracy.h"
#include "monomap/eval/render_fidelity.h"
#include "monomap/eval/structure_accuracy.h"
#include "monomap/eval/trajectory_metrics.h"

namespace monomap {

nlohmann::json ToJson(const ErrorStats& stats);
// {"absolute_m": {...}, "relative_percent": {...}}
nlohmann::json ToJson(const PointAccuracy& accuracy);
// {"matched": n, "scale": s, "translation_m": {...}, "rotation_deg": {...}}
nlohmann::json ToJson(const TrajectoryErrors& errors);
// {"counts": {true_planes, observed_true_planes, fitted_planes, landmarks,
//             landmarks_off_structure},
//  "point_error": {"all_landmarks": {...}, "landmarks_on_planes": {...}},
//  "planes": {"matches": [{fitted_id, inliers, true_id, normal_error_deg,
//                          offset_error_m, matched}],
//             "normal_error_deg": {...}, "offset_error_m": {...},
//             "precision": p, "recall": r},
//  "true_planes": [{true_id, near_landmarks, observed, matched,
//                   best_fitted_id, normal_error_deg, offset_error_m}]}
// (errors of a true plane without a fitted plane are null).
nlohmann::json ToJson(const StructureAccuracy& accuracy);
// {"compared": n, "skipped": n, "ncc": {...}, "psnr_db": {...},
//  "coverage": {...}, "frames": [{frame, coverage, ncc, psnr_db}]}
nlohmann::json ToJson(const RenderFidelity& fidelity);

// Fixed-width tables, one row per quantity, columns count mean median p90
// max rms; each ends with a newline. Point errors in mm and %.
std::string FormatTable(const PointAccuracy& accuracy);
// NCC, PSNR (dB) and coverage (%) over the compared frames, and counts.
std::string FormatTable(const RenderFidelity& fidelity);
// Translation in mm, rotation in degrees, plus the matched count and scale.
std::string FormatTable(const TrajectoryErrors& errors);
// Counts, precision and recall, point errors (mm and %), then one row per
// fitted plane and one per true plane (normal errors in degrees, offsets
// in mm).
std::string FormatTable(const StructureAccuracy& accuracy);

}  // namespace monomap
