#include "monomap/io/trajectory_io.h"

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {

namespace {

bool ParsePoseTokens(const std::vector<std::string>& tokens, size_t first,
                     Rigid3d* pose, std::string* why) {
  double v[7];
  for (int i = 0; i < 7; ++i) {
    if (!ParseDouble(tokens[first + i], &v[i])) {
      *why = "value '" + tokens[first + i] + "' is not a finite number";
      return false;
    }
  }
  const Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
  const double norm = q.norm();
  if (norm < 1e-6) {
    *why = "quaternion has zero length";
    return false;
  }
  if (std::abs(norm - 1.0) > 1e-2) {
    *why = "quaternion is not unit length (norm " + std::to_string(norm) + ")";
    return false;
  }
  *pose = Rigid3d(q.normalized(), Eigen::Vector3d(v[0], v[1], v[2]));
  return true;
}

}  // namespace

std::vector<TimedPose> ReadTumTrajectory(const std::filesystem::path& path,
                                         std::vector<int>* line_numbers) {
  std::vector<TimedPose> poses;
  if (line_numbers != nullptr) line_numbers->clear();
  for (const TextLine& line : ReadDataLines(path)) {
    const auto tokens = SplitWhitespace(line.text);
    if (tokens.size() != 8) {
      throw InputError(path.string(), line.number,
                       "expected 8 values 'timestamp tx ty tz qx qy qz qw', "
                       "got " + std::to_string(tokens.size()));
    }
    TimedPose p;
    if (!ParseDouble(tokens[0], &p.timestamp)) {
      throw InputError(path.string(), line.number,
                       "timestamp '" + tokens[0] + "' is not a number");
    }
    std::string why;
    if (!ParsePoseTokens(tokens, 1, &p.world_from_cam, &why)) {
      throw InputError(path.string(), line.number, why);
    }
    if (!poses.empty() && p.timestamp <= poses.back().timestamp) {
      throw InputError(path.string(), line.number,
                       "timestamp " + tokens[0] + " does not increase");
    }
    poses.push_back(p);
    if (line_numbers != nullptr) line_numbers->push_back(line.number);
  }
  if (poses.empty()) {
    throw InputError(path.string() + ": no poses in trajectory file");
  }
  return poses;
}

std::string FormatTumTrajectory(const std::vector<TimedPose>& poses,
                                const std::string& comment) {
  std::ostringstream out;
  if (!comment.empty()) out << "# " << comment << "\n";
  out << "# timestamp tx ty tz qx qy qz qw  (T_world_cam: camera-to-world)\n";
  char buf[256];
  for (const auto& p : poses) {
    Eigen::Quaterniond q = p.world_from_cam.rotation.normalized();
    if (q.w() < 0) q.coeffs() *= -1.0;
    const auto& t = p.world_from_cam.translation;
    std::snprintf(buf, sizeof(buf),
                  "%.6f %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n", p.timestamp,
                  t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
    out << buf;
  }
  return out.str();
}

void WriteTumTrajectory(const std::filesystem::path& path,
                        const std::vector<TimedPose>& poses,
                        const std::string& comment) {
  WriteFileAtomic(path, FormatTumTrajectory(poses, comment));
}

Rigid3d ParsePose(const std::string& text, const std::string& what) {
  const auto tokens = SplitWhitespace(text);
  if (tokens.size() != 7) {
    throw InputError(what + ": expected 7 values 'tx ty tz qx qy qz qw', got " +
                     std::to_string(tokens.size()));
  }
  Rigid3d pose;
  std::string why;
  if (!ParsePoseTokens(tokens, 0, &pose, &why)) {
    throw InputError(what + ": " + why);
  }
  return pose;
}

bool InterpolatePose(const std::vector<TimedPose>& poses, double t,
                     double max_gap, Rigid3d* pose) {
  if (poses.empty()) return false;
  constexpr double kEps = 1e-6;  // timestamps printed with 6 decimals
  auto it = std::lower_bound(
      poses.begin(), poses.end(), t,
      [](const TimedPose& p, double time) { return p.timestamp < time; });
  if (it != poses.end() && std::abs(it->timestamp - t) <= kEps) {
    *pose = it->world_from_cam;
    return true;
  }
  if (it != poses.begin() && std::abs(std::prev(it)->timestamp - t) <= kEps) {
    *pose = std::prev(it)->world_from_cam;
    return true;
  }
  if (it == poses.begin() || it == poses.end()) return false;
  const TimedPose& b = *it;
  const TimedPose& a = *std::prev(it);
  if (b.timestamp - a.timestamp > max_gap) return false;
  const double s = (t - a.timestamp) / (b.timestamp - a.timestamp);
  *pose = Interpolate(a.world_from_cam, b.world_from_cam, s);
  return true;
}

}  // namespace monomap
