#include "monomap/io/gltf.h"

#include <gtest/gtest.h>

#include <cstring>

#include <opencv2/imgproc.hpp>
#include <tiny_gltf.h>

#include "monomap/util/error.h"

namespace monomap {
namespace {
namespace fs = std::filesystem;

double TriangleArea(const Polygon2d& p, const Eigen::Vector3i& t) {
  const Eigen::Vector2d a = p[t[1]] - p[t[0]], b = p[t[2]] - p[t[0]];
  return 0.5 * (a.x() * b.y() - a.y() * b.x());
}

// Checks n - 2 counter-clockwise triangles covering the polygon's area.
void ExpectTriangulation(const Polygon2d& polygon) {
  const auto triangles = TriangulatePolygon(polygon);
  ASSERT_EQ(triangles.size(), polygon.size() - 2);
  double area = 0;
  for (const auto& t : triangles) {
    EXPECT_GE(TriangleArea(polygon, t), -1e-15);
    area += TriangleArea(polygon, t);
    // Centroid inside: no triangle covers a notch.
    const Eigen::Vector2d c =
        (polygon[t[0]] + polygon[t[1]] + polygon[t[2]]) / 3.0;
    if (TriangleArea(polygon, t) > 1e-12) {
      EXPECT_TRUE(PointInPolygon(polygon, c));
    }
  }
  EXPECT_NEAR(area, std::abs(PolygonArea(polygon)), 1e-12);
}

TEST(GltfTest, TriangulatesConvexAndNonConvexPolygons) {
  ExpectTriangulation({{0, 0}, {1, 0}, {1, 1}, {0, 1}});
  // L shape, both orientations: a fan from vertex 0 would cover the notch.
  Polygon2d l = {{1, 1}, {0.2, 1}, {0.2, 0.2}, {1, 0.2}, {1, 0}, {0, 0},
                 {0, 2}, {1, 2}};
  ExpectTriangulation(l);
  std::reverse(l.begin(), l.end());
  ExpectTriangulation(l);
  // Comb with collinear vertices.
  ExpectTriangulation({{0, 0}, {3, 0}, {3, 1}, {2.5, 1}, {2.5, 0.2}, {2, 0.2},
                       {2, 1}, {1, 1}, {1, 0.5}, {0.5, 0.5}, {0, 0.5}});
  EXPECT_TRUE(TriangulatePolygon({{0, 0}, {1, 0}}).empty());
}

template <typename T>
std::vector<T> AccessorValues(const tinygltf::Model& model, int index,
                              int components) {
  const tinygltf::Accessor& accessor = model.accessors.at(index);
  const tinygltf::BufferView& view = model.bufferViews.at(accessor.bufferView);
  const tinygltf::Buffer& buffer = model.buffers.at(view.buffer);
  std::vector<T> values(accessor.count * components);
  EXPECT_LE(view.byteOffset + accessor.byteOffset + values.size() * sizeof(T),
            buffer.data.size());
  std::memcpy(values.data(),
              buffer.data.data() + view.byteOffset + accessor.byteOffset,
              values.size() * sizeof(T));
  return values;
}

// Two textured planes: a rectangle on z = 0 and an L-shaped hexagon on a
// tilted plane, with random textures.
Map TwoTexturedPlanes() {
  Map map;
  for (int i = 0; i < 2; ++i) {
    TexturedPlane p;
    p.id = 4 + i;
    p.plane.normal = i == 0 ? Eigen::Vector3d::UnitZ()
                            : Eigen::Vector3d(0.3, -1, 0.2).normalized();
    p.plane.offset = i == 0 ? 0.0 : 1.5;
    p.frame = MakePlaneFrame(p.plane, {1, 2, 3}, {1, 0, 0});
    p.pixels_per_meter = 50 + 25 * i;
    p.texture = cv::Mat(20 + i, 30 - i, CV_8UC4);
    cv::randu(p.texture, 0, 256);
    p.polygon = i == 0 ? Polygon2d{{0, 0}, {0.6, 0}, {0.6, 0.4}, {0, 0.4}}
                       : Polygon2d{{0, 0}, {0.3, 0}, {0.3, 0.1}, {0.1, 0.1},
                                   {0.1, 0.25}, {0, 0.25}};
    map.planes.push_back(p);
  }
  return map;
}

// The primitive's material: double-sided, with the plane's texture
// embedded as a PNG that decodes to it exactly.
void ExpectEmbeddedTexture(const tinygltf::Model& model,
                           const tinygltf::Primitive& primitive,
                           const TexturedPlane& plane) {
  const tinygltf::Material& material = model.materials.at(primitive.material);
  EXPECT_TRUE(material.doubleSided);
  const int texture = material.pbrMetallicRoughness.baseColorTexture.index;
  const tinygltf::Image& image =
      model.images.at(model.textures.at(texture).source);
  EXPECT_EQ(image.mimeType, "image/png");
  EXPECT_GE(image.bufferView, 0);  // embedded, not a file
  // tinygltf decodes the PNG to RGBA: must be the BGRA texture exactly.
  ASSERT_EQ(image.width, plane.texture.cols);
  ASSERT_EQ(image.height, plane.texture.rows);
  ASSERT_EQ(image.component, 4);
  cv::Mat rgba(image.height, image.width, CV_8UC4,
               const_cast<unsigned char*>(image.image.data()));
  cv::Mat bgra;
  cv::cvtColor(rgba, bgra, cv::COLOR_RGBA2BGRA);
  EXPECT_EQ(cv::norm(bgra, plane.texture, cv::NORM_INF), 0.0);
}

// The primitive's vertices are the polygon corners in the world, its
// texture coordinates follow the texel centre convention, and its indices
// triangulate the polygon.
void ExpectPlaneGeometry(const tinygltf::Model& model,
                         const tinygltf::Primitive& primitive,
                         const TexturedPlane& plane) {
  const size_t n = plane.polygon.size();
  const auto positions =
      AccessorValues<float>(model, primitive.attributes.at("POSITION"), 3);
  const auto texcoords =
      AccessorValues<float>(model, primitive.attributes.at("TEXCOORD_0"), 2);
  const auto indices = AccessorValues<uint32_t>(model, primitive.indices, 1);
  ASSERT_EQ(positions.size(), 3 * n);
  ASSERT_EQ(texcoords.size(), 2 * n);
  EXPECT_EQ(indices.size(), 3 * (n - 2));
  double max_position_error = 0, max_uv_error = 0;
  for (size_t k = 0; k < n; ++k) {
    const Eigen::Vector3d x = plane.frame.ToWorld(plane.polygon[k]);
    max_position_error =
        std::max(max_position_error,
                 (Eigen::Vector3d(positions[3 * k], positions[3 * k + 1],
                                  positions[3 * k + 2]) -
                  x)
                     .norm());
    EXPECT_LT(std::abs(plane.plane.SignedDistance(x)), 1e-12);
    // The texel centre convention: pixel (c, r) centre at uv
    // ((c + 0.5) / width, (r + 0.5) / height).
    const Eigen::Vector2d px = plane.TextureFromWorld(x);
    const Eigen::Vector2d uv((px.x() + 0.5) / plane.texture.cols,
                             (px.y() + 0.5) / plane.texture.rows);
    max_uv_error = std::max(
        max_uv_error,
        (Eigen::Vector2d(texcoords[2 * k], texcoords[2 * k + 1]) - uv).norm());
  }
  EXPECT_LT(max_position_error, 1e-6);
  EXPECT_LT(max_uv_error, 1e-6);
  for (uint32_t index : indices) EXPECT_LT(index, n);
}

TEST(GltfTest, GlbRoundTripsThroughTinyGltf) {
  const Map map = TwoTexturedPlanes();
  const fs::path path = fs::temp_directory_path() / "monomap_gltf_test.glb";
  WriteMapGlb(path, map);

  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string error, warning;
  ASSERT_TRUE(loader.LoadBinaryFromFile(&model, &error, &warning, path.string()))
      << error;
  EXPECT_TRUE(error.empty()) << error;
  EXPECT_EQ(model.asset.version, "2.0");
  ASSERT_EQ(model.scenes.size(), 1u);
  EXPECT_EQ(model.scenes[0].nodes.size(), 2u);
  ASSERT_EQ(model.nodes.size(), 2u);
  ASSERT_EQ(model.meshes.size(), 2u);
  ASSERT_EQ(model.materials.size(), 2u);
  ASSERT_EQ(model.textures.size(), 2u);
  ASSERT_EQ(model.images.size(), 2u);
  ASSERT_EQ(model.buffers.size(), 1u);

  for (int i = 0; i < 2; ++i) {
    SCOPED_TRACE("plane " + std::to_string(i));
    const TexturedPlane& plane = map.planes[i];
    const tinygltf::Node& node = model.nodes[i];
    EXPECT_EQ(node.name, "plane_" + std::to_string(plane.id));
    const tinygltf::Primitive& primitive = model.meshes.at(node.mesh).primitives.at(0);
    EXPECT_EQ(primitive.mode, TINYGLTF_MODE_TRIANGLES);
    ExpectEmbeddedTexture(model, primitive, plane);
    ExpectPlaneGeometry(model, primitive, plane);
  }
}

// The node of this name, or nullptr.
const tinygltf::Node* FindNode(const tinygltf::Model& model,
                               const std::string& name) {
  for (const tinygltf::Node& n : model.nodes) {
    if (n.name == name) return &n;
  }
  return nullptr;
}

// A 1 x 1 m wall on y = 2, a camera path of 5 poses and 7 coloured
// landmarks.
Map WallPathAndLandmarks() {
  Map map;
  TexturedPlane wall;
  wall.id = 0;
  wall.plane.normal = Eigen::Vector3d::UnitY();
  wall.plane.offset = -2.0;  // y = 2
  wall.frame = MakePlaneFrame(wall.plane, {0, 2, 0}, {1, 0, 0});
  wall.pixels_per_meter = 10;
  wall.texture = cv::Mat(10, 10, CV_8UC4, cv::Scalar(1, 2, 3, 255));
  wall.polygon = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  map.planes.push_back(wall);
  for (int i = 0; i < 5; ++i) {
    map.trajectory.push_back(
        {0.1 * i, Rigid3d(Eigen::Quaterniond::Identity(),
                          Eigen::Vector3d(0.5 * i, -0.1 * i, 0.3))});
  }
  for (int i = 0; i < 7; ++i) {
    Landmark l;
    l.id = i;
    l.x_in_world = {0.1 * i, 2.0, 1.0 + 0.05 * i};
    l.color = {255.f, 51.f * (i % 5), 0.f};
    map.landmarks.push_back(l);
  }
  return map;
}

// World (x, y, z) as stored in the file: (x, z, -y) if Y is up.
Eigen::Vector3d Stored(const Eigen::Vector3d& x, bool y_up) {
  return y_up ? Eigen::Vector3d(x.x(), x.z(), -x.y()) : x;
}

// Largest distance of the float triples xyz from the expected points.
double MaxPointError(const std::vector<float>& xyz,
                     const std::vector<Eigen::Vector3d>& expected) {
  double max_error = 0;
  for (size_t i = 0; i < expected.size(); ++i) {
    max_error =
        std::max(max_error,
                 (Eigen::Vector3d(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]) -
                  expected[i])
                     .norm());
  }
  return max_error;
}

// Node "camera_path": a LINE_STRIP through the trajectory's centres.
void ExpectCameraPath(const tinygltf::Model& model, const Map& map, bool y_up) {
  const tinygltf::Node* path_node = FindNode(model, "camera_path");
  ASSERT_NE(path_node, nullptr);
  const tinygltf::Primitive& line =
      model.meshes.at(path_node->mesh).primitives.at(0);
  EXPECT_EQ(line.mode, TINYGLTF_MODE_LINE_STRIP);
  const auto centres =
      AccessorValues<float>(model, line.attributes.at("POSITION"), 3);
  ASSERT_EQ(centres.size(), 3 * map.trajectory.size());
  std::vector<Eigen::Vector3d> expected;
  for (const TimedPose& p : map.trajectory) {
    expected.push_back(Stored(p.world_from_cam.translation, y_up));
  }
  EXPECT_LT(MaxPointError(centres, expected), 1e-6);
}

// Node "landmarks": POINTS at the landmarks with their colours / 255.
void ExpectLandmarkPoints(const tinygltf::Model& model, const Map& map,
                          bool y_up) {
  const tinygltf::Node* points_node = FindNode(model, "landmarks");
  ASSERT_NE(points_node, nullptr);
  const tinygltf::Primitive& points =
      model.meshes.at(points_node->mesh).primitives.at(0);
  EXPECT_EQ(points.mode, TINYGLTF_MODE_POINTS);
  const auto xyz =
      AccessorValues<float>(model, points.attributes.at("POSITION"), 3);
  const auto rgb =
      AccessorValues<float>(model, points.attributes.at("COLOR_0"), 3);
  ASSERT_EQ(xyz.size(), 3 * map.landmarks.size());
  ASSERT_EQ(rgb.size(), 3 * map.landmarks.size());
  std::vector<Eigen::Vector3d> expected;
  double max_color_error = 0;
  for (size_t i = 0; i < map.landmarks.size(); ++i) {
    expected.push_back(Stored(map.landmarks[i].x_in_world, y_up));
    max_color_error = std::max<double>(
        max_color_error,
        (Eigen::Vector3f(rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2]) -
         map.landmarks[i].color / 255.f)
            .norm());
  }
  EXPECT_LT(MaxPointError(xyz, expected), 1e-6);
  EXPECT_LT(max_color_error, 1e-6);
}

