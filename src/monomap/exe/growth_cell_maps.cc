#include "monomap/exe/growth_cell_maps.h"

#include <array>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {
namespace {

struct VerdictStyle {
  const char* name;
  cv::Vec3b bgr;
};

// Indexed by CellVerdict.
const std::array<VerdictStyle, kNumCellVerdicts> kStyles = {{
    {"textured", {0, 200, 0}},
    {"plain", {230, 160, 60}},
    {"inconsistent", {0, 0, 230}},
    {"plain_inconsistent", {200, 0, 160}},
    {"few_views", {70, 70, 70}},
    {"low_parallax", {0, 200, 230}},
    {"along_parallax", {200, 200, 0}},
    {"carved", {150, 150, 150}},
    {"claimed", {60, 30, 110}},
}};

constexpr int kPixelsPerCell = 4;

cv::Mat3b CellImage(const GrowthCellMap& m) {
  const int k = kPixelsPerCell;
  cv::Mat3b image(m.verdict.rows * k, m.verdict.cols * k);
  for (int r = 0; r < m.verdict.rows; ++r) {
    const int y0 = (m.verdict.rows - 1 - r) * k;  // t axis up
    for (int c = 0; c < m.verdict.cols; ++c) {
      cv::Vec3b colour = kStyles.at(m.verdict(r, c)).bgr;
      if (!m.member(r, c)) colour *= 0.4;
      image(cv::Rect(c * k, y0, k, k)).setTo(colour);
      if (m.fitted(r, c)) image(y0, c * k) = cv::Vec3b(255, 255, 255);
    }
  }
  return image;
}

nlohmann::json CellCounts(const PlaneGrowthStats& s) {
  const GrowthCellMap& m = s.cell_map;
  std::array<int, kNumCellVerdicts> all{}, grown{};
  for (int r = 0; r < m.verdict.rows; ++r) {
    for (int c = 0; c < m.verdict.cols; ++c) {
      const int v = m.verdict(r, c);
      ++all.at(v);
      if (m.member(r, c) && !m.fitted(r, c)) ++grown.at(v);
    }
  }
  nlohmann::json counts_all, counts_grown;
  for (int v = 0; v < kNumCellVerdicts; ++v) {
    counts_all[kStyles[v].name] = all[v];
    counts_grown[kStyles[v].name] = grown[v];
  }
  return {{"plane_id", s.plane_id}, {"cell_m", s.cell_m},
          {"rows", m.verdict.rows}, {"cols", m.verdict.cols},
          {"image", "plane_" + std::to_string(s.plane_id) + ".png"},
          {"cells", counts_all},    {"grown_cells", counts_grown}};
}

}  // namespace

void WriteGrowthCellMaps(const std::filesystem::path& dir,
                         const PlaneGrowthReport& report) {
  MarkOutputDirectory(dir, "growth-debug");
  nlohmann::json planes = nlohmann::json::array();
  for (const PlaneGrowthStats& s : report.planes) {
    if (s.cell_map.verdict.empty()) continue;
    std::vector<uchar> png;
    if (!cv::imencode(".png", CellImage(s.cell_map), png)) {
      throw OutputError("cannot encode the cell map of plane " +
                        std::to_string(s.plane_id));
    }
    WriteFileAtomic(dir / ("plane_" + std::to_string(s.plane_id) + ".png"),
                    std::string(png.begin(), png.end()));
    planes.push_back(CellCounts(s));
  }
  nlohmann::json legend;
  for (const VerdictStyle& style : kStyles) {
    legend[style.name] = {style.bgr[2], style.bgr[1], style.bgr[0]};  // RGB
  }
  const nlohmann::json out = {{"planes", planes},
                              {"legend_rgb", legend},
                              {"pixels_per_cell", kPixelsPerCell}};
  WriteFileAtomic(dir / "cells.json", out.dump(2) + "\n");
}

}  // namespace monomap
