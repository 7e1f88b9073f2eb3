// The geometry of a glTF 2.0 document (.gltf or .glb) for `substratec render`:
// its scene's mesh primitives flattened into world space, one draw each, with
// every vertex attribute the generated fragment shaders read, and its cameras.
//
// What is read: the default scene (`scene`, else scene 0, else every root
// node), the node hierarchy (matrix or translation/rotation/scale, composed
// parent first), each mesh primitive of mode 4 (triangles; 5 and 6, strips and
// fans, are converted to triangles), its indices (or none: 0..count-1) and
// attributes POSITION (required), NORMAL, TANGENT, TEXCOORD_0, TEXCOORD_1,
// COLOR_0 (accessors of any component type glTF allows, normalized integers
// decoded, byteStride honoured, sparse accessors applied). Missing normals are
// the faces' (flat); missing tangents are generated per vertex from the UVs
// (mikktspace.h); missing UVs are 0, missing colours white. Buffers come from
// files relative to the document, data: URIs, or a .glb's binary chunk.
//
// Every problem is an error located by the JSON pointer of what holds it
// ("/accessors/3: count 4 exceeds the buffer view's 36 bytes"), and nothing is
// returned: a missing or short buffer, an accessor out of its buffer view, an
// index out of range, a primitive of points or lines, a node cycle, a count
// over the limits below.
//
// Not read: morph targets, skins (the bind pose is drawn), EXT_mesh_gpu_instancing,
// attributes other than the six above; a document requiring KHR_draco_mesh_compression,
// EXT_meshopt_compression or KHR_mesh_quantization is an error. Orthographic
// cameras are a warning and skipped.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "diag/diagnostics.h"

namespace substratec::mesh {

/// Floats per vertex in Primitive::vertices, in this order (the vertex inputs of
/// runtime_shaders/substrate_vertex.vert, locations 0-5).
inline constexpr int kPositionOffset = 0;  // xyz, world space
inline constexpr int kNormalOffset = 3;    // xyz, unit, world space
inline constexpr int kTangentOffset = 6;   // xyz unit, world space; w = +-1, the bitangent's sign (glTF)
inline constexpr int kUv0Offset = 10;      // uv
inline constexpr int kUv1Offset = 12;      // uv
inline constexpr int kColorOffset = 14;    // rgba, linear
inline constexpr int kVertexFloats = 18;
/// Components per vertex input location (0..5).
inline constexpr std::array<uint32_t, 6> kVertexComponents = {3, 3, 4, 2, 2, 4};

struct MeshLimits {
  std::size_t maxFileBytes = std::size_t{1} << 30;        // the document and each buffer
  std::size_t maxVertices = std::size_t{1} << 24;         // over all primitives, after instancing by nodes
  std::size_t maxIndices = std::size_t{3} << 24;          // over all primitives, after instancing by nodes
  std::size_t maxNodes = 65536;                           // nodes visited (instances included)
  int maxDepth = 64;                                      // of the node hierarchy
};

/// One mesh primitive under one node, in world space: one draw.
struct Primitive {
  std::vector<float> vertices;    // kVertexFloats per vertex
  std::vector<uint32_t> indices;  // triangles, each < vertices.size() / kVertexFloats; counter-clockwise
                                  // front faces in world space (under a mirroring node, det < 0, the
                                  // winding is reversed, as glTF's rule for such nodes asks)
  int material = -1;              // the glTF material index; -1: none (glTF's default material)
  std::string location;           // "/meshes/M/primitives/P" (for messages)
  std::string node;               // "/nodes/N" of the instance
  bool generatedNormals = false;
  bool generatedTangents = false;
  std::array<double, 3> boundsMin{}, boundsMax{};  // of its world-space positions
};

/// A perspective camera in world space (+Y up, looking down `forward`).
struct Camera {
  std::string name;      // the glTF camera's name, or "" (and for the framing camera "frame")
  std::string location;  // "/cameras/C" or "" for a framing camera
  std::array<double, 3> position{}, forward{0, 0, -1}, up{0, 1, 0};  // forward and up unit, orthogonal
  double yfov = 0.7;     // radians, vertical
  double znear = 0.01;
  double zfar = 0;       // 0: infinite
  double aspectRatio = 0;  // as the glTF camera gives it (0: none; the image's then)
};

struct Scene {
  std::vector<Primitive> primitives;
  std::vector<Camera> cameras;  // the glTF's perspective cameras under the scene's nodes, in node order
  std::array<double, 3> boundsMin{}, boundsMax{};  // of every primitive
  std::size_t vertexCount = 0, indexCount = 0;
  std::vector<std::string> materialNames;  // the document's /materials/N names ("" when unnamed), by index
  std::vector<std::string> files;  // the files read: the document, then each external buffer (paths as opened)
};

/// Reads `path` (.gltf or .glb, told apart by content). nullopt with located errors in `diags`.
std::optional<Scene> loadGltfScene(const std::string& path, const MeshLimits& limits, Diagnostics& diags);

/// The same from the document's bytes; file buffers resolve against `baseDir`.
std::optional<Scene> loadGltfSceneFromBytes(const std::string& bytes, const std::string& baseDir,
                                            const MeshLimits& limits, Diagnostics& diags);

/// A camera that frames `scene`'s bounds: looking down -Z from +Z (slightly from
/// above: 15 degrees of elevation, 20 of azimuth), vertical field of view 35
/// degrees, the bounding sphere filling 90 % of the smaller image side for
/// `aspect` (width / height).
Camera framingCamera(const Scene& scene, double aspect);

}  // namespace substratec::mesh
