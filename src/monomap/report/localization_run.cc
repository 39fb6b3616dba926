#include "monomap/report/localization_run.h"

#include <algorithm>
#include <map>
#include <random>
#include <sstream>

#include "monomap/io/trajectory_io.h"
#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {
namespace {

// localize --particles-out: "step,x,y,z,qx,qy,qz,qw,log_weight" rows.
std::vector<std::vector<Eigen::Vector3d>> ReadParticlesCsv(
    const std::filesystem::path& path) {
  std::vector<std::vector<Eigen::Vector3d>> steps;
  bool header = true;
  for (const TextLine& line : ReadDataLines(path)) {
    if (header) {  // the column names
      header = false;
      if (line.text.rfind("step,", 0) == 0) continue;
    }
    std::vector<double> v;
    std::stringstream fields(line.text);
    std::string field;
    while (std::getline(fields, field, ',')) {
      double x = 0;
      if (!ParseDouble(field, &x)) {
        throw InputError(path.string() + ":" + std::to_string(line.number) +
                         ": not a number: '" + field + "'");
      }
      v.push_back(x);
    }
    if (v.size() != 9 || v[0] < 0 || v[0] != std::floor(v[0])) {
      throw InputError(path.string() + ":" + std::to_string(line.number) +
                       ": expected step,x,y,z,qx,qy,qz,qw,log_weight");
    }
    const size_t step = static_cast<size_t>(v[0]);
    if (step >= steps.size()) steps.resize(step + 1);
    steps[step].emplace_back(v[1], v[2], v[3]);
  }
  return steps;
}

// Runs `read` on `path`, turning its error into a problem.
template <typename F>
void ReadPart(const std::filesystem::path& path, LocalizationRunData* run,
              std::vector<ReportProblem>* problems, F&& read) {
  run->sources.push_back(path.string());
  try {
    if (!std::filesystem::is_regular_file(path)) {
      throw InputError("missing");
    }
    read(path);
  } catch (const Error& e) {
    problems->push_back({path.string(), e.what()});
  } catch (const std::exception& e) {  // nlohmann::json parse errors
    problems->push_back({path.string(), e.what()});
  }
}

}  // namespace

LocalizationRunData ReadLocalizationRun(const std::string& spec,
                                        std::vector<ReportProblem>* problems) {
  LocalizationRunData run;
  std::filesystem::path trajectory, report, particles, groundtruth;
  if (std::filesystem::is_directory(spec)) {
    const std::filesystem::path dir = spec;
    run.name = std::filesystem::path(spec).lexically_normal().filename();
    if (run.name.empty()) run.name = dir.parent_path().filename();
    trajectory = dir / "trajectory.txt";
    for (const char* name :
         {"report.json", "particles.csv", "groundtruth.txt"}) {
      if (!std::filesystem::exists(dir / name)) continue;
      const std::string n = name;
      (n == "report.json"     ? report
       : n == "particles.csv" ? particles
                              : groundtruth) = dir / name;
    }
  } else {
    std::stringstream list(spec);
    std::string file;
    while (std::getline(list, file, ',')) {
      const std::filesystem::path p = file;
      const std::string ext = p.extension().string();
      if (ext == ".json") {
        report = p;
      } else if (ext == ".csv") {
        particles = p;
      } else if (trajectory.empty()) {
        trajectory = p;
      } else {
        groundtruth = p;
      }
    }
    run.name = trajectory.stem().string();
  }
  if (trajectory.empty()) {
    problems->push_back({spec, "no trajectory (.txt) among the files"});
  } else {
    ReadPart(trajectory, &run, problems,
             [&](const auto& p) { run.trajectory = ReadTumTrajectory(p); });
  }
  if (!report.empty()) {
    ReadPart(report, &run, problems, [&](const auto& p) {
      run.report = nlohmann::json::parse(ReadFileToString(p));
    });
  }
  if (!particles.empty()) {
    ReadPart(particles, &run, problems,
             [&](const auto& p) { run.particles = ReadParticlesCsv(p); });
  }
  if (!groundtruth.empty()) {
    ReadPart(groundtruth, &run, problems,
             [&](const auto& p) { run.groundtruth = ReadTumTrajectory(p); });
  }
  return run;
}

std::vector<std::vector<Eigen::Vector3d>> ParticlePositions(
    const std::vector<std::vector<Particle>>& sets, int max_per_step,
    uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<std::vector<Eigen::Vector3d>> out;
  out.reserve(sets.size());
  for (const std::vector<Particle>& set : sets) {
    std::vector<size_t> index(set.size());
    for (size_t i = 0; i < index.size(); ++i) index[i] = i;
    if (static_cast<int>(index.size()) > max_per_step) {
      std::shuffle(index.begin(), index.end(), rng);
      index.resize(max_per_step);
    }
    std::vector<Eigen::Vector3d> xyz;
    xyz.reserve(index.size());
    for (size_t i : index) xyz.push_back(set[i].world_from_cam.translation);
    out.push_back(std::move(xyz));
  }
  return out;
}

}  // namespace monomap
