// The report page: the static template (web/report.html, .css, .js) with
// three.js, its GLTFLoader and OrbitControls and Chart.js inlined, and the
// report data (report_data.h) as a JSON script element. The page needs no
// network and no other file; everything it draws, it draws from the data.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "monomap/report/report_data.h"

namespace monomap {

// An embedded file of the page by name ("report.html", "report.css",
// "report.js", "three.js", "GLTFLoader.js", "OrbitControls.js",
// "chart.js"); empty if unknown. Defined by the generated
// report_assets.cc.
std::string_view ReportAsset(std::string_view name);

// The page for `data`.
std::string RenderReportHtml(const nlohmann::json& data);

// Writes the page (atomically). Throws OutputError on failure.
void WriteReportHtml(const std::filesystem::path& path,
                     const nlohmann::json& data);

// Gathers the report, writes the page and (if json_path is not empty) the
// data as JSON without the embedded files (keys *_base64), and returns the
// problems found in the inputs. The page is written even if there are
// problems.
std::vector<ReportProblem> WriteReport(
    const ReportInputs& inputs, const std::filesystem::path& html_path,
    const std::filesystem::path& json_path = {},
    const ReportOptions& options = {});

// What exe/ reports after WriteReport found problems: throws InputError
// naming the files (exit status 1), or returns if there are none.
void ThrowIfProblems(const std::vector<ReportProblem>& problems,
                     const std::filesystem::path& html_path);

}  // namespace monomap
