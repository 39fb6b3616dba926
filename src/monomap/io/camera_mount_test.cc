#include "monomap/io/camera_mount.h"

#include <gtest/gtest.h>

#include <sstream>

#include "monomap/util/angles.h"
#include "monomap/util/error.h"

namespace monomap {
namespace {

// A mount with a non-trivial rotation: camera looking forward, tilted down
// 20 degrees and yawed 5 degrees, 0.3 m above the base.
Rigid3d TestMount() {
  const Eigen::Quaterniond optical_from_forward =
      Eigen::AngleAxisd(DegToRadMulDiv(5), Eigen::Vector3d::UnitZ()) *
      Eigen::AngleAxisd(-M_PI / 2 - DegToRadMulDiv(20), Eigen::Vector3d::UnitX()) *
      Eigen::AngleAxisd(0.0, Eigen::Vector3d::UnitY());
  return Rigid3d(optical_from_forward, Eigen::Vector3d(0.12, -0.03, 0.31));
}

std::string MatrixList(const Rigid3d& t) {
  const Eigen::Matrix4d m = t.ToMatrix4();
  std::ostringstream out;
  out.precision(10);
  out << "[";
  for (int i = 0; i < 16; ++i) out << (i ? ", " : "") << m(i / 4, i % 4);
  out << "]";
  return out.str();
}

double PoseDifference(const Rigid3d& a, const Rigid3d& b) {
  return (a.translation - b.translation).norm() +
         AngleBetween(a.rotation, b.rotation);
}

std::string ErrorOf(const std::string& yaml) {
  try {
    ParseCameraMount(yaml, "mount.yaml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(CameraMountTest, AllFormsGiveTheSameMount) {
  const Rigid3d m = TestMount();
  const auto& q = m.rotation;
  const auto& t = m.translation;
  std::ostringstream xyzw, wxyz, map_form;
  xyzw.precision(12);
  wxyz.precision(12);
  map_form.precision(12);
  xyzw << "base_from_cam:\n  translation: [" << t.x() << ", " << t.y() << ", "
       << t.z() << "]\n  rotation_xyzw: [" << q.x() << ", " << q.y() << ", "
       << q.z() << ", " << q.w() << "]\n";
  wxyz << "base_from_cam:\n  translation: [" << t.x() << ", " << t.y() << ", "
       << t.z() << "]\n  rotation_wxyz: [" << q.w() << ", " << q.x() << ", "
       << q.y() << ", " << q.z() << "]\n";
  map_form << "base_from_cam:\n  translation: [" << t.x() << ", " << t.y()
           << ", " << t.z() << "]\n  rotation: {x: " << q.x()
           << ", y: " << q.y() << ", z: " << q.z() << ", w: " << q.w() << "}\n";
  const std::vector<std::string> forms = {
      xyzw.str(),
      wxyz.str(),
      map_form.str(),
      "base_from_cam: " + MatrixList(m) + "\n",
      "T_base_cam: " + MatrixList(m) + "\n",
      "T_cam_base: " + MatrixList(m.Inverse()) + "\n",
      "%YAML:1.0\n---\nT_base_cam: !!opencv-matrix\n  rows: 4\n  cols: 4\n"
      "  dt: d\n  data: " +
          MatrixList(m) + "\n",
  };
  for (const std::string& yaml : forms) {
    SCOPED_TRACE(yaml);
    EXPECT_LT(PoseDifference(ParseCameraMount(yaml, "mount.yaml"), m), 1e-8);
  }
}

TEST(CameraMountTest, BadFormsNameTheField) {
  const Rigid3d m = TestMount();
  Eigen::Matrix4d scaled = m.ToMatrix4();
  scaled.topLeftCorner<3, 3>() *= 1.1;
  std::ostringstream scaled_list;
  scaled_list << "[";
  for (int i = 0; i < 16; ++i) {
    scaled_list << (i ? ", " : "") << scaled(i / 4, i % 4);
  }
  scaled_list << "]";

  EXPECT_NE(ErrorOf("T_base_cam: " + scaled_list.str())
                .find("mount.yaml: field 'T_base_cam': rotation part is not"),
            std::string::npos)
      << ErrorOf("T_base_cam: " + scaled_list.str());
  EXPECT_NE(ErrorOf("T_base_cam: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, "
                    "0, 2]")
                .find("last row must be [0 0 0 1]"),
            std::string::npos);
  EXPECT_NE(ErrorOf("T_base_cam: [1, 0, 0]").find("'T_base_cam'"),
            std::string::npos);
  EXPECT_NE(ErrorOf("base_from_cam: {translation: [0, 0, 0], rotation_xyzw: "
                    "[0, 0, 0, 1], scale: 2}")
                .find("'base_from_cam.scale': unknown field"),
            std::string::npos);
  EXPECT_NE(ErrorOf("base_from_cam: {translation: [0, 0, 0], rotation_xyzw: "
                    "[0, 0, 0, 2]}")
                .find("'base_from_cam.rotation_xyzw': quaternion is not unit"),
            std::string::npos);
  EXPECT_NE(ErrorOf("base_from_cam: {translation: [0, 0, 0]}")
                .find("'base_from_cam.rotation_xyzw': missing"),
            std::string::npos);
  EXPECT_NE(ErrorOf("T_imu_cam: [1]").find("'base_from_cam': missing"),
            std::string::npos);
  EXPECT_NE(ErrorOf("base_from_cam: {rows: 3, cols: 3, data: [1]}")
                .find("'base_from_cam.rows/cols'"),
            std::string::npos);
}

}  // namespace
}  // namespace monomap
