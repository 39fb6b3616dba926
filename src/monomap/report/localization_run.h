// Reading a localization run for the report: what `monomap localize`
// writes (-o TRAJ.txt, --report R.json, --particles-out P.csv).
#pragma once

#include <string>
#include <vector>

#include "monomap/localization/particle_filter.h"
#include "monomap/report/report_data.h"

namespace monomap {

// `spec` is a run directory (trajectory.txt, and if present report.json,
// particles.csv, groundtruth.txt) or a comma-separated list of files told
// apart by extension: .txt the estimate (TUM), .json localize's report,
// .csv the particles; a second .txt is the ground truth (TUM, map frame).
// Files that are missing or malformed become problems; the run keeps what
// could be read.
LocalizationRunData ReadLocalizationRun(const std::string& spec,
                                        std::vector<ReportProblem>* problems);

// Camera positions of the particle sets, at most `max_per_step` per step
// (a seeded random subset, so the page stays small and deterministic).
std::vector<std::vector<Eigen::Vector3d>> ParticlePositions(
    const std::vector<std::vector<Particle>>& sets, int max_per_step,
    uint64_t seed = 1);

}  // namespace monomap
