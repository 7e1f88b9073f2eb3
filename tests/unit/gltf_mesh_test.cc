// The glTF geometry loader of `substratec render` (compiler/tools/mesh): small
// documents built here (buffers as base64 data: URIs) read into world-space
// primitives — attributes decoded, nodes composed, strips and fans made
// triangle lists, normals and tangents generated — every problem a located
// error; the framing camera; the corpus' real .glb assets; and the
// MikkTSpace-style tangent generator alone.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "mesh/gltf_mesh.h"
#include "mesh/mikktspace.h"

namespace substratec::mesh {
// A named namespace: the unit tests are a unity build, and other files have their own helpers.
namespace gltf_mesh_test {

using J = nlohmann::json;
using vec::Vec3;

/// RFC 4648 base64 of `bytes`, padded.
std::string base64(const std::string& bytes) {
  static const char* const kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    std::uint32_t n = static_cast<unsigned char>(bytes[i]) << 16;
    if (i + 1 < bytes.size()) n |= static_cast<unsigned char>(bytes[i + 1]) << 8;
    if (i + 2 < bytes.size()) n |= static_cast<unsigned char>(bytes[i + 2]);
    out += kAlphabet[n >> 18 & 63];
    out += kAlphabet[n >> 12 & 63];
    out += i + 1 < bytes.size() ? kAlphabet[n >> 6 & 63] : '=';
    out += i + 2 < bytes.size() ? kAlphabet[n & 63] : '=';
  }
  return out;
}

/// The bytes of `values` (little-endian: the host's order on every platform we build on).
template <class T>
std::string bytesOf(const std::vector<T>& values) {
  std::string s(values.size() * sizeof(T), '\0');
  if (!values.empty()) std::memcpy(s.data(), values.data(), s.size());
  return s;
}

/// A glTF document under construction: one buffer, which its views point into.
class Gltf {
 public:
  J doc = {{"asset", {{"version", "2.0"}}}, {"scenes", J::array({J::object({{"nodes", J::array()}})})}};
  std::string bin;