TEST(GltfTest, CameraPathPointsAndYUp) {
  const Map map = WallPathAndLandmarks();
  const TexturedPlane& wall = map.planes[0];
  for (bool y_up : {false, true}) {
    SCOPED_TRACE(y_up ? "y up" : "z up");
    const fs::path path = fs::temp_directory_path() / "monomap_gltf_extras.glb";
    WriteMapGlb(path, map, {.camera_path = true, .points = true, .y_up = y_up});
    tinygltf::TinyGLTF loader;
    tinygltf::Model model;
    std::string error, warning;
    ASSERT_TRUE(
        loader.LoadBinaryFromFile(&model, &error, &warning, path.string()))
        << error;
    EXPECT_EQ(model.scenes.at(0).nodes.size(), 3u);
    ExpectCameraPath(model, map, y_up);
    ExpectLandmarkPoints(model, map, y_up);

    // The wall's corners and normal in the file's axes.
    const tinygltf::Primitive& quad =
        model.meshes.at(FindNode(model, "plane_0")->mesh).primitives.at(0);
    const auto corners =
        AccessorValues<float>(model, quad.attributes.at("POSITION"), 3);
    const auto normals =
        AccessorValues<float>(model, quad.attributes.at("NORMAL"), 3);
    ASSERT_EQ(corners.size(), 12u);
    double max_error = 0;
    for (size_t k = 0; k < 4; ++k) {
      const Eigen::Vector3d c(corners[3 * k], corners[3 * k + 1],
                              corners[3 * k + 2]);
      const Eigen::Vector3d n(normals[3 * k], normals[3 * k + 1],
                              normals[3 * k + 2]);
      max_error = std::max(
          {max_error,
           (c - Stored(wall.frame.ToWorld(wall.polygon[k]), y_up)).norm(),
           (n - Stored(Eigen::Vector3d::UnitY(), y_up)).norm()});
    }
    EXPECT_LT(max_error, 1e-6);
  }
}

TEST(GltfTest, EmptyMapIsAValidGlb) {
  const fs::path path = fs::temp_directory_path() / "monomap_gltf_empty.glb";
  WriteMapGlb(path, Map());
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string error, warning;
  EXPECT_TRUE(loader.LoadBinaryFromFile(&model, &error, &warning, path.string()))
      << error;
  EXPECT_TRUE(model.nodes.empty());
}

}  // namespace
}  // namespace monomap
