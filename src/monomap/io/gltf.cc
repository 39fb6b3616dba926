#include "monomap/io/gltf.h"

#include <cmath>
#include <cstring>
#include <sstream>

#include <opencv2/imgcodecs.hpp>
// Debian's libtinygltf.so (target TinyGLTF::TinyGLTF) holds the
// implementation, so TINYGLTF_IMPLEMENTATION is not defined here.
#include <tiny_gltf.h>

#include "monomap/util/error.h"
#include "monomap/util/file.h"

namespace monomap {

namespace {

double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// p inside or on the boundary of the counter-clockwise triangle abc.
bool InTriangle(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  return Cross(b - a, p - a) >= 0 && Cross(c - b, p - b) >= 0 &&
         Cross(a - c, p - c) >= 0;
}

}  // namespace

std::vector<Eigen::Vector3i> TriangulatePolygon(const Polygon2d& polygon) {
  std::vector<Eigen::Vector3i> triangles;
  const int n = static_cast<int>(polygon.size());
  if (n < 3) return triangles;
  std::vector<int> remaining(n);
  for (int i = 0; i < n; ++i) remaining[i] = i;
  if (PolygonArea(polygon) < 0) {
    std::reverse(remaining.begin(), remaining.end());
  }
  // Scale-aware threshold for "strictly convex".
  Eigen::Vector2d lo, hi;
  PolygonBounds(polygon, &lo, &hi);
  const double eps = 1e-12 * std::max(1e-300, (hi - lo).squaredNorm());

  auto is_ear = [&](size_t k, bool allow_flat) {
    const size_t m = remaining.size();
    const int ia = remaining[(k + m - 1) % m];
    const int ib = remaining[k];
    const int ic = remaining[(k + 1) % m];
    const Eigen::Vector2d &a = polygon[ia], &b = polygon[ib], &c = polygon[ic];
    const double turn = Cross(b - a, c - b);
    if (allow_flat ? turn < -eps : turn <= eps) return false;
    if (allow_flat) return true;  // a flat vertex is clipped unconditionally
    for (int j : remaining) {
      if (j == ia || j == ib || j == ic) continue;
      const Eigen::Vector2d& p = polygon[j];
      if (p == a || p == b || p == c) continue;
      if (InTriangle(p, a, b, c)) return false;
    }
    return true;
  };

  while (remaining.size() > 3) {
    const size_t m = remaining.size();
    size_t ear = m;
    for (int pass = 0; pass < 2 && ear == m; ++pass) {
      for (size_t k = 0; k < m; ++k) {
        if (is_ear(k, pass == 1)) {
          ear = k;
          break;
        }
      }
    }
    if (ear == m) break;  // self-intersecting: close with a fan below
    triangles.emplace_back(remaining[(ear + m - 1) % m], remaining[ear],
                           remaining[(ear + 1) % m]);
    remaining.erase(remaining.begin() + static_cast<std::ptrdiff_t>(ear));
  }
  for (size_t k = 1; k + 1 < remaining.size(); ++k) {
    triangles.emplace_back(remaining[0], remaining[k], remaining[k + 1]);
  }
  return triangles;
}

namespace {

// A glTF model with one binary buffer and one scene, built node by node.
class GlbBuilder {
 public:
  explicit GlbBuilder(bool y_up) : y_up_(y_up) {
    model_.asset.version = "2.0";
    model_.asset.generator = "monomap";
    model_.buffers.emplace_back();
    tinygltf::Sampler sampler;
    sampler.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
    sampler.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
    sampler.wrapS = TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
    sampler.wrapT = TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
    model_.samplers.push_back(sampler);
    scene_.name = "monomap";
  }

  // World (z up) to the file's axes.
  Eigen::Vector3f ToFile(const Eigen::Vector3d& x) const {
    return y_up_ ? Eigen::Vector3f(x.x(), x.z(), -x.y()) : x.cast<float>();
  }

  // A node "plane_<id>": the polygon as triangles with the plane's texture
  // (path names the file in errors). Skips planes with nothing to show.
  void AddTexturedPlane(const TexturedPlane& plane,
                        const std::filesystem::path& path);
  // A mesh node of one untextured primitive (camera path, points).
  void AddUntexturedNode(const std::string& name, int mode,
                         const std::vector<Eigen::Vector3f>& xyz,
                         const std::vector<Eigen::Vector3f>& rgb);
  // The model, its buffer padded to 4 bytes (or dropped if empty).
  tinygltf::Model Finish();