  /// Appends `bytes` (4-byte aligned) as a buffer view; its index.
  int view(const std::string& bytes, int stride = 0) {
    while (bin.size() % 4) bin += '\0';
    J v = {{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", bytes.size()}};
    if (stride) v["byteStride"] = stride;
    bin += bytes;
    doc["bufferViews"].push_back(v);
    return static_cast<int>(doc["bufferViews"].size()) - 1;
  }
  /// An accessor over view `v`; its index.
  int accessor(int v, int componentType, const char* type, int count, bool normalized = false, int offset = 0) {
    J a = {{"bufferView", v}, {"componentType", componentType}, {"type", type}, {"count", count}};
    if (normalized) a["normalized"] = true;
    if (offset) a["byteOffset"] = offset;
    doc["accessors"].push_back(a);
    return static_cast<int>(doc["accessors"].size()) - 1;
  }
  /// Floats as a tightly packed accessor of `type` (`components` each); its index.
  int floats(const std::vector<float>& values, const char* type, int components) {
    return accessor(view(bytesOf(values)), 5126, type, static_cast<int>(values.size()) / components);
  }
  /// Unsigned int indices; the accessor's index.
  int indices(const std::vector<std::uint32_t>& values) {
    return accessor(view(bytesOf(values)), 5125, "SCALAR", static_cast<int>(values.size()));
  }
  /// A mesh of one primitive (`primitive`: attributes, indices, mode...) and a
  /// root node of the scene using it, with `node`'s members; the node's index.
  int meshNode(const J& primitive, J node = J::object()) {
    doc["meshes"].push_back({{"primitives", J::array({primitive})}});
    node["mesh"] = doc["meshes"].size() - 1;
    doc["nodes"].push_back(node);
    const int n = static_cast<int>(doc["nodes"].size()) - 1;
    doc["scenes"][0]["nodes"].push_back(n);
    return n;
  }
  /// The document's text, its buffer a data: URI.
  std::string text() {
    J d = doc;
    d["buffers"] = J::array({{{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + base64(bin)}}});
    return d.dump(2);
  }
};

/// Loads `text`; the scene, or nullopt with the diagnostics in `log`.
std::optional<Scene> load(const std::string& text, std::string* log = nullptr, const MeshLimits& limits = {},
                          const std::string& baseDir = ".") {
  Diagnostics d("test.gltf");
  auto scene = loadGltfSceneFromBytes(text, baseDir, limits, d);
  if (log) *log = d.formatAll();
  return scene;
}

/// The diagnostics of loading `text`, which must fail.
std::string loadError(const std::string& text, const MeshLimits& limits = {}, const std::string& baseDir = ".") {
  std::string log;
  EXPECT_FALSE(load(text, &log, limits, baseDir).has_value());
  return log;
}

/// Three floats of vertex `v` of `p` at `offset`.
Vec3 at(const Primitive& p, std::size_t v, int offset) {
  const float* f = p.vertices.data() + v * kVertexFloats + offset;
  return {f[0], f[1], f[2]};
}

/// Float `i` of vertex `v` of `p`.
float floatAt(const Primitive& p, std::size_t v, int i) { return p.vertices[v * kVertexFloats + i]; }

/// Expects `a` within `tol` of `b`, componentwise.
void expectNear(const Vec3& a, const Vec3& b, double tol = 1e-5) {
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(a[i], b[i], tol) << "component " << i;
}

/// The right triangle (0,0,0), (1,0,0), (0,1,0) with TEXCOORD_0 = position.xy (and `extra` attributes).
J triangle(Gltf& g, J extra = J::object()) {
  J attrs = extra;
  attrs["POSITION"] = g.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3", 3);
  attrs["TEXCOORD_0"] = g.floats({0, 0, 1, 0, 0, 1}, "VEC2", 2);
  return {{"attributes", attrs}};
}

/// "[pointer]": how a diagnostic names its JSON pointer.
std::string bracket(const std::string& pointer) { return "[" + pointer + "]"; }

// ---------------------------------------------------------------- reading

TEST(GltfMesh, OneTriangleRoundTripsWithDefaultsAndGeneratedFrame) {
  Gltf g;
  g.meshNode(triangle(g));
  std::string log;
  auto scene = load(g.text(), &log);
  ASSERT_TRUE(scene) << log;
  ASSERT_EQ(scene->primitives.size(), 1u);
  const Primitive& p = scene->primitives[0];
  ASSERT_EQ(p.vertices.size(), 3u * kVertexFloats);
  EXPECT_EQ(p.indices, (std::vector<std::uint32_t>{0, 1, 2}));
  EXPECT_EQ(p.location, "/meshes/0/primitives/0");
  EXPECT_EQ(p.node, "/nodes/0");
  EXPECT_EQ(p.material, -1);
  EXPECT_TRUE(p.generatedNormals);
  EXPECT_TRUE(p.generatedTangents);
  expectNear(at(p, 1, kPositionOffset), {1, 0, 0}, 0);
  expectNear(at(p, 2, kPositionOffset), {0, 1, 0}, 0);
  for (std::size_t v = 0; v < 3; ++v) {
    EXPECT_EQ(floatAt(p, v, kUv0Offset), floatAt(p, v, kPositionOffset));  // uv = position.xy
    EXPECT_EQ(floatAt(p, v, kUv1Offset), 0.0f);
    EXPECT_EQ(floatAt(p, v, kUv1Offset + 1), 0.0f);
    for (int c = 0; c < 4; ++c) EXPECT_EQ(floatAt(p, v, kColorOffset + c), 1.0f);  // white
    const Vec3 n = at(p, v, kNormalOffset), t = at(p, v, kTangentOffset);
    expectNear(n, {0, 0, 1});  // the face's normal
    EXPECT_NEAR(vec::length(t), 1, 1e-6);
    EXPECT_NEAR(vec::dot(n, t), 0, 1e-6);
    expectNear(t, {1, 0, 0});  // along +u
    EXPECT_EQ(floatAt(p, v, kTangentOffset + 3), 1.0f);  // cross(N, T) = +Y = +v
  }
  EXPECT_EQ(scene->vertexCount, 3u);
  EXPECT_EQ(scene->indexCount, 3u);
  expectNear({scene->boundsMin[0], scene->boundsMin[1], scene->boundsMin[2]}, {0, 0, 0}, 0);
  expectNear({scene->boundsMax[0], scene->boundsMax[1], scene->boundsMax[2]}, {1, 1, 0}, 0);
}

TEST(GltfMesh, TangentFollowsUAndItsSignFollowsMirroredV) {
  Gltf g;
  J prim = triangle(g);
  prim["attributes"]["TEXCOORD_0"] = g.floats({0, 0, 0, -1, 1, 0}, "VEC2", 2);  // u = y, v = -x
  g.meshNode(prim);
  auto scene = load(g.text());
  ASSERT_TRUE(scene);
  const Primitive& p = scene->primitives[0];
  for (std::size_t v = 0; v < 3; ++v) {
    expectNear(at(p, v, kTangentOffset), {0, 1, 0});  // dP/du = +Y
    // cross(N, T) = cross(+Z, +Y) = -X = dP/dv: w = +1.
    EXPECT_EQ(floatAt(p, v, kTangentOffset + 3), 1.0f);
  }
  Gltf h;
  J mirrored = triangle(h);
  mirrored["attributes"]["TEXCOORD_0"] = h.floats({0, 0, 0, 1, 1, 0}, "VEC2", 2);  // u = y, v = x
  h.meshNode(mirrored);
  scene = load(h.text());
  ASSERT_TRUE(scene);
  for (std::size_t v = 0; v < 3; ++v) EXPECT_EQ(floatAt(scene->primitives[0], v, kTangentOffset + 3), -1.0f);
}

TEST(GltfMesh, NodeTranslationRotationScaleMovePositionsAndNormals) {
  Gltf g;
  // The plane x + y = 0, its normal (1, 1, 0) / sqrt 2.
  const float s = static_cast<float>(std::sqrt(0.5));
  J attrs = {{"POSITION", g.floats({0, 0, 0, 1, -1, 0, 0, 0, 1}, "VEC3", 3)},
             {"NORMAL", g.floats({s, s, 0, s, s, 0, s, s, 0}, "VEC3", 3)}};
  const double h = std::sqrt(0.5);  // 90 degrees about +Z
  g.meshNode({{"attributes", attrs}},
             {{"translation", {1, 2, 3}}, {"rotation", {0, 0, h, h}}, {"scale", {2, 1, 1}}});
  std::string log;
  auto scene = load(g.text(), &log);
  ASSERT_TRUE(scene) << log;
  const Primitive& p = scene->primitives[0];
  EXPECT_FALSE(p.generatedNormals);
  // (1, -1, 0): scaled (2, -1, 0), rotated (1, 2, 0), translated (2, 4, 3).
  expectNear(at(p, 1, kPositionOffset), {2, 4, 3});
  expectNear(at(p, 2, kPositionOffset), {1, 2, 4});
  const Vec3 p0 = at(p, 0, kPositionOffset);
  for (std::size_t v = 0; v < 3; ++v) {
    const Vec3 n = at(p, v, kNormalOffset);
    EXPECT_NEAR(vec::length(n), 1, 1e-6);
    // Still the world triangle's normal under the non-uniform scale: (1, 2, 0) rotated, over sqrt 5.
    EXPECT_NEAR(vec::dot(n, vec::sub(at(p, 1, kPositionOffset), p0)), 0, 1e-5);
    EXPECT_NEAR(vec::dot(n, vec::sub(at(p, 2, kPositionOffset), p0)), 0, 1e-5);
    expectNear(n, {-2 / std::sqrt(5.0), 1 / std::sqrt(5.0), 0});
  }
}

TEST(GltfMesh, ParentTransformsComposeParentFirst) {
  Gltf g;
  const int child = g.meshNode(triangle(g), {{"translation", {1, 0, 0}}});
  g.doc["scenes"][0]["nodes"] = J::array();
  g.doc["nodes"].push_back({{"children", {child}}, {"scale", {2, 2, 2}}});
  g.doc["scenes"][0]["nodes"].push_back(1);
  auto scene = load(g.text());
  ASSERT_TRUE(scene);
  expectNear(at(scene->primitives[0], 1, kPositionOffset), {4, 0, 0});  // 2 * ((1, 0, 0) + (1, 0, 0))
  EXPECT_EQ(scene->primitives[0].node, "/nodes/0");
}

TEST(GltfMesh, MirroringMatrixFlipsTangentSignAndWinding) {
  Gltf g;
  g.meshNode(triangle(g), {{"matrix", {-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}});
  auto scene = load(g.text());
  ASSERT_TRUE(scene);
  const Primitive& p = scene->primitives[0];
  expectNear(at(p, 1, kPositionOffset), {-1, 0, 0});
  EXPECT_EQ(p.indices, (std::vector<std::uint32_t>{0, 2, 1}));  // still counter-clockwise seen from the normal
  for (std::size_t v = 0; v < 3; ++v) {
    const Vec3 n = at(p, v, kNormalOffset), t = at(p, v, kTangentOffset);
    expectNear(n, {0, 0, 1});
    expectNear(t, {-1, 0, 0});  // M * (+X)
    EXPECT_EQ(floatAt(p, v, kTangentOffset + 3), -1.0f);
    // glTF's bitangent cross(N, T) * w is still M * dP/dv = +Y.
    expectNear(vec::scale(vec::cross(n, t), floatAt(p, v, kTangentOffset + 3)), {0, 1, 0});
  }
}

TEST(GltfMesh, StripsAndFansBecomeTriangleLists) {
  const std::vector<float> quad = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
  const std::vector<float> up = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
  for (int mode : {5, 6}) {
    Gltf g;
    g.meshNode({{"attributes", {{"POSITION", g.floats(quad, "VEC3", 3)}, {"NORMAL", g.floats(up, "VEC3", 3)}}},
                {"mode", mode}});
    auto scene = load(g.text());
    ASSERT_TRUE(scene) << mode;
    const auto want = mode == 5 ? std::vector<std::uint32_t>{0, 1, 2, 1, 3, 2} : std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3};
    EXPECT_EQ(scene->primitives[0].indices, want) << "mode " << mode;
  }
  Gltf fan;
  fan.meshNode({{"attributes", {{"POSITION", fan.floats(quad, "VEC3", 3)}}}, {"indices", fan.indices({0, 1, 3, 2})},
                {"mode", 6}});
  auto scene = load(fan.text());
  ASSERT_TRUE(scene);
  const Primitive& p = scene->primitives[0];  // flat normals: un-indexed
  EXPECT_EQ(p.indices, (std::vector<std::uint32_t>{0, 1, 2, 3, 4, 5}));
  expectNear(at(p, 4, kPositionOffset), {1, 1, 0});
  expectNear(at(p, 5, kPositionOffset), {0, 1, 0});
  for (std::size_t v = 0; v < 6; ++v) expectNear(at(p, v, kNormalOffset), {0, 0, 1});
}

TEST(GltfMesh, NormalizedIntegerTexcoordsAndColoursAreDecoded) {
  Gltf g;
  J prim = triangle(g);
  const std::vector<std::uint8_t> uv = {0, 255, 255, 0, 128, 51};
  prim["attributes"]["TEXCOORD_1"] = g.accessor(g.view(bytesOf(uv)), 5121, "VEC2", 3, true);
  const std::vector<std::uint8_t> rgb = {255, 0, 51, 0, 255, 0, 0, 0, 255};
  prim["attributes"]["COLOR_0"] = g.accessor(g.view(bytesOf(rgb)), 5121, "VEC3", 3, true);
  g.meshNode(prim);
  std::string log;
  auto scene = load(g.text(), &log);
  ASSERT_TRUE(scene) << log;
  const Primitive& p = scene->primitives[0];
  EXPECT_FLOAT_EQ(floatAt(p, 0, kUv1Offset + 1), 1.0f);
  EXPECT_FLOAT_EQ(floatAt(p, 2, kUv1Offset), 128.0f / 255.0f);
  EXPECT_FLOAT_EQ(floatAt(p, 2, kUv1Offset + 1), 0.2f);
  EXPECT_FLOAT_EQ(floatAt(p, 0, kColorOffset + 2), 0.2f);
  EXPECT_FLOAT_EQ(floatAt(p, 1, kColorOffset + 1), 1.0f);
  for (std::size_t v = 0; v < 3; ++v) EXPECT_EQ(floatAt(p, v, kColorOffset + 3), 1.0f);  // VEC3: alpha 1

  Gltf h;
  J rgba = triangle(h);
  const std::vector<std::uint16_t> c16 = {65535, 0, 0, 32768, 0, 65535, 0, 0, 0, 0, 65535, 65535};
  rgba["attributes"]["COLOR_0"] = h.accessor(h.view(bytesOf(c16)), 5123, "VEC4", 3, true);
  h.meshNode(rgba);
  scene = load(h.text(), &log);
  ASSERT_TRUE(scene) << log;
  EXPECT_FLOAT_EQ(floatAt(scene->primitives[0], 0, kColorOffset + 3), 32768.0f / 65535.0f);
  EXPECT_FLOAT_EQ(floatAt(scene->primitives[0], 2, kColorOffset + 3), 1.0f);
}

TEST(GltfMesh, InterleavedBufferViewHonoursByteStride) {
  Gltf g;
  // Per vertex: position (12 bytes), normal (12), uv (8): stride 32.
  const std::vector<float> data = {0, 0, 0, 0, 0, 1, 0, 0,  //
                                   2, 0, 0, 0, 0, 1, 1, 0,  //
                                   0, 2, 0, 0, 0, 1, 0, 1};
  const int v = g.view(bytesOf(data), 32);
  J attrs = {{"POSITION", g.accessor(v, 5126, "VEC3", 3)},
             {"NORMAL", g.accessor(v, 5126, "VEC3", 3, false, 12)},
             {"TEXCOORD_0", g.accessor(v, 5126, "VEC2", 3, false, 24)}};
  g.meshNode({{"attributes", attrs}});
  std::string log;
  auto scene = load(g.text(), &log);
  ASSERT_TRUE(scene) << log;
  const Primitive& p = scene->primitives[0];
  expectNear(at(p, 1, kPositionOffset), {2, 0, 0}, 0);
  expectNear(at(p, 2, kPositionOffset), {0, 2, 0}, 0);
  expectNear(at(p, 2, kNormalOffset), {0, 0, 1}, 0);
  EXPECT_EQ(floatAt(p, 1, kUv0Offset), 1.0f);
  EXPECT_EQ(floatAt(p, 2, kUv0Offset + 1), 1.0f);
  EXPECT_FALSE(p.generatedNormals);
}

TEST(GltfMesh, SparseAccessorsReplaceElements) {
  Gltf g;
  J prim = triangle(g);
  const int indices = g.view(bytesOf(std::vector<std::uint16_t>{2, 0}));
  const int values = g.view(bytesOf(std::vector<float>{0, 3, 0}));
  g.doc["accessors"][0]["sparse"] = {{"count", 1}, {"indices", {{"bufferView", indices}, {"componentType", 5123}}},
                                     {"values", {{"bufferView", values}}}};
  // A colour accessor without a bufferView: zeros, then the sparse values.
  const int colourValues = g.view(bytesOf(std::vector<float>{1, 0.5f, 0.25f}));
  g.doc["accessors"].push_back({{"componentType", 5126}, {"type", "VEC3"}, {"count", 3},
                                {"sparse", {{"count", 1},
                                            {"indices", {{"bufferView", indices}, {"byteOffset", 2}, {"componentType", 5123}}},
                                            {"values", {{"bufferView", colourValues}}}}}});
  prim["attributes"]["COLOR_0"] = g.doc["accessors"].size() - 1;
  g.meshNode(prim);
  std::string log;
  auto scene = load(g.text(), &log);
  ASSERT_TRUE(scene) << log;
  const Primitive& p = scene->primitives[0];
  expectNear(at(p, 2, kPositionOffset), {0, 3, 0}, 0);
  expectNear(at(p, 0, kColorOffset), {1, 0.5, 0.25}, 0);
  expectNear(at(p, 1, kColorOffset), {0, 0, 0}, 0);
}

TEST(GltfMesh, MaterialIndexAndNames) {
  Gltf g;
  J prim = triangle(g);
  prim["material"] = 1;
  g.meshNode(prim);
  g.doc["materials"] = J::array({{{"name", "steel"}}, J::object()});
  auto scene = load(g.text());
  ASSERT_TRUE(scene);
  EXPECT_EQ(scene->primitives[0].material, 1);
  EXPECT_EQ(scene->materialNames, (std::vector<std::string>{"steel", ""}));
}

TEST(GltfMesh, GlbBinaryChunkIsBufferZero) {
  Gltf g;
  g.meshNode(triangle(g));
  J doc = g.doc;
  doc["buffers"] = J::array({{{"byteLength", g.bin.size()}}});
  std::string json = doc.dump(), bin = g.bin;
  while (json.size() % 4) json += ' ';
  while (bin.size() % 4) bin += '\0';
  auto u32 = [](std::uint32_t v) { return bytesOf(std::vector<std::uint32_t>{v}); };
  const std::string glb = "glTF" + u32(2) + u32(static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + bin.size())) +
                          u32(static_cast<std::uint32_t>(json.size())) + "JSON" + json +
                          u32(static_cast<std::uint32_t>(bin.size())) + std::string("BIN\0", 4) + bin;
  std::string log;
  auto scene = load(glb, &log);
  ASSERT_TRUE(scene) << log;
  expectNear(at(scene->primitives[0], 1, kPositionOffset), {1, 0, 0}, 0);
}

TEST(GltfMesh, FileBufferResolvesAgainstTheDocumentPercentDecoded) {
  const std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / "gltf_mesh_test_files";
  std::filesystem::create_directories(dir);
  Gltf g;
  g.meshNode(triangle(g));
  std::ofstream(dir / "tri mesh.bin", std::ios::binary) << g.bin;
  J doc = g.doc;
  doc["buffers"] = J::array({{{"byteLength", g.bin.size()}, {"uri", "tri%20mesh.bin"}}});
  std::ofstream(dir / "tri.gltf") << doc.dump();
  Diagnostics d("tri.gltf");
  auto scene = loadGltfScene((dir / "tri.gltf").string(), {}, d);
  ASSERT_TRUE(scene) << d.formatAll();
  expectNear(at(scene->primitives[0], 2, kPositionOffset), {0, 1, 0}, 0);
}

TEST(GltfMesh, CameraNodesBecomeWorldSpaceCameras) {
  Gltf g;
  g.meshNode(triangle(g));
  g.doc["cameras"] = J::array({{{"type", "perspective"}, {"name", "main"},
                                {"perspective", {{"yfov", 0.5}, {"znear", 0.1}, {"zfar", 100}, {"aspectRatio", 1.5}}}},
                               {{"type", "orthographic"}, {"orthographic", {{"xmag", 1}, {"ymag", 1}, {"znear", 0.1}, {"zfar", 10}}}}});
  const double h = std::sqrt(0.5);  // 90 degrees about +Y: -Z turns to -X
  g.doc["nodes"].push_back({{"camera", 0}, {"translation", {1, 2, 3}}, {"rotation", {0, h, 0, h}}});
  g.doc["nodes"].push_back({{"camera", 1}});
  g.doc["scenes"][0]["nodes"].push_back(1);
  g.doc["scenes"][0]["nodes"].push_back(2);
  Diagnostics d("test.gltf");
  auto scene = loadGltfSceneFromBytes(g.text(), ".", {}, d);
  ASSERT_TRUE(scene) << d.formatAll();
  ASSERT_EQ(scene->cameras.size(), 1u);  // the orthographic one skipped
  const Camera& c = scene->cameras[0];
  EXPECT_EQ(c.name, "main");
  EXPECT_EQ(c.location, "/cameras/0");
  expectNear(c.position, {1, 2, 3});
  expectNear(c.forward, {-1, 0, 0});
  expectNear(c.up, {0, 1, 0});
  EXPECT_DOUBLE_EQ(c.yfov, 0.5);
  EXPECT_DOUBLE_EQ(c.znear, 0.1);
  EXPECT_DOUBLE_EQ(c.zfar, 100);
  EXPECT_DOUBLE_EQ(c.aspectRatio, 1.5);
  EXPECT_FALSE(d.hasErrors());
  EXPECT_NE(d.formatAll().find("warning: an orthographic camera"), std::string::npos) << d.formatAll();
  EXPECT_NE(d.formatAll().find(bracket("/cameras/1")), std::string::npos);
}

TEST(GltfMesh, DefaultSceneIsAllRootNodesWithoutScenes) {
  Gltf g;
  g.meshNode(triangle(g));
  g.doc["nodes"].push_back({{"mesh", 0}, {"translation", {0, 0, 5}}, {"children", {0}}});
  g.doc.erase("scenes");  // node 1 is the one root; node 0 is drawn through it
  auto scene = load(g.text());
  ASSERT_TRUE(scene);
  ASSERT_EQ(scene->primitives.size(), 2u);
  EXPECT_EQ(scene->primitives[0].node, "/nodes/1");
  EXPECT_EQ(scene->primitives[1].node, "/nodes/0");
  expectNear(at(scene->primitives[1], 0, kPositionOffset), {0, 0, 5});
}

// ---------------------------------------------------------------- errors

TEST(GltfMesh, MissingPositionIsALocatedError) {
  Gltf g;
  g.meshNode({{"attributes", {{"NORMAL", g.floats({0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3", 3)}}}});
  const std::string log = loadError(g.text());
  EXPECT_NE(log.find("POSITION"), std::string::npos) << log;
  EXPECT_NE(log.find(bracket("/meshes/0/primitives/0/attributes")), std::string::npos) << log;
}

TEST(GltfMesh, IndexOutOfRangeIsALocatedError) {
  Gltf g;
  J prim = triangle(g);
  prim["indices"] = g.indices({0, 1, 3});
  g.meshNode(prim);
  const std::string log = loadError(g.text());
  EXPECT_NE(log.find("index 3"), std::string::npos) << log;
  EXPECT_NE(log.find(bracket("/meshes/0/primitives/0/indices")), std::string::npos) << log;
}

TEST(GltfMesh, AccessorPastItsBufferViewIsALocatedError) {
  Gltf g;
  J prim = triangle(g);
  g.doc["accessors"][0]["count"] = 4;  // 48 bytes of a 36-byte view
  g.meshNode(prim);
  const std::string log = loadError(g.text());
  EXPECT_NE(log.find("36 bytes"), std::string::npos) << log;
  EXPECT_NE(log.find(bracket("/accessors/0")), std::string::npos) << log;
}

TEST(GltfMesh, BufferViewPastItsBufferIsALocatedError) {
  Gltf g;
  g.meshNode(triangle(g));
  g.doc["bufferViews"][1]["byteLength"] = 1000;
  const std::string log = loadError(g.text());
  EXPECT_NE(log.find(bracket("/bufferViews/1")), std::string::npos) << log;
}

TEST(GltfMesh, LinesArePointedOut) {
  Gltf g;
  J prim = triangle(g);
  prim["mode"] = 1;
  g.meshNode(prim);
  const std::string log = loadError(g.text());
  EXPECT_NE(log.find("mode 1 (lines) is not triangles; render draws triangles only"), std::string::npos) << log;
  EXPECT_NE(log.find(bracket("/meshes/0/primitives/0")), std::string::npos) << log;
}

TEST(GltfMesh, TrianglesMustBeWhole) {
  Gltf g;
  J prim = triangle(g);
  prim["indices"] = g.indices({0, 1, 2, 0});
  g.meshNode(prim);
  const std::string log = loadError(g.text());
  EXPECT_NE(log.find("multiple of 3"), std::string::npos) << log;
  EXPECT_NE(log.find(bracket("/meshes/0/primitives/0/indices")), std::string::npos) << log;
}

TEST(GltfMesh, AttributeCountsMustAgree) {
  Gltf g;
  J prim = triangle(g);
  prim["attributes"]["TEXCOORD_0"] = g.floats({0, 0, 1, 0}, "VEC2", 2);
  g.meshNode(prim);
  const std::string log = loadError(g.text());
  EXPECT_NE(log.find(bracket("/meshes/0/primitives/0/attributes/TEXCOORD_0")), std::string::npos) << log;
}

TEST(GltfMesh, WrongAttributeFormatIsALocatedError) {
  Gltf g;
  J prim = triangle(g);
  const std::vector<std::uint8_t> uv = {0, 255, 255, 0, 128, 51};
  prim["attributes"]["TEXCOORD_0"] = g.accessor(g.view(bytesOf(uv)), 5121, "VEC2", 3, false);  // not normalized
  g.meshNode(prim);
  const std::string log = loadError(g.text());
  EXPECT_NE(log.find(bracket("/meshes/0/primitives/0/attributes/TEXCOORD_0")), std::string::npos) << log;
}

TEST(GltfMesh, NodeCycleIsALocatedError) {
  Gltf g;
  g.meshNode(triangle(g), {{"children", {1}}});
  g.doc["nodes"].push_back({{"children", {0}}});
  const std::string log = loadError(g.text());
  EXPECT_NE(log.find("cycle"), std::string::npos) << log;
  EXPECT_NE(log.find(bracket("/nodes/0")), std::string::npos) << log;
}

TEST(GltfMesh, HierarchyDeeperThanTheLimitIsALocatedError) {
  Gltf g;
  g.meshNode(triangle(g), {{"children", {1}}});
  g.doc["nodes"].push_back({{"children", {2}}});
  g.doc["nodes"].push_back(J::object());
  MeshLimits limits;
  limits.maxDepth = 2;
  const std::string log = loadError(g.text(), limits);
  EXPECT_NE(log.find("maxDepth"), std::string::npos) << log;
  EXPECT_NE(log.find(bracket("/nodes/2")), std::string::npos) << log;
}

TEST(GltfMesh, VerticesOverTheLimitAreALocatedError) {
  Gltf g;
  g.meshNode(triangle(g));
  g.doc["nodes"].push_back({{"mesh", 0}, {"translation", {0, 0, 1}}});  // a second instance
  g.doc["scenes"][0]["nodes"].push_back(1);
  MeshLimits limits;
  limits.maxVertices = 5;
  const std::string log = loadError(g.text(), limits);
  EXPECT_NE(log.find("maxVertices"), std::string::npos) << log;
  EXPECT_NE(log.find(bracket("/nodes/1")), std::string::npos) << log;
  limits.maxVertices = 6;
  EXPECT_TRUE(load(g.text(), nullptr, limits));
}

TEST(GltfMesh, MissingBufferFileIsALocatedError) {
  Gltf g;
  g.meshNode(triangle(g));
  J doc = g.doc;
  doc["buffers"] = J::array({{{"byteLength", g.bin.size()}, {"uri", "no_such_file.bin"}}});
  const std::string log = loadError(doc.dump(2), {}, testing::TempDir());
  EXPECT_NE(log.find("no_such_file.bin"), std::string::npos) << log;
  EXPECT_NE(log.find(bracket("/buffers/0/uri")), std::string::npos) << log;
}

TEST(GltfMesh, MalformedJsonIsAnErrorAtItsLineAndColumn) {
  const std::string log = loadError("{\n  \"asset\": {\"version\": \"2.0\"},\n  \"nodes\": [,]\n}\n");
  EXPECT_NE(log.find("test.gltf:3:"), std::string::npos) << log;
}

TEST(GltfMesh, WrongTypeForCountIsALocatedError) {
  Gltf g;
  g.meshNode(triangle(g));
  g.doc["accessors"][0]["count"] = "x";
  const std::string log = loadError(g.text());
  EXPECT_NE(log.find(bracket("/accessors/0/count")), std::string::npos) << log;
}

TEST(GltfMesh, NonFinitePositionIsALocatedError) {
  Gltf g;
  J prim = triangle(g);
  prim["attributes"]["POSITION"] = g.floats({0, 0, 0, INFINITY, 0, 0, 0, 1, 0}, "VEC3", 3);
  g.meshNode(prim);
  const std::string log = loadError(g.text());
  EXPECT_NE(log.find("not finite"), std::string::npos) << log;
  EXPECT_NE(log.find(bracket("/meshes/0/primitives/0/attributes/POSITION")), std::string::npos) << log;
}

TEST(GltfMesh, NodeIndexOutOfRangeIsALocatedError) {
  Gltf g;
  g.meshNode(triangle(g), {{"children", {7}}});
  std::string log = loadError(g.text());
  EXPECT_NE(log.find(bracket("/nodes/0/children/0")), std::string::npos) << log;
  g.doc["nodes"][0].erase("children");
  g.doc["scenes"][0]["nodes"].push_back(-1);
  log = loadError(g.text());
  EXPECT_NE(log.find(bracket("/scenes/0/nodes/1")), std::string::npos) << log;
}

/// Every value's JSON pointer in `j` (depth first).
void pointersOf(const J& j, const std::string& at, std::vector<std::string>& out) {
  out.push_back(at);
  if (j.is_object())
    for (auto it = j.begin(); it != j.end(); ++it) pointersOf(*it, at + "/" + it.key(), out);
  if (j.is_array())
    for (std::size_t i = 0; i < j.size(); ++i) pointersOf(j[i], at + "/" + std::to_string(i), out);
}

TEST(GltfMesh, EveryValueReplacedByAWrongOneFailsCleanlyOrLoadsUsably) {
  Gltf g;
  J prim = triangle(g, {{"NORMAL", g.floats({0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3", 3)}});
  prim["indices"] = g.indices({0, 1, 2});
  prim["material"] = 0;
  const int sparseIndices = g.view(bytesOf(std::vector<std::uint16_t>{1, 0}));
  const int sparseValues = g.view(bytesOf(std::vector<float>{2, 0, 0}));
  g.doc["accessors"][0]["sparse"] = {{"count", 1}, {"indices", {{"bufferView", sparseIndices}, {"componentType", 5123}}},
                                     {"values", {{"bufferView", sparseValues}}}};
  const int child = g.meshNode(prim, {{"translation", {1, 0, 0}}, {"rotation", {0, 0, 0, 1}}, {"scale", {1, 2, 1}}});
  g.doc["nodes"].push_back({{"children", {child}}, {"camera", 0}, {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}});
  g.doc["scenes"][0]["nodes"] = {1};
  g.doc["scene"] = 0;
  g.doc["cameras"] = J::array({{{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.1}}}}});
  g.doc["materials"] = J::array({{{"name", "m"}}});
  ASSERT_TRUE(load(g.text()));
  std::vector<std::string> pointers;
  pointersOf(g.doc, "", pointers);
  const std::vector<J> wrong = {"x", -1, 1e30, nullptr, J::object(), J::array({1}), 0, 3.5, 4294967295u};
  for (const std::string& ptr : pointers) {
    if (ptr.empty()) continue;
    for (const J& w : wrong) {
      Gltf m = g;
      m.doc[J::json_pointer(ptr)] = w;
      Diagnostics d("test.gltf");
      std::optional<Scene> scene;
      ASSERT_NO_THROW(scene = loadGltfSceneFromBytes(m.text(), ".", {}, d)) << ptr << " = " << w.dump();
      if (!scene) {
        EXPECT_TRUE(d.hasErrors()) << ptr << " = " << w.dump();
        continue;
      }
      for (const Primitive& p : scene->primitives) {
        for (float f : p.vertices) ASSERT_TRUE(std::isfinite(f)) << ptr << " = " << w.dump();
        for (std::uint32_t i : p.indices) ASSERT_LT(i, p.vertices.size() / kVertexFloats) << ptr << " = " << w.dump();
      }
    }
  }
}

// ---------------------------------------------------------------- framing

TEST(GltfMesh, FramingCameraLooksAtTheBoundsCentreAndSeesThemWhole) {
  Scene scene;
  scene.primitives.emplace_back();
  scene.boundsMin = {-1, 0, -3};
  scene.boundsMax = {3, 2, 1};
  for (double aspect : {0.5, 1.0, 2.0}) {
    const Camera c = framingCamera(scene, aspect);
    const Vec3 centre{1, 1, -1};
    expectNear(c.forward, vec::normalizeOr(vec::sub(centre, c.position), {0, 0, 0}), 1e-9);
    EXPECT_NEAR(vec::length(c.forward), 1, 1e-9);
    EXPECT_NEAR(vec::length(c.up), 1, 1e-9);
    EXPECT_NEAR(vec::dot(c.forward, c.up), 0, 1e-9);
    EXPECT_GT(c.up[1], 0);
    EXPECT_LT(c.forward[2], 0);  // looking down -Z, from above (forward.y < 0)
    EXPECT_LT(c.forward[1], 0);
    EXPECT_NEAR(c.yfov, 35 * std::acos(-1.0) / 180, 1e-12);
    EXPECT_EQ(c.zfar, 0);
    // The bounding sphere (radius 3: half the diagonal (4, 2, 4)) fills 90 % of the smaller half-extent.
    const double distance = vec::length(vec::sub(centre, c.position));
    const double seen = std::tan(std::asin(3.0 / distance));
    EXPECT_NEAR(seen, 0.9 * std::tan(c.yfov / 2) * std::min(1.0, aspect), 1e-9) << aspect;
    EXPECT_GT(c.znear, 0);
    EXPECT_LT(c.znear, distance - 3.0);
  }
}

TEST(GltfMesh, FramingCameraOfAnEmptySceneIsFinite) {
  for (double aspect : {1.0, 0.0, -1.0, std::nan("")}) {
    const Camera c = framingCamera(Scene{}, aspect);
    for (int i = 0; i < 3; ++i) {
      EXPECT_TRUE(std::isfinite(c.position[i]));
      EXPECT_TRUE(std::isfinite(c.forward[i]));
      EXPECT_TRUE(std::isfinite(c.up[i]));
    }
    EXPECT_TRUE(std::isfinite(c.znear) && c.znear > 0);
    EXPECT_EQ(c.name, "frame");
  }
}

// ---------------------------------------------------------------- the corpus

/// Expects a loaded scene usable by the renderer: finite vertices, unit normals and tangents, indices in range.
void expectUsable(const Scene& scene) {
  ASSERT_GT(scene.primitives.size(), 0u);
  for (const Primitive& p : scene.primitives) {
    const std::size_t n = p.vertices.size() / kVertexFloats;
    ASSERT_EQ(p.vertices.size() % kVertexFloats, 0u);
    for (float f : p.vertices) ASSERT_TRUE(std::isfinite(f)) << p.location;
    for (std::size_t v = 0; v < n; ++v) {
      ASSERT_NEAR(vec::length(at(p, v, kNormalOffset)), 1, 1e-3) << p.location << " vertex " << v;
      ASSERT_NEAR(vec::length(at(p, v, kTangentOffset)), 1, 1e-3) << p.location << " vertex " << v;
      ASSERT_EQ(std::fabs(floatAt(p, v, kTangentOffset + 3)), 1.0f);
    }
    ASSERT_EQ(p.indices.size() % 3, 0u);
    for (std::uint32_t i : p.indices) ASSERT_LT(i, n) << p.location;
  }
}

TEST(GltfMesh, CorpusGeometryLoads) {
  // The shared corpus next to the repository (tests/import/corpus copies its glTF
  // documents, not these binary assets).
  const std::filesystem::path dir = std::filesystem::path(SUBSTRATEC_SOURCE_DIR "/../shared/corpus/assets/materialx/Geometry");
  if (!std::filesystem::exists(std::filesystem::path(SUBSTRATEC_SOURCE_DIR "/../shared/corpus")))
    GTEST_SKIP() << "no ../shared/corpus next to the repository";
  for (const char* name : {"shaderball.glb", "boombox.glb"}) {
    Diagnostics d(name);
    auto scene = loadGltfScene((dir / name).string(), {}, d);
    ASSERT_TRUE(scene) << name << ": " << d.formatAll();
    EXPECT_FALSE(d.hasErrors()) << d.formatAll();
    expectUsable(*scene);
    EXPECT_GT(scene->vertexCount, 0u);
    const Camera c = framingCamera(*scene, 1.0);
    for (int i = 0; i < 3; ++i) EXPECT_TRUE(std::isfinite(c.position[i])) << name;
  }
}

// ---------------------------------------------------------------- tangents alone

/// A vertex record of the kVertexFloats layout.
std::vector<float> vertexRecord(Vec3 position, Vec3 normal, float u, float v) {
  std::vector<float> r(kVertexFloats, 0.0f);
  for (int i = 0; i < 3; ++i) {
    r[kPositionOffset + i] = static_cast<float>(position[i]);
    r[kNormalOffset + i] = static_cast<float>(normal[i]);
  }
  r[kUv0Offset] = u;
  r[kUv0Offset + 1] = v;
  return r;
}

TEST(MikkTangents, DegenerateUvsFallBackToAPerpendicularWithPositiveSign) {
  std::vector<float> vs;
  for (const Vec3& p : {Vec3{0, 0, 0}, Vec3{1, 0, 0}, Vec3{0, 1, 0}}) {
    const auto r = vertexRecord(p, {0, 1, 0}, 0.5f, 0.5f);  // every corner the same uv
    vs.insert(vs.end(), r.begin(), r.end());
  }
  generateTangents(vs, {0, 1, 2});
  for (std::size_t v = 0; v < 3; ++v) {
    const float* t = vs.data() + v * kVertexFloats + kTangentOffset;
    EXPECT_NEAR(std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]), 1, 1e-6);
    EXPECT_NEAR(t[1], 0, 1e-6);  // orthogonal to the normal +Y
    EXPECT_EQ(t[3], 1.0f);
  }
}

TEST(MikkTangents, NeverNanOnZeroAreaTrianglesOrBadIndices) {
  std::vector<float> vs;
  for (int i = 0; i < 4; ++i) {
    const auto r = vertexRecord({0, 0, 0}, {0, 0, 0}, static_cast<float>(i), static_cast<float>(i * i));
    vs.insert(vs.end(), r.begin(), r.end());
  }
  generateTangents(vs, {0, 1, 2, 1, 2, 99});
  for (float f : vs) EXPECT_TRUE(std::isfinite(f));
  for (std::size_t v = 0; v < 4; ++v) EXPECT_EQ(std::fabs(vs[v * kVertexFloats + kTangentOffset + 3]), 1.0f);
}

TEST(MikkTangents, SharedVerticesAverageByCornerAngle) {
  // A unit square as two triangles sharing an edge, uv = position.xy, tilted normals: the
  // tangent stays +U projected off each normal.
  std::vector<float> vs;
  const Vec3 n = vec::normalizeOr({0, 0.3, 1}, {0, 0, 1});
  for (const Vec3& p : {Vec3{0, 0, 0}, Vec3{1, 0, 0}, Vec3{1, 1, 0}, Vec3{0, 1, 0}}) {
    const auto r = vertexRecord(p, n, static_cast<float>(p[0]), static_cast<float>(p[1]));
    vs.insert(vs.end(), r.begin(), r.end());
  }
  generateTangents(vs, {0, 1, 2, 0, 2, 3});
  for (std::size_t v = 0; v < 4; ++v) {
    const float* t = vs.data() + v * kVertexFloats + kTangentOffset;
    EXPECT_NEAR(t[0], 1, 1e-6);
    EXPECT_NEAR(t[1], 0, 1e-6);
    EXPECT_NEAR(t[2], 0, 1e-6);
    EXPECT_EQ(t[3], 1.0f);
  }
}

}  // namespace gltf_mesh_test
}  // namespace substratec::mesh
