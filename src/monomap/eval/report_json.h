// JSON and plain-text renderings of the evaluation figures. Every figure
// the project reports goes through these, so field names are stable:
// ErrorStats -> {count, mean, median, p90, max, rms}.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "monomap/eval/board_poses.h"
#include "monomap/eval/checkerboard_accuracy.h"
#include "monomap/eval/lens_residuals.h"
#include "monomap/eval/plane_accuracy.h"
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
// {"num_planes": n, "planes": [{id, distance_m: {...}}], "all": {...}}
nlohmann::json ToJson(const PlaneSurfaceAccuracy& accuracy);
// {found, plane_id, corners_found, corners_expected} and, if found,
// {detector, error_m: {...}}.
nlohmann::json ToJson(const CheckerboardAccuracy& accuracy,
                      const CheckerboardSpec& spec);
// {frames, poses, rms_px, rotation_sigma_deg, position_sigma_m}
nlohmann::json ToJson(const BoardPoseReport& report);
// {"tracks_used": n, "rings": [{min_radius_px, max_radius_px, count,
//  radial_mean_px, radial_median_px, tangential_median_px}]}
nlohmann::json ToJson(const LensResidualReport& report);
// The matching thresholds: {max_match_angle_deg, max_match_offset_m,
// polygon_margin_m, min_observed_landmarks, observed_distance_m}.
nlohmann::json ToJson(const StructureAccuracyOptions& options);

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
// One row per plane and one for all: samples, median, p90, max (mm).
std::string FormatTable(const PlaneSurfaceAccuracy& accuracy);
// One line: found or not, where, corner errors (mm).
std::string FormatTable(const CheckerboardAccuracy& accuracy,
                        const CheckerboardSpec& spec);
// Corner RMS (px) and the formal sigmas (deg, mm): median and max.
std::string FormatTable(const BoardPoseReport& report);
// Tracks used, then one row per ring (px).
std::string FormatTable(const LensResidualReport& report);

}  // namespace monomap
