#include "monomap/eval/checkerboard_accuracy.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgproc.hpp>

#include "monomap/util/error.h"

namespace monomap {
namespace {

// A z=0 plane texture at 1000 px/m showing a 10x7-square board whose inner
// corner (0, 0) is at world (0.1, 0.05, 0), seen 180 degrees rotated when
// `flip` (u along -x).
TexturedPlane BoardPlane(bool flip, double shift_m) {
  TexturedPlane p;
  p.plane.normal = Eigen::Vector3d::UnitZ();
  p.pixels_per_meter = 1000.0;
  p.frame.u_axis = Eigen::Vector3d(flip ? -1 : 1, 0, 0);
  p.frame.v_axis = Eigen::Vector3d(0, flip ? -1 : 1, 0);
  p.frame.origin = flip ? Eigen::Vector3d(0.5 + shift_m, 0.35, 0)
                        : Eigen::Vector3d(shift_m, 0, 0);
  p.texture = cv::Mat(350, 500, CV_8UC4, cv::Scalar(255, 255, 255, 255));
  for (int j = -1; j < 6; ++j) {
    for (int i = -1; i < 9; ++i) {
      if ((i + j) % 2 != 0) continue;
      // Square with corners at world (0.1 + 0.04 i, 0.05 + 0.04 j).
      const Eigen::Vector2d a = p.TextureFromWorld(
          {0.1 + 0.04 * i, 0.05 + 0.04 * j, 0}) + Eigen::Vector2d(0.5, 0.5);
      const Eigen::Vector2d b = p.TextureFromWorld(
          {0.1 + 0.04 * (i + 1), 0.05 + 0.04 * (j + 1), 0}) +
          Eigen::Vector2d(0.5, 0.5);
      cv::rectangle(p.texture,
                    cv::Rect(cv::Point(std::lround(std::min(a.x(), b.x())),
                                       std::lround(std::min(a.y(), b.y()))),
                             cv::Point(std::lround(std::max(a.x(), b.x())),
                                       std::lround(std::max(a.y(), b.y())))),
                    cv::Scalar(0, 0, 0, 255), cv::FILLED);
    }
  }
  p.polygon = {{0, 0}, {0.5, 0}, {0.5, 0.35}, {0, 0.35}};
  return p;
}

TEST(Checkerboard, MapsCornersToTheirWorldPositions) {
  CheckerboardSpec spec;
  spec.origin = Eigen::Vector3d(0.1, 0.05, 0);
  for (bool flip : {false, true}) {
    Map map;
    map.planes.push_back(BoardPlane(flip, 0.0));
    const CheckerboardAccuracy acc = EvaluateCheckerboard(map, spec);
    ASSERT_TRUE(acc.found) << "flip " << flip;
    EXPECT_EQ(acc.detector, "findChessboardCorners");
    EXPECT_EQ(acc.corners_found, 54);
    // Exact drawing at 1 mm per texel: sub-texel corners.
    EXPECT_LT(acc.error_m.mean, 0.0005) << flip;
    EXPECT_LT((acc.corners_in_world[0] - spec.Corner(0, 0)).norm(), 0.001);
  }
  // A texture misplaced by 3 mm is measured as 3 mm off.
  Map shifted;
  shifted.planes.push_back(BoardPlane(false, 0.0));
  shifted.planes.back().frame.origin.x() += 0.003;
  const CheckerboardAccuracy acc = EvaluateCheckerboard(shifted, spec);
  ASSERT_TRUE(acc.found);
  EXPECT_NEAR(acc.error_m.mean, 0.003, 0.0006);
  // Its shape is right: one rigid motion takes the 3 mm away.
  EXPECT_LT(acc.shape_error_m.mean, 0.0005);
  // ... and comes back once the map is moved into the truth's frame.
  Sim3d truth_from_map;
  truth_from_map.rigid.translation = Eigen::Vector3d(-0.003, 0.0, 0.0);
  const CheckerboardAccuracy aligned =
      EvaluateCheckerboard(shifted, spec, truth_from_map);
  ASSERT_TRUE(aligned.found);
  EXPECT_LT(aligned.error_m.mean, 0.0005);
  // A scale: a map 2 % small, scaled back.
  Map small;
  small.planes.push_back(BoardPlane(false, 0.0));
  TexturedPlane& p = small.planes.back();
  p.frame.origin *= 0.98;
  p.pixels_per_meter /= 0.98;
  Sim3d grow;
  grow.scale = 1.0 / 0.98;
  EXPECT_GT(EvaluateCheckerboard(small, spec).error_m.mean, 0.002);
  // A wrong scale is a wrong shape: no rigid motion removes it.
  EXPECT_GT(EvaluateCheckerboard(small, spec).shape_error_m.mean, 0.001);
  EXPECT_LT(EvaluateCheckerboard(small, spec, grow).error_m.mean, 0.0005);
}

// Black surroundings right up to the board's outer squares (no quiet zone)
// defeat the classic detector; the sector-based fallback still finds the
// board, with the same accuracy.
TEST(Checkerboard, FindsBoardWithoutQuietZone) {
  CheckerboardSpec spec;
  spec.origin = Eigen::Vector3d(0.1, 0.05, 0);
  Map map;
  map.planes.push_back(BoardPlane(false, 0.0));
  cv::Mat& t = map.planes.back().texture;
  // The board (outer squares included) spans world x 0.06-0.46, y 0.01-0.29,
  // texels 60-460 x 10-290 at 1000 px/m.
  cv::Mat outside(t.size(), CV_8UC1, cv::Scalar(255));
  outside(cv::Rect(60, 10, 400, 280)).setTo(0);
  t.setTo(cv::Scalar(0, 0, 0, 255), outside);
  const CheckerboardAccuracy acc = EvaluateCheckerboard(map, spec);
  ASSERT_TRUE(acc.found);
  EXPECT_EQ(acc.detector, "findChessboardCornersSB");
  EXPECT_EQ(acc.corners_found, 54);
  EXPECT_LT(acc.error_m.mean, 0.0005);
}

TEST(Checkerboard, NotFoundInPlainTexture) {
  Map map;
  TexturedPlane p = BoardPlane(false, 0);
  p.texture.setTo(cv::Scalar(128, 128, 128, 255));
  map.planes.push_back(p);
  EXPECT_FALSE(EvaluateCheckerboard(map, CheckerboardSpec{}).found);
}

TEST(Checkerboard, YamlOfTheWrongKindNamesTheField) {
  // Each was an unwrapped yaml-cpp error (an internal error) before.
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() /
      ("monomap_checkerboard_" + std::to_string(::getpid()) + ".yaml");
  for (const std::string text :
       {"just a scalar\n", "- a\n- list\n", "chessboard: 3\n",
        "chessboard: [1, 2]\n", "chessboard:\n  inner_corners_x: [1]\n"}) {
    std::ofstream(path) << text;
    try {
      ReadCheckerboardYaml(path);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("chessboard"), std::string::npos)
          << e.what();
      EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos)
          << e.what();
    }
  }
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace monomap

namespace monomap {
namespace {

TEST(Checkerboard, OverTheBoardIncludesItsOuterSquaresAtAnyHeight) {
  CheckerboardSpec board;  // 9 x 6 inner corners, 4 cm squares, at z = 0
  board.origin = {0.1, 0.2, 0.0};
  // Inner corners span [0, 8] x [0, 5] squares; the printed board one more.
  EXPECT_TRUE(board.Over(board.origin));
  EXPECT_TRUE(board.Over(board.Corner(8, 5)));
  EXPECT_TRUE(board.Over(board.origin + Eigen::Vector3d(-0.039, -0.039, 0)));
  EXPECT_TRUE(board.Over(board.Corner(9, 6) - Eigen::Vector3d(1e-6, 1e-6, 0)));
  EXPECT_FALSE(board.Over(board.origin + Eigen::Vector3d(-0.041, 0, 0)));
  EXPECT_FALSE(board.Over(board.Corner(4, 6) + Eigen::Vector3d(0, 0.001, 0)));
  // A mug standing on the board is over it; one beside it is not.
  EXPECT_TRUE(board.Over(board.Corner(4, 3) + Eigen::Vector3d(0, 0, -0.1)));
  EXPECT_FALSE(board.Over(board.Corner(12, 3) + Eigen::Vector3d(0, 0, -0.1)));
  // A rotated board: its own axes count, not the world's.
  board.x_axis = Eigen::Vector3d(0, 1, 0);
  board.y_axis = Eigen::Vector3d(-1, 0, 0);
  EXPECT_TRUE(board.Over(board.Corner(8, 5)));
  EXPECT_FALSE(board.Over(board.origin + Eigen::Vector3d(0.1, 0, 0)));
}

}  // namespace
}  // namespace monomap
