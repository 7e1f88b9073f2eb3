// The generated scene the render tests draw: a UV sphere (material 0) over a
// ground quad (material 1) and a camera, written as a .gltf with its buffer
// in a data: URI and no tangents (the loader generates them). It is also
// the shader ball's stand-in where ../shared/corpus is absent (CI's clean
// clone): render_corpus_test.cc.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace substratec::gputest {

inline std::string base64(const std::string& bytes) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    uint32_t v = static_cast<unsigned char>(bytes[i]) << 16;
    if (i + 1 < bytes.size()) v |= static_cast<unsigned char>(bytes[i + 1]) << 8;
    if (i + 2 < bytes.size()) v |= static_cast<unsigned char>(bytes[i + 2]);
    out += k[(v >> 18) & 63];
    out += k[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? k[(v >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? k[v & 63] : '=';
  }
  return out;
}

/// A primitive's arrays, appended to one buffer.
struct MeshData {
  std::vector<float> positions, normals, uvs;
  std::vector<uint32_t> indices;
};

inline MeshData sphere(int slices, int stacks) {
  MeshData m;
  for (int j = 0; j <= stacks; ++j)
    for (int i = 0; i <= slices; ++i) {
      const double theta = M_PI * j / stacks, phi = 2 * M_PI * i / slices;
      const double n[3] = {std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi)};
      for (double c : n) m.positions.push_back(static_cast<float>(c)), m.normals.push_back(static_cast<float>(c));
      m.uvs.push_back(static_cast<float>(2.0 * i / slices));
      m.uvs.push_back(static_cast<float>(1.0 * j / stacks));
    }
  for (int j = 0; j < stacks; ++j)
    for (int i = 0; i < slices; ++i) {
      const uint32_t a = j * (slices + 1) + i, b = a + slices + 1;
      m.indices.insert(m.indices.end(), {a, b, a + 1, a + 1, b, b + 1});
    }
  return m;
}

inline MeshData ground() {
  MeshData m;
  m.positions = {-3, -1, -3, -3, -1, 3, 3, -1, 3, 3, -1, -3};
  m.normals = {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0};
  m.uvs = {0, 0, 0, 3, 3, 3, 3, 0};
  m.indices = {0, 1, 2, 0, 2, 3};
  return m;
}

/// The test scene: a sphere (material 0) over a ground quad (material 1), and a camera.
inline std::string sceneGltf() {
  using J = nlohmann::json;
  std::string buffer;
  J accessors = J::array(), views = J::array(), primitives = J::array();
  auto add = [&](const void* data, std::size_t bytes, std::size_t count, int componentType, const char* type,
                 bool indices) {
    views.push_back({{"buffer", 0}, {"byteOffset", buffer.size()}, {"byteLength", bytes}});
    if (!indices) views.back()["byteStride"] = bytes / count;
    buffer.append(static_cast<const char*>(data), bytes);
    accessors.push_back({{"bufferView", views.size() - 1}, {"componentType", componentType}, {"count", count},
                         {"type", type}});
    return accessors.size() - 1;
  };
  const MeshData meshes[2] = {sphere(32, 16), ground()};
  for (int m = 0; m < 2; ++m) {
    const MeshData& d = meshes[m];
    const std::size_t n = d.positions.size() / 3;
    const auto p = add(d.positions.data(), d.positions.size() * 4, n, 5126, "VEC3", false);
    float lo[3] = {1e9, 1e9, 1e9}, hi[3] = {-1e9, -1e9, -1e9};
    for (std::size_t i = 0; i < d.positions.size(); ++i)
      lo[i % 3] = std::min(lo[i % 3], d.positions[i]), hi[i % 3] = std::max(hi[i % 3], d.positions[i]);
    accessors[p]["min"] = {lo[0], lo[1], lo[2]};
    accessors[p]["max"] = {hi[0], hi[1], hi[2]};
    const auto nn = add(d.normals.data(), d.normals.size() * 4, n, 5126, "VEC3", false);
    const auto uv = add(d.uvs.data(), d.uvs.size() * 4, n, 5126, "VEC2", false);
    const auto ix = add(d.indices.data(), d.indices.size() * 4, d.indices.size(), 5125, "SCALAR", true);
    primitives.push_back({{"attributes", {{"POSITION", p}, {"NORMAL", nn}, {"TEXCOORD_0", uv}}},
                          {"indices", ix}, {"material", m}});
  }
  J doc = {{"asset", {{"version", "2.0"}}},
           {"scene", 0},
           {"scenes", {{{"nodes", {0, 1, 2}}}}},
           {"nodes",
            {{{"mesh", 0}},
             {{"mesh", 1}},
             {{"camera", 0}, {"translation", {0.0, 0.6, 3.6}}, {"rotation", {-0.0871557, 0.0, 0.0, 0.9961947}}}}},
           {"cameras", {{{"type", "perspective"}, {"perspective", {{"yfov", 0.7}, {"znear", 0.05}}}}}},
           {"meshes", {{{"primitives", {primitives[0]}}}, {{"primitives", {primitives[1]}}}}},
           {"materials",
            {{{"name", "sphere"}, {"pbrMetallicRoughness", {{"baseColorFactor", {0.8, 0.3, 0.2, 1}},
                                                             {"metallicFactor", 0.0}, {"roughnessFactor", 0.4}}}},
             {{"name", "floor"}, {"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 0.5, 0.5, 1}},
                                                            {"metallicFactor", 0.0}, {"roughnessFactor", 0.8}}}}}},
           {"accessors", accessors},
           {"bufferViews", views},
           {"buffers", {{{"byteLength", buffer.size()},
                         {"uri", "data:application/octet-stream;base64," + base64(buffer)}}}}};
  return doc.dump();
}

}  // namespace substratec::gputest