 private:
  std::vector<unsigned char>& bytes() { return model_.buffers[0].data; }
  // Appends data to the single buffer as a 4-byte aligned buffer view.
  int AddView(const void* data, size_t size, int target);
  int AddAccessor(int view, int component_type, int type, size_t count);
  // A float accessor of `count` elements of `type` over a new view of data.
  int AddFloatAccessor(const void* data, size_t count, int type,
                       size_t components);
  // The texture's image, texture and material; returns the material.
  int AddTextureMaterial(const TexturedPlane& plane, const std::string& name,
                         const std::filesystem::path& path);
  // Adds a mesh of one primitive and a scene node showing it.
  void AddMeshNode(const std::string& name,
                   const tinygltf::Primitive& primitive);

  bool y_up_;
  tinygltf::Model model_;
  tinygltf::Scene scene_;
};

int GlbBuilder::AddView(const void* data, size_t size, int target) {
  std::vector<unsigned char>& b = bytes();
  b.resize((b.size() + 3) / 4 * 4, 0);
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = b.size();
  view.byteLength = size;
  view.target = target;
  const auto* p = static_cast<const unsigned char*>(data);
  b.insert(b.end(), p, p + size);
  model_.bufferViews.push_back(view);
  return static_cast<int>(model_.bufferViews.size()) - 1;
}

int GlbBuilder::AddAccessor(int view, int component_type, int type,
                            size_t count) {
  tinygltf::Accessor accessor;
  accessor.bufferView = view;
  accessor.byteOffset = 0;
  accessor.componentType = component_type;
  accessor.type = type;
  accessor.count = count;
  model_.accessors.push_back(accessor);
  return static_cast<int>(model_.accessors.size()) - 1;
}

int GlbBuilder::AddFloatAccessor(const void* data, size_t count, int type,
                                 size_t components) {
  return AddAccessor(AddView(data, count * components * sizeof(float),
                             TINYGLTF_TARGET_ARRAY_BUFFER),
                     TINYGLTF_COMPONENT_TYPE_FLOAT, type, count);
}

void GlbBuilder::AddMeshNode(const std::string& name,
                             const tinygltf::Primitive& primitive) {
  tinygltf::Mesh mesh;
  mesh.name = name;
  mesh.primitives.push_back(primitive);
  model_.meshes.push_back(mesh);
  tinygltf::Node node;
  node.name = name;
  node.mesh = static_cast<int>(model_.meshes.size()) - 1;
  model_.nodes.push_back(node);
  scene_.nodes.push_back(static_cast<int>(model_.nodes.size()) - 1);
}

int GlbBuilder::AddTextureMaterial(const TexturedPlane& plane,
                                   const std::string& name,
                                   const std::filesystem::path& path) {
  std::vector<uchar> png;
  if (!cv::imencode(".png", plane.texture, png)) {
    throw OutputError(path.string() + ": cannot encode texture of " + name);
  }
  tinygltf::Image image;
  image.name = name;
  image.mimeType = "image/png";
  image.bufferView = AddView(png.data(), png.size(), 0);
  model_.images.push_back(image);

  tinygltf::Texture texture;
  texture.sampler = 0;
  texture.source = static_cast<int>(model_.images.size()) - 1;
  model_.textures.push_back(texture);

  tinygltf::Material material;
  material.name = name;
  material.pbrMetallicRoughness.baseColorTexture.index =
      static_cast<int>(model_.textures.size()) - 1;
  material.pbrMetallicRoughness.metallicFactor = 0.0;
  material.pbrMetallicRoughness.roughnessFactor = 1.0;
  material.doubleSided = true;
  // Alpha 0 marks texels no image saw: cut them out.
  material.alphaMode = "MASK";
  material.alphaCutoff = 0.5;
  model_.materials.push_back(material);
  return static_cast<int>(model_.materials.size()) - 1;
}

void GlbBuilder::AddTexturedPlane(const TexturedPlane& plane,
                                  const std::filesystem::path& path) {
  if (plane.polygon.size() < 3 || plane.texture.empty() ||
      !(plane.pixels_per_meter > 0)) {
    return;
  }
  const std::string name = "plane_" + std::to_string(plane.id);
  const size_t n = plane.polygon.size();
  std::vector<float> positions, normals, texcoords;
  std::vector<double> min(3, INFINITY), max(3, -INFINITY);
  const Eigen::Vector3f normal = ToFile(plane.plane.normal);
  for (const Eigen::Vector2d& st : plane.polygon) {
    const Eigen::Vector3f x = ToFile(plane.frame.ToWorld(st));
    for (int k = 0; k < 3; ++k) {
      positions.push_back(x[k]);
      normals.push_back(normal[k]);
      min[k] = std::min<double>(min[k], x[k]);
      max[k] = std::max<double>(max[k], x[k]);
    }
    texcoords.push_back(static_cast<float>(st.x() * plane.pixels_per_meter /
                                           plane.texture.cols));
    texcoords.push_back(static_cast<float>(st.y() * plane.pixels_per_meter /
                                           plane.texture.rows));
  }
  std::vector<uint32_t> indices;
  for (const Eigen::Vector3i& tri : TriangulatePolygon(plane.polygon)) {
    for (int k = 0; k < 3; ++k) indices.push_back(tri[k]);
  }

  tinygltf::Primitive primitive;
  primitive.mode = TINYGLTF_MODE_TRIANGLES;
  const int position_accessor =
      AddFloatAccessor(positions.data(), n, TINYGLTF_TYPE_VEC3, 3);
  model_.accessors[position_accessor].minValues = min;
  model_.accessors[position_accessor].maxValues = max;
  primitive.attributes["POSITION"] = position_accessor;
  primitive.attributes["NORMAL"] =
      AddFloatAccessor(normals.data(), n, TINYGLTF_TYPE_VEC3, 3);
  primitive.attributes["TEXCOORD_0"] =
      AddFloatAccessor(texcoords.data(), n, TINYGLTF_TYPE_VEC2, 2);
  primitive.indices =
      AddAccessor(AddView(indices.data(), indices.size() * sizeof(uint32_t),
                          TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER),
                  TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR,
                  indices.size());
  primitive.material = AddTextureMaterial(plane, name, path);
  AddMeshNode(name, primitive);
}

void GlbBuilder::AddUntexturedNode(const std::string& name, int mode,
                                   const std::vector<Eigen::Vector3f>& xyz,
                                   const std::vector<Eigen::Vector3f>& rgb) {
  if (xyz.empty()) return;
  std::vector<double> min(3, INFINITY), max(3, -INFINITY);
  for (const Eigen::Vector3f& x : xyz) {
    for (int k = 0; k < 3; ++k) {
      min[k] = std::min<double>(min[k], x[k]);
      max[k] = std::max<double>(max[k], x[k]);
    }
  }
  tinygltf::Primitive primitive;
  primitive.mode = mode;
  primitive.attributes["POSITION"] =
      AddFloatAccessor(xyz.data(), xyz.size(), TINYGLTF_TYPE_VEC3, 3);
  model_.accessors.back().minValues = min;
  model_.accessors.back().maxValues = max;
  if (!rgb.empty()) {
    primitive.attributes["COLOR_0"] =
        AddFloatAccessor(rgb.data(), rgb.size(), TINYGLTF_TYPE_VEC3, 3);
  }
  tinygltf::Material material;
  material.name = name;
  material.pbrMetallicRoughness.baseColorFactor =
      rgb.empty() ? std::vector<double>{1.0, 0.2, 0.1, 1.0}
                  : std::vector<double>{1.0, 1.0, 1.0, 1.0};
  material.pbrMetallicRoughness.metallicFactor = 0.0;
  model_.materials.push_back(material);
  primitive.material = static_cast<int>(model_.materials.size()) - 1;
  AddMeshNode(name, primitive);
}

tinygltf::Model GlbBuilder::Finish() {
  if (bytes().empty()) {
    model_.buffers.clear();
  } else {
    bytes().resize((bytes().size() + 3) / 4 * 4, 0);
  }
  model_.scenes.push_back(scene_);
  model_.defaultScene = 0;
  return std::move(model_);
}

}  // namespace

void WriteMapGlb(const std::filesystem::path& path, const Map& map,
                 const GlbOptions& options) {
  GlbBuilder builder(options.y_up);
  for (const TexturedPlane& plane : map.planes) {
    builder.AddTexturedPlane(plane, path);
  }
  if (options.camera_path) {
    std::vector<Eigen::Vector3f> centres;
    for (const TimedPose& p : map.trajectory) {
      centres.push_back(builder.ToFile(p.world_from_cam.translation));
    }
    builder.AddUntexturedNode("camera_path", TINYGLTF_MODE_LINE_STRIP, centres,
                              {});
  }
  if (options.points) {
    std::vector<Eigen::Vector3f> xyz, rgb;
    for (const Landmark& l : map.landmarks) {
      xyz.push_back(builder.ToFile(l.x_in_world));
      rgb.push_back(l.color / 255.f);
    }
    builder.AddUntexturedNode("landmarks", TINYGLTF_MODE_POINTS, xyz, rgb);
  }
  tinygltf::Model model = builder.Finish();

  tinygltf::TinyGLTF writer;
  std::ostringstream out;
  if (!writer.WriteGltfSceneToStream(&model, out, /*prettyPrint=*/false,
                                     /*writeBinary=*/true)) {
    throw OutputError(path.string() + ": glTF serialization failed");
  }
  WriteFileAtomic(path, out.str());
}

}  // namespace monomap
