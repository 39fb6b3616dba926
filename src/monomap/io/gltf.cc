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

void WriteMapGlb(const std::filesystem::path& path, const Map& map,
                 const GlbOptions& options) {
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "monomap";
  model.buffers.emplace_back();
  std::vector<unsigned char>& bytes = model.buffers[0].data;

  // Appends data to the single buffer as a 4-byte aligned buffer view.
  auto add_view = [&](const void* data, size_t size, int target) {
    bytes.resize((bytes.size() + 3) / 4 * 4, 0);
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = bytes.size();
    view.byteLength = size;
    view.target = target;
    const auto* p = static_cast<const unsigned char*>(data);
    bytes.insert(bytes.end(), p, p + size);
    model.bufferViews.push_back(view);
    return static_cast<int>(model.bufferViews.size()) - 1;
  };
  auto add_accessor = [&](int view, int component_type, int type,
                          size_t count) {
    tinygltf::Accessor accessor;
    accessor.bufferView = view;
    accessor.byteOffset = 0;
    accessor.componentType = component_type;
    accessor.type = type;
    accessor.count = count;
    model.accessors.push_back(accessor);
    return static_cast<int>(model.accessors.size()) - 1;
  };

  tinygltf::Sampler sampler;
  sampler.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
  sampler.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
  sampler.wrapS = TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
  sampler.wrapT = TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
  model.samplers.push_back(sampler);

  // World (z up) to the file's axes.
  auto to_file = [&](const Eigen::Vector3d& x) -> Eigen::Vector3f {
    return options.y_up ? Eigen::Vector3f(x.x(), x.z(), -x.y())
                        : x.cast<float>();
  };

  tinygltf::Scene scene;
  scene.name = "monomap";
  // Adds a mesh of one primitive and a scene node showing it.
  auto add_mesh_node = [&](const std::string& name,
                           const tinygltf::Primitive& primitive) {
    tinygltf::Mesh mesh;
    mesh.name = name;
    mesh.primitives.push_back(primitive);
    model.meshes.push_back(mesh);
    tinygltf::Node node;
    node.name = name;
    node.mesh = static_cast<int>(model.meshes.size()) - 1;
    model.nodes.push_back(node);
    scene.nodes.push_back(static_cast<int>(model.nodes.size()) - 1);
  };
  for (const TexturedPlane& plane : map.planes) {
    if (plane.polygon.size() < 3 || plane.texture.empty() ||
        !(plane.pixels_per_meter > 0)) {
      continue;
    }
    const std::string name = "plane_" + std::to_string(plane.id);
    const size_t n = plane.polygon.size();
    std::vector<float> positions, normals, texcoords;
    std::vector<double> min(3, INFINITY), max(3, -INFINITY);
    const Eigen::Vector3f normal = to_file(plane.plane.normal);
    for (const Eigen::Vector2d& st : plane.polygon) {
      const Eigen::Vector3f x = to_file(plane.frame.ToWorld(st));
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
    const int position_accessor = add_accessor(
        add_view(positions.data(), positions.size() * sizeof(float),
                 TINYGLTF_TARGET_ARRAY_BUFFER),
        TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, n);
    model.accessors[position_accessor].minValues = min;
    model.accessors[position_accessor].maxValues = max;
    primitive.attributes["POSITION"] = position_accessor;
    primitive.attributes["NORMAL"] = add_accessor(
        add_view(normals.data(), normals.size() * sizeof(float),
                 TINYGLTF_TARGET_ARRAY_BUFFER),
        TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, n);
    primitive.attributes["TEXCOORD_0"] = add_accessor(
        add_view(texcoords.data(), texcoords.size() * sizeof(float),
                 TINYGLTF_TARGET_ARRAY_BUFFER),
        TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC2, n);
    primitive.indices = add_accessor(
        add_view(indices.data(), indices.size() * sizeof(uint32_t),
                 TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER),
        TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR,
        indices.size());

    std::vector<uchar> png;
    if (!cv::imencode(".png", plane.texture, png)) {
      throw OutputError(path.string() + ": cannot encode texture of " + name);
    }
    tinygltf::Image image;
    image.name = name;
    image.mimeType = "image/png";
    image.bufferView = add_view(png.data(), png.size(), 0);
    model.images.push_back(image);

    tinygltf::Texture texture;
    texture.sampler = 0;
    texture.source = static_cast<int>(model.images.size()) - 1;
    model.textures.push_back(texture);

    tinygltf::Material material;
    material.name = name;
    material.pbrMetallicRoughness.baseColorTexture.index =
        static_cast<int>(model.textures.size()) - 1;
    material.pbrMetallicRoughness.metallicFactor = 0.0;
    material.pbrMetallicRoughness.roughnessFactor = 1.0;
    material.doubleSided = true;
    // Alpha 0 marks texels no image saw: cut them out.
    material.alphaMode = "MASK";
    material.alphaCutoff = 0.5;
    model.materials.push_back(material);
    primitive.material = static_cast<int>(model.materials.size()) - 1;

    add_mesh_node(name, primitive);
  }
  // A mesh node of one untextured primitive (camera path, points).
  auto add_node = [&](const std::string& name, int mode,
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
    primitive.attributes["POSITION"] = add_accessor(
        add_view(xyz.data(), xyz.size() * sizeof(Eigen::Vector3f),
                 TINYGLTF_TARGET_ARRAY_BUFFER),
        TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, xyz.size());
    model.accessors.back().minValues = min;
    model.accessors.back().maxValues = max;
    if (!rgb.empty()) {
      primitive.attributes["COLOR_0"] = add_accessor(
          add_view(rgb.data(), rgb.size() * sizeof(Eigen::Vector3f),
                   TINYGLTF_TARGET_ARRAY_BUFFER),
          TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, rgb.size());
    }
    tinygltf::Material material;
    material.name = name;
    material.pbrMetallicRoughness.baseColorFactor =
        rgb.empty() ? std::vector<double>{1.0, 0.2, 0.1, 1.0}
                    : std::vector<double>{1.0, 1.0, 1.0, 1.0};
    material.pbrMetallicRoughness.metallicFactor = 0.0;
    model.materials.push_back(material);
    primitive.material = static_cast<int>(model.materials.size()) - 1;
    add_mesh_node(name, primitive);
  };
  if (options.camera_path) {
    std::vector<Eigen::Vector3f> centres;
    for (const TimedPose& p : map.trajectory) {
      centres.push_back(to_file(p.world_from_cam.translation));
    }
    add_node("camera_path", TINYGLTF_MODE_LINE_STRIP, centres, {});
  }
  if (options.points) {
    std::vector<Eigen::Vector3f> xyz, rgb;
    for (const Landmark& l : map.landmarks) {
      xyz.push_back(to_file(l.x_in_world));
      rgb.push_back(l.color / 255.f);
    }
    add_node("landmarks", TINYGLTF_MODE_POINTS, xyz, rgb);
  }

  if (bytes.empty()) {
    model.buffers.clear();
  } else {
    bytes.resize((bytes.size() + 3) / 4 * 4, 0);
  }
  model.scenes.push_back(scene);
  model.defaultScene = 0;

  tinygltf::TinyGLTF writer;
  std::ostringstream out;
  if (!writer.WriteGltfSceneToStream(&model, out, /*prettyPrint=*/false,
                                     /*writeBinary=*/true)) {
    throw OutputError(path.string() + ": glTF serialization failed");
  }
  WriteFileAtomic(path, out.str());
}

}  // namespace monomap
