#include "monomap/report/html_page.h"

#include <string>
#include <utility>
#include <vector>

#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {
namespace {

// JSON inside <script type="application/json">: "</" would end the
// element early; "<\/" is the same string in JSON.
std::string ScriptSafeJson(const nlohmann::json& data) {
  std::string text = data.dump();
  std::string out;
  out.reserve(text.size());
  for (size_t i = 0; i < text.size(); ++i) {
    out += text[i];
    if (text[i] == '<' && i + 1 < text.size() && text[i + 1] == '/') {
      out += '\\';
    }
  }
  return out;
}

std::string AssetOrThrow(std::string_view name) {
  const std::string_view asset = ReportAsset(name);
  if (asset.empty()) {
    throw std::logic_error("report page: asset not embedded: " +
                           std::string(name));
  }
  return std::string(asset);
}

// The data without the embedded files (keys ending in "_base64"): the
// JSON file is for reading figures, the page has the images.
nlohmann::json WithoutBlobs(const nlohmann::json& data) {
  if (data.is_array()) {
    nlohmann::json out = nlohmann::json::array();
    for (const nlohmann::json& v : data) out.push_back(WithoutBlobs(v));
    return out;
  }
  if (!data.is_object()) return data;
  nlohmann::json out = nlohmann::json::object();
  for (const auto& [key, value] : data.items()) {
    const std::string suffix = "_base64";
    if (key.size() >= suffix.size() &&
        key.compare(key.size() - suffix.size(), suffix.size(), suffix) == 0) {
      continue;
    }
    out[key] = WithoutBlobs(value);
  }
  return out;
}

}  // namespace

std::string RenderReportHtml(const nlohmann::json& data) {
  // Each marker of the template is replaced once, scanning the template
  // only (never the inserted text), in the order they appear.
  const std::vector<std::pair<std::string, std::string>> blobs = {
      {"@REPORT_CSS@", AssetOrThrow("report.css")},
      {"@LIB_THREE@", AssetOrThrow("three.js")},
      {"@LIB_GLTF_LOADER@", AssetOrThrow("GLTFLoader.js")},
      {"@LIB_ORBIT_CONTROLS@", AssetOrThrow("OrbitControls.js")},
      {"@LIB_CHART@", AssetOrThrow("chart.js")},
      {"@REPORT_DATA@", ScriptSafeJson(data)},
      {"@REPORT_JS@", AssetOrThrow("report.js")},
  };
  const std::string_view page = ReportAsset("report.html");
  std::string out;
  size_t pos = 0;
  for (const auto& [marker, blob] : blobs) {
    const size_t at = page.find(marker, pos);
    if (at == std::string_view::npos) {
      throw std::logic_error("report page: template lacks " + marker);
    }
    out.append(page.substr(pos, at - pos));
    out += blob;
    pos = at + marker.size();
  }
  out.append(page.substr(pos));
  return out;
}

void WriteReportHtml(const std::filesystem::path& path,
                     const nlohmann::json& data) {
  WriteFileAtomic(path, RenderReportHtml(data));
}

std::vector<ReportProblem> WriteReport(const ReportInputs& inputs,
                                       const std::filesystem::path& html_path,
                                       const std::filesystem::path& json_path,
                                       const ReportOptions& options) {
  ReportData data = BuildReportData(inputs, options);
  // Links to the map files, relative to the page so that they survive
  // moving the output directory as a whole.
  const std::filesystem::path page_dir =
      std::filesystem::absolute(html_path).parent_path();
  for (nlohmann::json& f : data.json["map_files"]) {
    const std::filesystem::path target =
        std::filesystem::absolute(f["path"].get<std::string>());
    f["link"] = target.lexically_relative(page_dir).generic_string();
  }
  WriteReportHtml(html_path, data.json);
  if (!json_path.empty()) {
    WriteFileAtomic(json_path, WithoutBlobs(data.json).dump(1) + "\n");
  }
  return data.problems;
}

void ThrowIfProblems(const std::vector<ReportProblem>& problems,
                     const std::filesystem::path& html_path) {
  if (problems.empty()) return;
  std::string text = "report: " + std::to_string(problems.size()) +
                     " input file(s) missing or unreadable (the page " +
                     html_path.string() + " names them and shows the rest):";
  for (const ReportProblem& p : problems) {
    text += "\n  " + p.file + ": " + p.message;
  }
  throw InputError(text);
}

}  // namespace monomap
