// Trajectory accuracy: absolute trajectory error (ATE) after an alignment
// and relative pose error (RPE) over a frame delta, in the spirit of the
// TUM RGB-D benchmark tools.
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "monomap/eval/point_accuracy.h"
#include "monomap/geometry/rigid3.h"
#include "monomap/map/map.h"

namespace monomap {

// How the estimate is brought onto the ground truth before ATE.
enum class Alignment {
  kNone,       // compare as is
  kFirstPose,  // rigid transform mapping the first estimated pose onto the
               // first ground-truth pose
  kSE3,        // least-squares rigid transform of the positions (Umeyama)
  kSim3,       // least-squares similarity (rigid + scale) of the positions
  kSim3Poses,  // similarity whose rotation is the mean of the matched
               // orientation differences, then scale and translation by
               // least squares on the positions: determined also for a
               // straight drive, where kSim3 leaves the roll about the
               // line free
  kSE3Poses,   // the same without scale: removes one rigid offset of the
               // estimate's frame (a monocular map's frame is its
               // odometry's) and leaves its scale error in
};

// "none", "first", "se3", "sim3", "sim3-poses" or "se3-poses" -> Alignment.
// Throws OptionsError for another name.
Alignment ParseAlignment(const std::string& name);

struct TrajectoryErrors {
  size_t matched = 0;          // associated pose pairs (ATE) or pose-pair
                               // deltas (RPE)
  ErrorStats translation_m;    // position error (m, in the gt frame)
  ErrorStats rotation_deg;     // rotation angle error (degrees)
  double scale = 1.0;          // estimate->gt scale (Sim3 ATE; else 1)
};

// Index pairs (estimate, ground truth) of poses whose timestamps differ by
// at most max_dt seconds: each estimated pose takes the nearest gt pose;
// a gt pose is used at most once (the first estimate claiming it wins).
// Both inputs must be sorted by timestamp (StageError otherwise).
std::vector<std::pair<size_t, size_t>> AssociateByTimestamp(
    const std::vector<TimedPose>& estimate,
    const std::vector<TimedPose>& groundtruth, double max_dt = 1e-3);

// Similarity transform gt ~ scale * rotation * est + translation.
struct Sim3d {
  Rigid3d rigid;
  double scale = 1.0;
};

// The alignment transform for matched poses. Throws StageError if fewer
// than 2 poses match (3 for kSE3/kSim3), or if the positions are too
// degenerate (collinear) for kSE3/kSim3.
Sim3d AlignTrajectories(const std::vector<TimedPose>& estimate,
                        const std::vector<TimedPose>& groundtruth,
                        Alignment alignment, double max_dt = 1e-3);

// ATE: per matched pose, the position error |T(p_est) - p_gt| and the
// rotation angle between R_align * R_est and R_gt. Throws StageError as
// AlignTrajectories.
TrajectoryErrors AbsoluteTrajectoryError(
    const std::vector<TimedPose>& estimate,
    const std::vector<TimedPose>& groundtruth, Alignment alignment,
    double max_dt = 1e-3);

// RPE: for matched poses i and i + delta_frames (indices into the matched
// sequence), E = (gt_i^-1 gt_j)^-1 (est_i^-1 est_j); errors are |t(E)| and
// the angle of R(E). Needs no alignment (only scale matters). Throws
// OptionsError if delta_frames < 1, StageError if fewer than
// max(2, delta_frames + 1) poses match.
TrajectoryErrors RelativePoseError(const std::vector<TimedPose>& estimate,
                                   const std::vector<TimedPose>& groundtruth,
                                   int delta_frames = 1, double max_dt = 1e-3);

}  // namespace monomap
