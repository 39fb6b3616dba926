#include "monomap/io/camera_mount.h"

#include <cmath>
#include <set>
#include <vector>

#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {
namespace fs = std::filesystem;

namespace {

// Tolerances for hand-typed or printed calibrations (Kalibr prints 8 digits).
constexpr double kOrthonormalTolerance = 1e-4;
constexpr double kUnitQuaternionTolerance = 1e-2;

double Scalar(const fs::path& path, const YAML::Node& node,
              const std::string& field) {
  if (!node || !node.IsScalar()) {
    throw InputError(path.string(), field, "missing or not a number");
  }
  double d = 0;
  try {
    d = node.as<double>();
  } catch (const YAML::Exception&) {
    throw InputError(path.string(), field, "value is not a number");
  }
  if (!std::isfinite(d)) {
    throw InputError(path.string(), field, "value is not finite");
  }
  return d;
}

}  // namespace

std::vector<double> YamlNumbers(const fs::path& path, const YAML::Node& node,
                                const std::string& field, size_t count) {
  if (!node || !node.IsSequence() || node.size() != count) {
    throw InputError(
        path.string(), field,
        "expected a list of " + std::to_string(count) + " numbers");
  }
  std::vector<double> values;
  for (const YAML::Node& v : node) values.push_back(Scalar(path, v, field));
  return values;
}

namespace {

Eigen::Quaterniond QuaternionField(const fs::path& path, const YAML::Node& m,
                                   const std::string& prefix) {
  Eigen::Quaterniond q;
  std::string field;
  if (m["rotation_xyzw"]) {
    field = prefix + ".rotation_xyzw";
    const auto v = YamlNumbers(path, m["rotation_xyzw"], field, 4);
    q = Eigen::Quaterniond(v[3], v[0], v[1], v[2]);
  } else if (m["rotation_wxyz"]) {
    field = prefix + ".rotation_wxyz";
    const auto v = YamlNumbers(path, m["rotation_wxyz"], field, 4);
    q = Eigen::Quaterniond(v[0], v[1], v[2], v[3]);
  } else if (m["rotation"] && m["rotation"].IsMap()) {
    field = prefix + ".rotation";
    double v[4];
    const char* names[4] = {"x", "y", "z", "w"};
    for (int i = 0; i < 4; ++i) {
      v[i] = Scalar(path, m["rotation"][names[i]], field + "." + names[i]);
    }
    q = Eigen::Quaterniond(v[3], v[0], v[1], v[2]);
  } else {
    throw InputError(path.string(), prefix + ".rotation_xyzw",
                     "missing (or rotation_wxyz, or rotation: {x, y, z, w})");
  }
  if (std::abs(q.norm() - 1.0) > kUnitQuaternionTolerance) {
    throw InputError(path.string(), field, "quaternion is not unit length");
  }
  return q.normalized();
}

Rigid3d FromTranslationQuaternion(const fs::path& path, const YAML::Node& m,
                                  const std::string& prefix) {
  static const std::set<std::string> kKnown = {"translation", "rotation_xyzw",
                                               "rotation_wxyz", "rotation"};
  for (const auto& kv : m) {
    const std::string key = kv.first.as<std::string>("");
    if (!kKnown.count(key)) {
      throw InputError(path.string(), prefix + "." + key,
                       "unknown field (expected translation and "
                       "rotation_xyzw, or a 4x4 matrix)");
    }
  }
  const auto t =
      YamlNumbers(path, m["translation"], prefix + ".translation", 3);
  return Rigid3d(QuaternionField(path, m, prefix),
                 Eigen::Vector3d(t[0], t[1], t[2]));
}

Rigid3d FromNode(const fs::path& path, const YAML::Node& node,
                 const std::string& key) {
  if (node.IsSequence() || (node.IsMap() && node["data"])) {
    return ParseRigidMatrix(path, node, key);
  }
  if (node.IsMap()) return FromTranslationQuaternion(path, node, key);
  throw InputError(path.string(), key,
                   "expected {translation, rotation_xyzw} or a 4x4 matrix");
}

}  // namespace

// A 4x4 row-major matrix: a plain list or an OpenCV matrix map.
Rigid3d ParseRigidMatrix(const fs::path& path, const YAML::Node& node,
                         const std::string& field) {
  std::vector<double> m;
  if (node.IsMap()) {
    const int rows = node["rows"] ? node["rows"].as<int>(-1) : -1;
    const int cols = node["cols"] ? node["cols"].as<int>(-1) : -1;
    if (rows != 4 || cols != 4) {
      throw InputError(path.string(), field + ".rows/cols",
                       "expected a 4x4 matrix");
    }
    m = YamlNumbers(path, node["data"], field + ".data", 16);
  } else {
    m = YamlNumbers(path, node, field, 16);
  }
  Eigen::Matrix4d t;
  for (int i = 0; i < 16; ++i) t(i / 4, i % 4) = m[i];
  if ((t.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() >
      1e-9) {
    throw InputError(path.string(), field, "last row must be [0 0 0 1]");
  }
  const Eigen::Matrix3d r = t.topLeftCorner<3, 3>();
  if ((r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() >
          kOrthonormalTolerance ||
      r.determinant() < 0) {
    throw InputError(path.string(), field,
                     "rotation part is not a rotation (orthonormal, det +1)");
  }
  // Project onto SO(3) through the quaternion (removes printing noise).
  return Rigid3d(Eigen::Quaterniond(r), t.topRightCorner<3, 1>());
}

YAML::Node LoadYamlText(const std::string& yaml_text, const fs::path& path) {
  std::string text = yaml_text;
  if (text.rfind("%YAML:", 0) == 0) text = text.substr(text.find('\n') + 1);
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(path.string(), e.mark.line + 1,
                     "malformed YAML: " + e.msg);
  }
}

Rigid3d ParseCameraMount(const std::string& yaml_text, const fs::path& path) {
  const YAML::Node root = LoadYamlText(yaml_text, path);
  if (!root.IsMap()) throw InputError(path.string() + ": not a YAML mapping");
  if (root["base_from_cam"]) {
    return FromNode(path, root["base_from_cam"], "base_from_cam");
  }
  if (root["T_base_cam"]) {
    return ParseRigidMatrix(path, root["T_base_cam"], "T_base_cam");
  }
  if (root["T_cam_base"]) {
    return ParseRigidMatrix(path, root["T_cam_base"], "T_cam_base").Inverse();
  }
  throw InputError(path.string(), "base_from_cam",
                   "missing (expected base_from_cam, T_base_cam or "
                   "T_cam_base)");
}

Rigid3d ReadCameraMount(const fs::path& path) {
  return ParseCameraMount(ReadFileToString(path), path);
}

}  // namespace monomap
