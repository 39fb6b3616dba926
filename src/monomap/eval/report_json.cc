#include "monomap/eval/report_json.h"

#include <cstdio>

namespace monomap {

nlohmann::json ToJson(const ErrorStats& s) {
  return {{"count", s.count}, {"mean", s.mean}, {"median", s.median},
          {"p90", s.p90},     {"max", s.max},   {"rms", s.rms}};
}

nlohmann::json ToJson(const PointAccuracy& a) {
  return {{"absolute_m", ToJson(a.absolute_m)},
          {"relative_percent", ToJson(a.relative_percent)},
          {"share_above_1cm", a.share_above_1cm}};
}

nlohmann::json ToJson(const TrajectoryErrors& e) {
  return {{"matched", e.matched},
          {"scale", e.scale},
          {"translation_m", ToJson(e.translation_m)},
          {"rotation_deg", ToJson(e.rotation_deg)}};
}

nlohmann::json ToJson(const StructureAccuracy& a) {
  nlohmann::json matches = nlohmann::json::array();
  for (const PlaneMatch& m : a.matches) {
    matches.push_back({{"fitted_id", m.fitted_id},
                       {"inliers", m.inliers},
                       {"true_id", m.true_id},
                       {"normal_error_deg", m.normal_error_deg},
                       {"offset_error_m", m.offset_error_m},
                       {"matched", m.matched}});
  }
  nlohmann::json true_planes = nlohmann::json::array();
  for (const TruePlaneResult& t : a.true_plane_results) {
    const bool compared = t.best_fitted_id >= 0;
    true_planes.push_back(
        {{"true_id", t.true_id},
         {"near_landmarks", t.near_landmarks},
         {"observed", t.observed},
         {"matched", t.matched},
         {"best_fitted_id", t.best_fitted_id},
         {"normal_error_deg",
          compared ? nlohmann::json(t.normal_error_deg) : nlohmann::json()},
         {"offset_error_m",
          compared ? nlohmann::json(t.offset_error_m) : nlohmann::json()}});
  }
  nlohmann::json j;
  j["counts"] = {{"true_planes", a.true_planes},
                 {"observed_true_planes", a.observed_true_planes},
                 {"fitted_planes", a.fitted_planes},
                 {"landmarks", a.landmarks},
                 {"landmarks_off_structure", a.landmarks_off_structure}};
  j["point_error"] = {{"all_landmarks", ToJson(a.point_error_all)},
                      {"landmarks_on_planes", ToJson(a.point_error_on_planes)}};
  j["planes"] = {{"matches", matches},
                 {"normal_error_deg", ToJson(a.normal_error_deg)},
                 {"offset_error_m", ToJson(a.offset_error_m)},
                 {"precision", a.precision},
                 {"recall", a.recall}};
  j["true_planes"] = true_planes;
  const AreaCoverage& c = a.coverage;
  nlohmann::json area_planes = nlohmann::json::array();
  for (const PlaneCoverage& p : c.planes) {
    area_planes.push_back({{"true_id", p.true_id},
                           {"seen_area_m2", p.seen_area_m2},
                           {"recovered_area_m2", p.recovered_area_m2},
                           {"observable_area_m2", p.observable_area_m2},
                           {"recovered_observable_area_m2",
                            p.recovered_observable_area_m2}});
  }
  nlohmann::json map_planes = nlohmann::json::array();
  for (const MapPlaneCoverage& p : c.map_planes) {
    map_planes.push_back({{"map_id", p.map_id},
                          {"area_m2", p.area_m2},
                          {"on_truth_m2", p.on_truth_m2}});
  }
  j["area"] = {{"seen_area_m2", c.seen_area_m2},
               {"recovered_area_m2", c.recovered_area_m2},
               {"area_recall", c.area_recall},
               {"large_planes_seen", c.large_planes_seen},
               {"large_planes_recovered", c.large_planes_recovered},
               {"map_area_m2", c.map_area_m2},
               {"map_area_on_truth_m2", c.map_area_on_truth_m2},
               {"area_precision", c.area_precision},
               {"observable_area_m2", c.observable_area_m2},
               {"recovered_observable_area_m2", c.recovered_observable_area_m2},
               {"observable_recall", c.observable_recall},
               {"large_planes_observable", c.large_planes_observable},
               {"large_planes_observable_recovered",
                c.large_planes_observable_recovered},
               {"planes", area_planes},
               {"map_planes", map_planes}};
  return j;
}

nlohmann::json ToJson(const RenderFidelity& f) {
  nlohmann::json frames = nlohmann::json::array();
  for (const FrameFidelity& x : f.frames) {
    frames.push_back({{"frame", x.frame},
                      {"coverage", x.coverage},
                      {"ncc", x.ncc},
                      {"psnr_db", x.psnr_db}});
  }
  return {{"compared", f.frames.size()},    {"skipped", f.skipped},
          {"ncc", ToJson(f.ncc)},           {"psnr_db", ToJson(f.psnr_db)},
          {"coverage", ToJson(f.coverage)}, {"frames", frames}};
}

namespace {

std::string Header() {
  char buf[160];
  std::snprintf(buf, sizeof(buf), "%-20s %8s %10s %10s %10s %10s %10s\n", "",
                "count", "mean", "median", "p90", "max", "rms");
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

std::string FormatTable(const RenderFidelity& f) {
  char buf[96];
  std::snprintf(buf, sizeof(buf), "%zu frames compared, %d skipped\n",
                f.frames.size(), f.skipped);
  return buf + Header() + Row("NCC", f.ncc, 1.0) +
         Row("PSNR (dB)", f.psnr_db, 1.0) +
         Row("coverage (%)", f.coverage, 100.0);
}

std::string FormatTable(const StructureAccuracy& a) {
  int matched_fitted = 0, matched_observed = 0;
  for (const PlaneMatch& m : a.matches) matched_fitted += m.matched;
  for (const TruePlaneResult& t : a.true_plane_results) {
    matched_observed += t.observed && t.matched;
  }
  char buf[256];
  std::snprintf(buf, sizeof(buf),
                "%d true planes (%d observed), %d fitted planes; %d "
                "landmarks, %d on no true plane\n"
                "plane precision %.1f%% (%d of %d fitted planes match), "
                "recall %.1f%% (%d of %d observed true planes found)\n",
                a.true_planes, a.observed_true_planes, a.fitted_planes,
                a.landmarks, a.landmarks_off_structure, 100 * a.precision,
                matched_fitted, a.fitted_planes, 100 * a.recall,
                matched_observed, a.observed_true_planes);
  std::string out = buf;
  const AreaCoverage& c = a.coverage;
  std::snprintf(buf, sizeof(buf),
                "area recovered %.1f%% (%.2f of %.2f m^2 seen); large "
                "planes recovered %d of %d; map area on the true structure "
                "%.1f%% (%.2f of %.2f m^2)\n",
                100 * c.area_recall, c.recovered_area_m2, c.seen_area_m2,
                c.large_planes_recovered, c.large_planes_seen,
                100 * c.area_precision, c.map_area_on_truth_m2, c.map_area_m2);
  out += buf;
  std::snprintf(buf, sizeof(buf),
                "observable area (2 views, parallax and incidence bounded) "
                "recovered %.1f%% (%.2f of %.2f m^2); large planes %d of %d\n",
                100 * c.observable_recall, c.recovered_observable_area_m2,
                c.observable_area_m2, c.large_planes_observable_recovered,
                c.large_planes_observable);
  out += buf;
  out +=
      Header() + Row("all abs (mm)", a.point_error_all.absolute_m, 1e3) +
      Row("all rel (%)", a.point_error_all.relative_percent, 1.0) +
      Row("on planes abs (mm)", a.point_error_on_planes.absolute_m, 1e3) +
      Row("on planes rel (%)", a.point_error_on_planes.relative_percent, 1.0) +
      Row("normal error (deg)", a.normal_error_deg, 1.0) +
      Row("offset error (mm)", a.offset_error_m, 1e3);
  out += "fitted  inliers  true  normal(deg)  offset(mm)  match\n";
  for (const PlaneMatch& m : a.matches) {
    std::snprintf(buf, sizeof(buf), "%6d  %7d  %4d  %11.3f  %10.2f  %5s\n",
                  m.fitted_id, m.inliers, m.true_id, m.normal_error_deg,
                  m.offset_error_m * 1e3, m.matched ? "yes" : "no");
    out += buf;
  }
  out +=
      "  true  landmarks  observed  matched  best fitted  normal(deg)  "
      "offset(mm)\n";
  for (const TruePlaneResult& t : a.true_plane_results) {
    if (t.best_fitted_id >= 0) {
      std::snprintf(buf, sizeof(buf),
                    "%6d  %9d  %8s  %7s  %11d  %11.3f  %10.2f\n", t.true_id,
                    t.near_landmarks, t.observed ? "yes" : "no",
                    t.matched ? "yes" : "no", t.best_fitted_id,
                    t.normal_error_deg, t.offset_error_m * 1e3);
    } else {
      std::snprintf(buf, sizeof(buf), "%6d  %9d  %8s  %7s  %11s  %11s  %10s\n",
                    t.true_id, t.near_landmarks, t.observed ? "yes" : "no",
                    "no", "-", "-", "-");
    }
    out += buf;
  }
  return out;
}

nlohmann::json ToJson(const PlaneSurfaceAccuracy& a) {
  nlohmann::json j;
  j["num_planes"] = a.planes.size();
  j["planes"] = nlohmann::json::array();
  for (const PlaneSurfaceAccuracy::PlaneErrors& p : a.planes) {
    j["planes"].push_back({{"id", p.id}, {"distance_m", ToJson(p.distance_m)}});
  }
  j["all"] = ToJson(a.all);
  return j;
}

std::string FormatTable(const PlaneSurfaceAccuracy& a) {
  std::string table = "plane  samples  median(mm)  p90(mm)  max(mm)\n";
  char line[160];
  for (const PlaneSurfaceAccuracy::PlaneErrors& p : a.planes) {
    const ErrorStats& e = p.distance_m;
    std::snprintf(line, sizeof(line), "%5d  %7zu  %10.2f  %7.2f  %7.2f\n", p.id,
                  e.count, e.median * 1e3, e.p90 * 1e3, e.max * 1e3);
    table += line;
  }
  const ErrorStats& e = a.all;
  std::snprintf(line, sizeof(line), "  all  %7zu  %10.2f  %7.2f  %7.2f\n",
                e.count, e.median * 1e3, e.p90 * 1e3, e.max * 1e3);
  return table + line;
}

nlohmann::json ToJson(const CheckerboardAccuracy& acc,
                      const CheckerboardSpec& spec) {
  nlohmann::json j;
  j["found"] = acc.found;
  j["plane_id"] = acc.plane_id;
  j["corners_found"] = acc.corners_found;
  j["corners_expected"] = spec.inner_corners_x * spec.inner_corners_y;
  if (acc.found) {
    j["detector"] = acc.detector;
    j["error_m"] = ToJson(acc.error_m);
    j["shape_error_m"] = ToJson(acc.shape_error_m);
  }
  return j;
}

std::string FormatTable(const CheckerboardAccuracy& acc,
                        const CheckerboardSpec& spec) {
  char table[400];
  std::snprintf(table, sizeof(table),
                "checkerboard %dx%d: %s in plane %d%s%s, corner error mean "
                "%.2f mm, median %.2f mm, max %.2f mm; after the best rigid "
                "fit (shape) mean %.2f mm\n",
                spec.inner_corners_x, spec.inner_corners_y,
                acc.found ? "found" : "NOT found", acc.plane_id,
                acc.found ? " by " : "", acc.detector.c_str(),
                acc.error_m.mean * 1e3, acc.error_m.median * 1e3,
                acc.error_m.max * 1e3, acc.shape_error_m.mean * 1e3);
  return table;
}

nlohmann::json ToJson(const BoardPoseReport& report) {
  nlohmann::json j;
  j["frames"] = report.frames;
  j["poses"] = report.poses.size();
  j["rms_px"] = ToJson(report.rms_px);
  j["rotation_sigma_deg"] = ToJson(report.rotation_sigma_deg);
  j["position_sigma_m"] = ToJson(report.position_sigma_m);
  return j;
}

std::string FormatTable(const BoardPoseReport& report) {
  char table[320];
  std::snprintf(table, sizeof(table),
                "corner RMS error (px): median %.3f, max %.3f\n"
                "formal sigma, rotation (deg): median %.4f, max %.4f\n"
                "formal sigma, camera centre (mm): median %.3f, max %.3f\n",
                report.rms_px.median, report.rms_px.max,
                report.rotation_sigma_deg.median, report.rotation_sigma_deg.max,
                report.position_sigma_m.median * 1e3,
                report.position_sigma_m.max * 1e3);
  return table;
}

nlohmann::json ToJson(const LensResidualReport& report) {
  nlohmann::json j;
  j["tracks_used"] = report.tracks_used;
  j["rings"] = nlohmann::json::array();
  for (const LensResidualRing& r : report.rings) {
    j["rings"].push_back({{"min_radius_px", r.min_radius_px},
                          {"max_radius_px", r.max_radius_px},
                          {"count", r.count},
                          {"radial_mean_px", r.radial_mean_px},
                          {"radial_median_px", r.radial_median_px},
                          {"tangential_median_px", r.tangential_median_px}});
  }
  return j;
}

std::string FormatTable(const LensResidualReport& report) {
  std::string table = "tracks used: " + std::to_string(report.tracks_used) +
                      "\nradius (px)   observations   radial mean  "
                      "radial median  tangential median (px)\n";
  for (const LensResidualRing& r : report.rings) {
    char line[160];
    std::snprintf(line, sizeof(line),
                  "%4.0f-%-4.0f %14d %13.3f %14.3f %18.3f\n", r.min_radius_px,
                  r.max_radius_px, r.count, r.radial_mean_px,
                  r.radial_median_px, r.tangential_median_px);
    table += line;
  }
  return table;
}

nlohmann::json ToJson(const StructureAccuracyOptions& o) {
  return {{"max_match_angle_deg", o.max_match_angle_deg},
          {"max_match_offset_m", o.max_match_offset_m},
          {"polygon_margin_m", o.polygon_margin_m},
          {"min_observed_landmarks", o.min_observed_landmarks},
          {"observed_distance_m", o.observed_distance_m},
          {"coverage",
           {{"sample_spacing_m", o.coverage.sample_spacing_m},
            {"max_views", o.coverage.max_views},
            {"max_angle_deg", o.coverage.max_angle_deg},
            {"max_distance_m", o.coverage.max_distance_m},
            {"large_plane_area_m2", o.coverage.large_plane_area_m2}}}};
}

}  // namespace monomap
