#include "mesh/gltf_mesh.h"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <numeric>
#include <set>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "format/json_document.h"
#include "import/glb_container.h"
#include "import/gltf_resources.h"
#include "mesh/mikktspace.h"

namespace substratec::mesh {

namespace {

using vec::Vec3;

// ---------------------------------------------------------------- matrices

/// A 4x4 affine matrix, column-major as glTF writes it: row r, column c at [c * 4 + r].
using Mat4 = std::array<double, 16>;

constexpr Mat4 kIdentity = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

/// The matrix product a * b.
Mat4 multiply(const Mat4& a, const Mat4& b) {
  Mat4 m{};
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) {
      double s = 0;
      for (int k = 0; k < 4; ++k) s += a[k * 4 + r] * b[c * 4 + k];
      m[c * 4 + r] = s;
    }
  return m;
}

/// Column `c` of the upper 3x3 of `m`.
Vec3 column(const Mat4& m, int c) { return {m[c * 4], m[c * 4 + 1], m[c * 4 + 2]}; }

/// M * (p, 1): a point (glTF's node matrices are affine; the last row is ignored).
Vec3 transformPoint(const Mat4& m, const Vec3& p) {
  return vec::add(vec::add(vec::scale(column(m, 0), p[0]), vec::scale(column(m, 1), p[1])),
                  vec::add(vec::scale(column(m, 2), p[2]), column(m, 3)));
}

/// M's upper 3x3 * d: a direction.
Vec3 transformDirection(const Mat4& m, const Vec3& d) {
  return vec::add(vec::add(vec::scale(column(m, 0), d[0]), vec::scale(column(m, 1), d[1])),
                  vec::scale(column(m, 2), d[2]));
}

/// The determinant of M's upper 3x3.
double determinant3(const Mat4& m) { return vec::dot(column(m, 0), vec::cross(column(m, 1), column(m, 2))); }

/// The cofactor matrix of M's upper 3x3 times n: det(M) * inverse-transpose(M) * n,
/// defined for a singular M too (the normal's direction up to the sign of det).
Vec3 cofactorTimes(const Mat4& m, const Vec3& n) {
  const Vec3 a0 = column(m, 0), a1 = column(m, 1), a2 = column(m, 2);
  return vec::add(vec::add(vec::scale(vec::cross(a1, a2), n[0]), vec::scale(vec::cross(a2, a0), n[1])),
                  vec::scale(vec::cross(a0, a1), n[2]));
}

/// T * R * S from a translation, a unit quaternion (x, y, z, w) and a scale.
Mat4 composeTrs(const double t[3], const double q[4], const double s[3]) {
  const double x = q[0], y = q[1], z = q[2], w = q[3];
  const Vec3 c0 = {1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w)};
  const Vec3 c1 = {2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w)};
  const Vec3 c2 = {2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y)};
  Mat4 m = kIdentity;
  const Vec3 cols[3] = {c0, c1, c2};
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) m[c * 4 + r] = cols[c][r] * s[c];
  for (int r = 0; r < 3; ++r) m[12 + r] = t[r];
  return m;
}

// ---------------------------------------------------------------- JSON fields

/// A JSON pointer to member `key` of the value at `ptr`.
std::string member(const std::string& ptr, const char* key) { return ptr + "/" + pointerToken(key); }

/// Defensive reads of JSON members: a wrong type or range is a located error,
/// never an exception; an absent optional member leaves the output untouched.
class Fields {
 public:
  explicit Fields(Diagnostics& d) : d_(d) {}

  /// Reports an error at `ptr`; always false.
  bool fail(const std::string& ptr, const std::string& message) {
    d_.error(ptr, message);
    return false;
  }

  /// The value `v` (at `ptr`) as a non-negative integer (an integral number up to 2^53).
  bool countValue(const Json& v, const std::string& ptr, std::uint64_t& out) {
    if (v.is_number_unsigned()) {
      out = v.get<std::uint64_t>();
      return true;
    }
    const double x = v.is_number() ? v.get<double>() : -1;
    if (!(x >= 0 && x <= 9007199254740992.0 && std::floor(x) == x))
      return fail(ptr, fmt::format("expected a non-negative integer, not {}", kindOfJson(v)));
    out = static_cast<std::uint64_t>(x);
    return true;
  }

  /// The value `v` (at `ptr`) as an index into `what`, an array of `size`.
  bool indexValue(const Json& v, const std::string& ptr, std::size_t size, const char* what, std::size_t& out) {
    std::uint64_t i = 0;
    if (!countValue(v, ptr, i)) return false;
    if (i >= size) return fail(ptr, fmt::format("index {} is out of range: the document has {} {}", i, size, what));
    out = static_cast<std::size_t>(i);
    return true;
  }

  /// `obj[key]` as a non-negative integer.
  bool count(const Json& obj, const std::string& ptr, const char* key, std::uint64_t& out, bool required) {
    auto it = obj.find(key);
    if (it == obj.end()) return !required || fail(ptr, fmt::format("\"{}\" is missing", key));
    return countValue(*it, member(ptr, key), out);
  }

  /// `obj[key]` as an index into `what` (an array of `size`), or nullopt when absent.
  bool index(const Json& obj, const std::string& ptr, const char* key, std::size_t size, const char* what,
             std::optional<std::size_t>& out) {
    auto it = obj.find(key);
    if (it == obj.end()) return true;
    std::size_t i = 0;
    if (!indexValue(*it, member(ptr, key), size, what, i)) return false;
    out = i;
    return true;
  }

  /// `obj[key]` as `n` finite numbers (an array of exactly n).
  bool numbers(const Json& obj, const std::string& ptr, const char* key, std::size_t n, double* out) {
    auto it = obj.find(key);
    if (it == obj.end()) return true;
    if (!it->is_array() || it->size() != n)
      return fail(member(ptr, key), fmt::format("\"{}\" must be an array of {} numbers, not {}", key, n, kindOfJson(*it)));
    for (std::size_t i = 0; i < n; ++i) {
      const Json& v = (*it)[i];
      if (!v.is_number() || !std::isfinite(v.get<double>()))
        return fail(fmt::format("{}/{}", member(ptr, key), i), fmt::format("expected a finite number, not {}", kindOfJson(v)));
      out[i] = v.get<double>();
    }
    return true;
  }

  /// `obj[key]` as a finite number.
  bool number(const Json& obj, const std::string& ptr, const char* key, double& out, bool required) {
    auto it = obj.find(key);
    if (it == obj.end()) return !required || fail(ptr, fmt::format("\"{}\" is missing", key));
    if (!it->is_number() || !std::isfinite(it->get<double>()))
      return fail(member(ptr, key), fmt::format("\"{}\" must be a number, not {}", key, kindOfJson(*it)));
    out = it->get<double>();
    return true;
  }

  /// `obj[key]` as a boolean.
  bool flag(const Json& obj, const std::string& ptr, const char* key, bool& out) {
    auto it = obj.find(key);
    if (it == obj.end()) return true;
    if (!it->is_boolean()) return fail(member(ptr, key), fmt::format("\"{}\" must be true or false, not {}", key, kindOfJson(*it)));
    out = it->get<bool>();
    return true;
  }

  /// `obj[key]` as a string.
  bool text(const Json& obj, const std::string& ptr, const char* key, std::string& out, bool required) {
    auto it = obj.find(key);
    if (it == obj.end()) return !required || fail(ptr, fmt::format("\"{}\" is missing", key));
    if (!it->is_string()) return fail(member(ptr, key), fmt::format("\"{}\" must be a string, not {}", key, kindOfJson(*it)));
    out = it->get<std::string>();
    return true;
  }

  /// `v` (at `ptr`) must be an object.
  bool object(const Json& v, const std::string& ptr) {
    return v.is_object() || fail(ptr, fmt::format("expected an object, not {}", kindOfJson(v)));
  }

  Diagnostics& diags() { return d_; }

 private:
  Diagnostics& d_;
};

// ---------------------------------------------------------------- accessors

/// A bufferView's bytes: [offset, offset + length) of `bytes`, its byteStride (0: tightly packed).
struct View {
  const std::string* bytes = nullptr;
  std::uint64_t offset = 0, length = 0, stride = 0;
};

/// An accessor as its JSON says, checked against its buffer view.
struct Layout {
  std::string ptr;  // "/accessors/N"
  int componentType = 0, components = 0;
  bool normalized = false;
  std::uint64_t count = 0, offset = 0, stride = 0;  // offset within the view; stride between elements
  std::optional<View> view;                         // none: zeros (then sparse)
  const Json* sparse = nullptr;
};

/// Bytes per component of a glTF componentType, 0 for another number.
int componentBytes(std::uint64_t type) {
  switch (type) {
    case 5120: case 5121: return 1;
    case 5122: case 5123: return 2;
    case 5125: case 5126: return 4;
    default: return 0;
  }
}

/// The name of a componentType, for messages.
const char* componentName(int type) {
  switch (type) {
    case 5120: return "byte (5120)";
    case 5121: return "unsigned byte (5121)";
    case 5122: return "short (5122)";
    case 5123: return "unsigned short (5123)";
    case 5125: return "unsigned int (5125)";
    case 5126: return "float (5126)";
    default: return "?";
  }
}

/// Components per element of an accessor type; 0 for the matrices and anything else.
int typeComponents(const std::string& type) {
  if (type == "SCALAR") return 1;
  if (type == "VEC2") return 2;
  if (type == "VEC3") return 3;
  if (type == "VEC4") return 4;
  return 0;
}

/// The unsigned little-endian integer of `n` bytes at `p`.
std::uint32_t littleEndian(const unsigned char* p, int n) {
  std::uint32_t v = 0;
  for (int i = n - 1; i >= 0; --i) v = v << 8 | p[i];
  return v;
}

/// One component at `p` as a double, normalized integers decoded as glTF says
/// (signed: max(c / (2^(b-1) - 1), -1); unsigned: c / (2^b - 1)).
double readComponent(const unsigned char* p, int type, bool normalized) {
  switch (type) {
    case 5120: {
      const auto c = static_cast<std::int8_t>(p[0]);
      return normalized ? std::max(c / 127.0, -1.0) : c;
    }
    case 5121: return normalized ? p[0] / 255.0 : p[0];
    case 5122: {
      const auto c = static_cast<std::int16_t>(static_cast<std::uint16_t>(littleEndian(p, 2)));
      return normalized ? std::max(c / 32767.0, -1.0) : c;
    }
    case 5123: return normalized ? littleEndian(p, 2) / 65535.0 : littleEndian(p, 2);
    case 5125: return littleEndian(p, 4);
    case 5126: {
      const std::uint32_t bits = littleEndian(p, 4);
      float f;
      std::memcpy(&f, &bits, sizeof f);
      return f;
    }
    default: return 0;
  }
}

/// Whether `count` elements of `elementBytes`, `stride` apart, fit in `available` bytes (overflow-safe).
bool fitsIn(std::uint64_t count, std::uint64_t elementBytes, std::uint64_t stride, std::uint64_t available) {
  if (count == 0) return true;
  if (elementBytes > available) return false;
  return stride == 0 || count - 1 <= (available - elementBytes) / stride;
}

// ---------------------------------------------------------------- attributes

/// The vertex attributes read, with where each goes in the vertex.
enum class Semantic { Position, Normal, Tangent, TexCoord, Color };
struct AttributeSpec {
  const char* name;
  Semantic semantic;
  int offset;
};
constexpr AttributeSpec kAttributes[] = {
    {"POSITION", Semantic::Position, kPositionOffset}, {"NORMAL", Semantic::Normal, kNormalOffset},
    {"TANGENT", Semantic::Tangent, kTangentOffset},    {"TEXCOORD_0", Semantic::TexCoord, kUv0Offset},
    {"TEXCOORD_1", Semantic::TexCoord, kUv1Offset},    {"COLOR_0", Semantic::Color, kColorOffset},
};

/// Whether an accessor's format is one glTF allows for `s`.
bool formatAllowed(Semantic s, const Layout& a) {
  const bool isFloat = a.componentType == 5126;
  const bool unorm = a.normalized && (a.componentType == 5121 || a.componentType == 5123);
  switch (s) {
    case Semantic::Position:
    case Semantic::Normal: return isFloat && a.components == 3;
    case Semantic::Tangent: return isFloat && a.components == 4;
    case Semantic::TexCoord: return (isFloat || unorm) && a.components == 2;
    case Semantic::Color: return (isFloat || unorm) && (a.components == 3 || a.components == 4);
  }
  return false;
}

/// What glTF allows for `s`, for messages.
const char* formatWanted(Semantic s) {
  switch (s) {
    case Semantic::Position:
    case Semantic::Normal: return "VEC3 of float";
    case Semantic::Tangent: return "VEC4 of float";
    case Semantic::TexCoord: return "VEC2 of float, or of normalized unsigned byte or short";
    case Semantic::Color: return "VEC3 or VEC4 of float, or of normalized unsigned byte or short";
  }
  return "";
}

/// A mesh primitive decoded once, in its mesh's space; each node instancing it transforms a copy.
struct LocalPrimitive {
  std::vector<float> vertices;  // kVertexFloats each
  std::vector<std::uint32_t> indices;
  int material = -1;
  bool generatedNormals = false, generatedTangents = false;
};

/// The triangle list of a strip (mode 5; every other triangle's winding reversed,
/// as glTF orders them) or a fan (mode 6) of `in`.
std::vector<std::uint32_t> triangulate(const std::vector<std::uint32_t>& in, int mode) {
  std::vector<std::uint32_t> out;
  if (in.size() < 3) return out;
  out.reserve((in.size() - 2) * 3);
  for (std::size_t i = 0; i + 2 < in.size(); ++i) {
    if (mode == 6) {
      out.insert(out.end(), {in[0], in[i + 1], in[i + 2]});
    } else if (i % 2 == 0) {
      out.insert(out.end(), {in[i], in[i + 1], in[i + 2]});
    } else {
      out.insert(out.end(), {in[i], in[i + 2], in[i + 1]});
    }
  }
  return out;
}

/// Three floats of a vertex record as doubles.
Vec3 load3(const float* v) { return {v[0], v[1], v[2]}; }

/// Stores three doubles into a vertex record.
void store3(float* v, const Vec3& x) {
  for (int i = 0; i < 3; ++i) v[i] = static_cast<float>(x[i]);
}

/// Un-indexes `p` (each triangle its own three vertices) with the faces' normals:
/// glTF's flat normals for a primitive without NORMAL (a face of no area: +Z).
void flattenNormals(LocalPrimitive& p) {
  std::vector<float> out(p.indices.size() * kVertexFloats);
  for (std::size_t t = 0; t + 2 < p.indices.size(); t += 3) {
    float* v[3];
    for (std::size_t c = 0; c < 3; ++c) {
      v[c] = out.data() + (t + c) * kVertexFloats;
      std::copy_n(p.vertices.data() + std::size_t{p.indices[t + c]} * kVertexFloats, kVertexFloats, v[c]);
    }
    const Vec3 p0 = load3(v[0] + kPositionOffset);
    const Vec3 n = vec::normalizeOr(vec::cross(vec::sub(load3(v[1] + kPositionOffset), p0),
                                               vec::sub(load3(v[2] + kPositionOffset), p0)), Vec3{0, 0, 1});
    for (float* x : v) store3(x + kNormalOffset, n);
  }
  p.vertices = std::move(out);
  std::iota(p.indices.begin(), p.indices.end(), 0u);
  p.generatedNormals = true;
}

/// Makes every vertex of `p` usable: unit normals (a zero or non-finite one: +Z),
/// given tangents orthonormal to them with w = +-1, finite UVs (else 0) and colours (else 1).
void sanitizeVertices(LocalPrimitive& p, bool tangentsGiven) {
  for (std::size_t v = 0; v < p.vertices.size(); v += kVertexFloats) {
    float* x = p.vertices.data() + v;
    const Vec3 n = vec::normalizeOr(load3(x + kNormalOffset), Vec3{0, 0, 1});
    store3(x + kNormalOffset, n);
    if (tangentsGiven) {
      store3(x + kTangentOffset, vec::orthonormalTo(load3(x + kTangentOffset), n));
      x[kTangentOffset + 3] = x[kTangentOffset + 3] < 0 ? -1.0f : 1.0f;
    }
    for (int i = kUv0Offset; i < kColorOffset; ++i)
      if (!std::isfinite(x[i])) x[i] = 0;
    for (int i = kColorOffset; i < kVertexFloats; ++i)
      if (!std::isfinite(x[i])) x[i] = 1;
  }
}

/// The file's bytes, its size checked before reading (at most `maxBytes`); nullopt with `why`.
std::optional<std::string> readWholeFile(const std::string& path, std::size_t maxBytes, std::string& why) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) {
    why = std::strerror(errno);
    return std::nullopt;
  }
  if (S_ISDIR(st.st_mode)) why = "it is a directory";
  else if (!S_ISREG(st.st_mode)) why = "it is not a regular file";
  else if (static_cast<std::uintmax_t>(st.st_size) > maxBytes)
    why = fmt::format("it holds {} bytes, over the limit of {} (MeshLimits::maxFileBytes)",
                      static_cast<std::uintmax_t>(st.st_size), maxBytes);
  if (!why.empty()) return std::nullopt;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    why = std::strerror(errno);
    return std::nullopt;
  }
  std::string bytes(static_cast<std::size_t>(st.st_size), '\0');
  if (!in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()))) {
    why = "it is shorter than its size";
    return std::nullopt;
  }
  return bytes;
}

/// A node's world transform and what it implies for the vertices it transforms.
struct Instance {
  Mat4 world = kIdentity;
  double det = 1;     // of the upper 3x3
  bool mirrored = false;  // det < 0: tangent w and the triangles' winding flip
};

// ---------------------------------------------------------------- the loader

/// Reads one parsed glTF document into a Scene; every failure a located error.
class Loader {
 public:
  Loader(const Json& doc, std::string baseDir, const std::string* bin, const MeshLimits& limits, Diagnostics& d)
      : doc_(doc), baseDir_(std::move(baseDir)), bin_(bin), limits_(limits), f_(d), errorsBefore_(d.errorCount()) {}

  /// The scene, or nullopt after errors.
  std::optional<Scene> run();

 private:
  bool readTopLevel();
  const Json& arrayOf(const char* key) const;
  const Json* element(const char* key, std::size_t i, std::string& ptr);
  // buffers and accessors
  const std::string* buffer(std::size_t i, std::uint64_t& byteLength);
  const std::string* loadBuffer(const Json& b, std::size_t index, const std::string& ptr);
  std::optional<View> bufferView(std::size_t i);
  std::optional<Layout> layout(std::size_t i, std::uint64_t countLimit);
  bool checkInView(Layout& a, const std::string& viewPtr);
  template <class T>
  bool decode(const Layout& a, std::vector<T>& out);
  template <class T>
  bool applySparse(const Layout& a, std::vector<T>& out);
  std::optional<View> sparsePart(const Json& sp, const std::string& ptr, std::uint64_t bytes);
  // primitives
  std::shared_ptr<const LocalPrimitive> localPrimitive(std::size_t mesh, std::size_t prim, const Json& p,
                                                       const std::string& ptr);
  bool buildPrimitive(const Json& p, const std::string& ptr, LocalPrimitive& out);
  bool readMode(const Json& p, const std::string& ptr, int& mode);
  bool readAttribute(const Json& attributes, const std::string& ptr, const AttributeSpec& spec,
                     std::uint64_t& count, LocalPrimitive& out);
  bool readIndices(const Json& p, const std::string& ptr, std::size_t vertexCount, int mode,
                   std::vector<std::uint32_t>& out);
  // nodes and cameras
  bool sceneRoots(std::vector<std::size_t>& roots, std::string& where);
  bool visit(std::size_t node, const Mat4& parent, const std::string& from, int depth);
  bool nodeMatrix(const Json& node, const std::string& ptr, Mat4& out);
  bool visitChildren(const Json& node, const std::string& ptr, const Mat4& world, int depth);
  bool emitMesh(std::size_t mesh, const Instance& inst, const std::string& nodePtr);
  bool emitPrimitive(const LocalPrimitive& lp, const Instance& inst, const std::string& primPtr,
                     const std::string& nodePtr);
  bool transformVertices(Primitive& out, const Instance& inst);
  bool emitCamera(std::size_t camera, const Mat4& world, const std::string& nodePtr);
  bool perspective(const Json& cam, const std::string& ptr, Camera& out);

  const Json& doc_;
  std::string baseDir_;
  const std::string* bin_;
  const MeshLimits& limits_;
  Fields f_;
  std::size_t errorsBefore_;  // the caller's errors, not this document's
  std::vector<std::unique_ptr<std::string>> owned_;  // buffers read from files and data: URIs, by index
  std::vector<const std::string*> buffers_;          // loaded buffers by index (null: not yet)
  std::vector<std::uint64_t> bufferLengths_;         // their byteLength
  std::map<std::pair<std::size_t, std::size_t>, std::shared_ptr<const LocalPrimitive>> primitives_;
  std::vector<char> onPath_;  // nodes on the path from the root being visited
  std::size_t visited_ = 0;
  std::set<std::size_t> warnedCameras_;
  Scene scene_;
};

/// The top-level array `key` (an empty one when absent; readTopLevel checked the type).
const Json& Loader::arrayOf(const char* key) const {
  static const Json kEmpty = Json::array();
  auto it = doc_.find(key);
  return it != doc_.end() && it->is_array() ? *it : kEmpty;
}

/// Element `i` of the top-level array `key`, which must be an object; `ptr` is set to its pointer.
const Json* Loader::element(const char* key, std::size_t i, std::string& ptr) {
  ptr = fmt::format("/{}/{}", key, i);
  const Json& a = arrayOf(key);
  if (i >= a.size()) {
    f_.fail(ptr, fmt::format("the document has {} {}", a.size(), key));
    return nullptr;
  }
  return f_.object(a[i], ptr) ? &a[i] : nullptr;
}

/// Checks the document's shape: an object, its arrays arrays, a 2.x version, no
/// required extension that changes geometry; collects the material names.
bool Loader::readTopLevel() {
  if (!doc_.is_object()) return f_.fail("", "expected a glTF document (a JSON object)");
  for (const char* key : {"buffers", "bufferViews", "accessors", "meshes", "nodes", "scenes", "cameras", "materials"})
    if (doc_.contains(key) && !doc_[key].is_array())
      return f_.fail(std::string("/") + key, fmt::format("expected an array, not {}", kindOfJson(doc_[key])));
  if (auto a = doc_.find("asset"); a != doc_.end() && a->is_object()) {
    auto v = a->find("version");
    if (v != a->end() && (!v->is_string() || v->get<std::string>().rfind("2.", 0) != 0))
      return f_.fail("/asset/version", fmt::format("glTF version {} is not 2.x", kindOfJson(*v)));
  }
  if (auto r = doc_.find("extensionsRequired"); r != doc_.end() && r->is_array())
    for (std::size_t i = 0; i < r->size(); ++i) {
      const Json& e = (*r)[i];
      if (e == "KHR_draco_mesh_compression" || e == "EXT_meshopt_compression" || e == "KHR_mesh_quantization")
        return f_.fail(fmt::format("/extensionsRequired/{}", i),
                       fmt::format("the required extension {} is not supported", kindOfJson(e)));
    }
  for (const Json& m : arrayOf("materials"))
    scene_.materialNames.push_back(m.is_object() && m.contains("name") && m["name"].is_string()
                                       ? m["name"].get<std::string>() : "");
  const std::size_t n = arrayOf("buffers").size();
  owned_.resize(n);
  buffers_.assign(n, nullptr);
  bufferLengths_.assign(n, 0);
  onPath_.assign(arrayOf("nodes").size(), 0);
  return true;
}

/// The bytes of buffer `i` (read on first use) and its byteLength; null after an error.
const std::string* Loader::buffer(std::size_t i, std::uint64_t& byteLength) {
  if (i < buffers_.size() && buffers_[i]) {
    byteLength = bufferLengths_[i];
    return buffers_[i];
  }
  std::string ptr;
  const Json* b = element("buffers", i, ptr);
  if (!b || !f_.count(*b, ptr, "byteLength", byteLength, true)) return nullptr;
  const std::string* bytes = loadBuffer(*b, i, ptr);
  if (!bytes) return nullptr;
  if (bytes->size() < byteLength)
    return f_.fail(member(ptr, "byteLength"), fmt::format("byteLength is {}, but the buffer holds {} bytes",
                                                          byteLength, bytes->size())), nullptr;
  buffers_[i] = bytes;
  bufferLengths_[i] = byteLength;
  return bytes;
}

/// Reads buffer `b`'s bytes: its uri (a data: URI, or a file relative to the
/// document) or, for a .glb's first buffer without one, the binary chunk.
const std::string* Loader::loadBuffer(const Json& b, std::size_t index, const std::string& ptr) {
  std::string uri;
  if (!f_.text(b, ptr, "uri", uri, false)) return nullptr;
  if (!b.contains("uri")) {
    if (index == 0 && bin_) return bin_;
    f_.fail(ptr, bin_ ? "a buffer other than the first has no uri" : "the buffer has no uri and the document "
                                                                     "no .glb binary chunk");
    return nullptr;
  }
  std::string why;
  std::optional<std::string> bytes;
  if (uri.rfind("data:", 0) == 0) {
    bytes = import::decodeDataUri(uri, &why);
  } else if (auto path = import::uriPath(uri)) {
    const std::string full = (std::filesystem::path(baseDir_) / *path).string();
    scene_.files.push_back(full);  // an input of the command, read or not
    bytes = readWholeFile(full, limits_.maxFileBytes, why);
    if (!bytes) why = fmt::format("cannot read {}: {}", quoteForDiagnostic(full, 200), why);
  } else {
    why = fmt::format("{} is not a relative file path or a data: URI", quoteForDiagnostic(uri));
  }
  if (!bytes) return f_.fail(member(ptr, "uri"), why), nullptr;
  owned_[index] = std::make_unique<std::string>(std::move(*bytes));
  return owned_[index].get();
}

/// Buffer view `i`, checked to lie inside its buffer.
std::optional<View> Loader::bufferView(std::size_t i) {
  std::string ptr;
  const Json* v = element("bufferViews", i, ptr);
  std::optional<std::size_t> b;
  View view;
  if (!v || !f_.index(*v, ptr, "buffer", arrayOf("buffers").size(), "buffers", b) ||
      !f_.count(*v, ptr, "byteOffset", view.offset, false) || !f_.count(*v, ptr, "byteLength", view.length, true) ||
      !f_.count(*v, ptr, "byteStride", view.stride, false))
    return std::nullopt;
  if (!b) return f_.fail(ptr, "\"buffer\" is missing"), std::nullopt;
  if (view.stride != 0 && (view.stride < 4 || view.stride > 252))
    return f_.fail(member(ptr, "byteStride"), fmt::format("byteStride {} is not in [4, 252]", view.stride)),
           std::nullopt;
  std::uint64_t bufferLength = 0;
  view.bytes = buffer(*b, bufferLength);
  if (!view.bytes) return std::nullopt;
  if (view.offset > bufferLength || view.length > bufferLength - view.offset)
    return f_.fail(ptr, fmt::format("bytes {} to {} lie outside buffers[{}] of {} bytes", view.offset,
                                    view.offset + view.length, *b, bufferLength)), std::nullopt;
  return view;
}

/// Accessor `i` as its JSON says, every element checked to lie in its buffer
/// view; its count at most `countLimit`.
std::optional<Layout> Loader::layout(std::size_t i, std::uint64_t countLimit) {
  Layout a;
  const Json* j = element("accessors", i, a.ptr);
  std::uint64_t type = 0, offset = 0;
  std::string typeName;
  std::optional<std::size_t> view;
  if (!j || !f_.count(*j, a.ptr, "componentType", type, true) || !f_.text(*j, a.ptr, "type", typeName, true) ||
      !f_.count(*j, a.ptr, "count", a.count, true) || !f_.flag(*j, a.ptr, "normalized", a.normalized) ||
      !f_.count(*j, a.ptr, "byteOffset", offset, false) ||
      !f_.index(*j, a.ptr, "bufferView", arrayOf("bufferViews").size(), "bufferViews", view))
    return std::nullopt;
  if (componentBytes(type) == 0)
    return f_.fail(member(a.ptr, "componentType"), fmt::format("componentType {} is not a glTF one", type)), std::nullopt;
  a.componentType = static_cast<int>(type);
  a.components = typeComponents(typeName);
  a.offset = offset;
  if (a.components == 0)
    return f_.fail(member(a.ptr, "type"), fmt::format("type {} is not SCALAR or VEC2-4 (the types geometry uses)",
                                                      quoteForDiagnostic(typeName))), std::nullopt;
  if (a.normalized && (type == 5125 || type == 5126))
    return f_.fail(member(a.ptr, "normalized"), fmt::format("a {} accessor cannot be normalized",
                                                            componentName(a.componentType))), std::nullopt;
  if (a.count == 0) return f_.fail(member(a.ptr, "count"), "count must be at least 1"), std::nullopt;
  if (a.count > countLimit)
    return f_.fail(member(a.ptr, "count"), fmt::format("count {} exceeds the limit of {} (MeshLimits)", a.count,
                                                       countLimit)), std::nullopt;
  if (auto s = j->find("sparse"); s != j->end()) a.sparse = &*s;
  if (view) {
    a.view = bufferView(*view);
    if (!a.view || !checkInView(a, fmt::format("/bufferViews/{}", *view))) return std::nullopt;
  }
  return a;
}

/// Whether every element of `a` lies inside its buffer view (a located error otherwise); sets a.stride.
bool Loader::checkInView(Layout& a, const std::string& viewPtr) {
  const std::uint64_t element = std::uint64_t(a.components) * componentBytes(a.componentType);
  const std::uint64_t stride = a.view->stride ? a.view->stride : element;
  if (stride < element)
    return f_.fail(a.ptr, fmt::format("elements of {} bytes do not fit in {}'s byteStride {}", element, viewPtr,
                                      stride));
  const std::uint64_t available = a.offset <= a.view->length ? a.view->length - a.offset : 0;
  if (a.offset > a.view->length || !fitsIn(a.count, element, stride, available))
    return f_.fail(a.ptr, fmt::format("count {} of {}-byte elements, {} bytes apart from byteOffset {}, exceeds "
                                      "the buffer view's {} bytes ({})", a.count, element, stride, a.offset,
                                      a.view->length, viewPtr));
  a.stride = stride;
  return true;
}

/// The elements of accessor `a` as T, components in order (zeros without a
/// buffer view), the sparse substitution applied.
template <class T>
bool Loader::decode(const Layout& a, std::vector<T>& out) {
  const std::size_t comps = static_cast<std::size_t>(a.components);
  out.assign(static_cast<std::size_t>(a.count) * comps, T{});
  if (a.view) {
    const auto* base = reinterpret_cast<const unsigned char*>(a.view->bytes->data()) + a.view->offset + a.offset;
    const int size = componentBytes(a.componentType);
    for (std::size_t e = 0; e < a.count; ++e)
      for (std::size_t c = 0; c < comps; ++c)
        out[e * comps + c] = static_cast<T>(readComponent(base + e * a.stride + c * size, a.componentType, a.normalized));
  }
  return !a.sparse || applySparse(a, out);
}

/// The bytes of a sparse accessor's `indices` or `values` (`bytes` long,
/// tightly packed) in its buffer view; nullopt after an error.
std::optional<View> Loader::sparsePart(const Json& sp, const std::string& ptr, std::uint64_t bytes) {
  std::optional<std::size_t> viewIndex;
  std::uint64_t offset = 0;
  if (!f_.object(sp, ptr) || !f_.index(sp, ptr, "bufferView", arrayOf("bufferViews").size(), "bufferViews", viewIndex) ||
      !f_.count(sp, ptr, "byteOffset", offset, false))
    return std::nullopt;
  if (!viewIndex) return f_.fail(ptr, "\"bufferView\" is missing"), std::nullopt;
  std::optional<View> view = bufferView(*viewIndex);
  if (!view) return std::nullopt;
  if (offset > view->length || bytes > view->length - offset)
    return f_.fail(ptr, fmt::format("{} bytes from byteOffset {} exceed bufferViews[{}]'s {} bytes", bytes, offset,
                                    *viewIndex, view->length)), std::nullopt;
  view->offset += offset;
  return view;
}

/// Applies accessor `a`'s sparse substitution (indices and values) to `out`.
template <class T>
bool Loader::applySparse(const Layout& a, std::vector<T>& out) {
  const std::string ptr = a.ptr + "/sparse";
  const Json& sp = *a.sparse;
  std::uint64_t count = 0, indexType = 0;
  if (!f_.object(sp, ptr) || !f_.count(sp, ptr, "count", count, true)) return false;
  if (count == 0 || count > a.count)
    return f_.fail(member(ptr, "count"), fmt::format("count {} is not in [1, {}]", count, a.count));
  if (!sp.contains("indices") || !sp.contains("values")) return f_.fail(ptr, "\"indices\" or \"values\" is missing");
  const std::string ip = ptr + "/indices", vp = ptr + "/values";
  if (!f_.object(sp["indices"], ip) || !f_.count(sp["indices"], ip, "componentType", indexType, true)) return false;
  if (indexType != 5121 && indexType != 5123 && indexType != 5125)
    return f_.fail(member(ip, "componentType"), fmt::format("componentType {} is not an index type", indexType));
  const int isize = componentBytes(indexType), csize = componentBytes(a.componentType);
  const std::size_t comps = static_cast<std::size_t>(a.components);
  auto indices = sparsePart(sp["indices"], ip, count * isize);
  auto values = indices ? sparsePart(sp["values"], vp, count * comps * csize) : std::nullopt;
  if (!values) return false;
  const auto* ib = reinterpret_cast<const unsigned char*>(indices->bytes->data()) + indices->offset;
  const auto* vb = reinterpret_cast<const unsigned char*>(values->bytes->data()) + values->offset;
  for (std::size_t k = 0; k < count; ++k) {
    const std::uint64_t target = littleEndian(ib + k * isize, isize);
    if (target >= a.count)
      return f_.fail(ip, fmt::format("index {} (entry {}) is not below the accessor's count {}", target, k, a.count));
    for (std::size_t c = 0; c < comps; ++c)
      out[target * comps + c] =
          static_cast<T>(readComponent(vb + (k * comps + c) * csize, a.componentType, a.normalized));
  }
  return true;
}

/// The primitive's mode (default 4), rejecting points and lines.
bool Loader::readMode(const Json& p, const std::string& ptr, int& mode) {
  std::uint64_t m = 4;
  if (!f_.count(p, ptr, "mode", m, false)) return false;
  static const char* const kNames[] = {"points", "lines", "line loop", "line strip"};
  if (m <= 3)
    return f_.fail(ptr, fmt::format("mode {} ({}) is not triangles; render draws triangles only", m, kNames[m]));
  if (m > 6) return f_.fail(member(ptr, "mode"), fmt::format("mode {} is not a glTF primitive mode", m));
  mode = static_cast<int>(m);
  return true;
}

/// Reads attribute `spec` into `out.vertices` (allocated by POSITION, whose
/// count `count` every other attribute must have).
bool Loader::readAttribute(const Json& attributes, const std::string& ptr, const AttributeSpec& spec,
                           std::uint64_t& count, LocalPrimitive& out) {
  const std::string where = member(ptr, spec.name);
  std::optional<std::size_t> index;
  if (!f_.index(attributes, ptr, spec.name, arrayOf("accessors").size(), "accessors", index)) return false;
  auto a = layout(*index, limits_.maxVertices);
  if (!a) return false;
  if (!formatAllowed(spec.semantic, *a))
    return f_.fail(where, fmt::format("{} is {} of {}; {} must be {}", a->ptr, a->components == 1 ? "SCALAR" :
                                      fmt::format("VEC{}", a->components), componentName(a->componentType),
                                      spec.name, formatWanted(spec.semantic)));
  if (spec.semantic == Semantic::Position) {
    count = a->count;
    out.vertices.assign(count * kVertexFloats, 0.0f);
    for (std::size_t v = 0; v < count; ++v) std::fill_n(out.vertices.data() + v * kVertexFloats + kColorOffset, 4, 1.0f);
  } else if (a->count != count) {
    return f_.fail(where, fmt::format("{} has count {}, POSITION {}; a primitive's attributes have one count",
                                      a->ptr, a->count, count));
  }
  std::vector<float> values;
  if (!decode(*a, values)) return false;
  const std::size_t comps = static_cast<std::size_t>(a->components);
  for (std::size_t v = 0; v < count; ++v)
    for (std::size_t c = 0; c < comps; ++c) {
      const float x = values[v * comps + c];
      if (spec.semantic == Semantic::Position && !std::isfinite(x))
        return f_.fail(where, fmt::format("{} element {} is not finite", a->ptr, v));
      out.vertices[v * kVertexFloats + spec.offset + c] = x;
    }
  return true;
}

/// The primitive's triangles as a list: its indices (each checked below
/// `vertexCount`) or 0..vertexCount-1, strips and fans converted.
bool Loader::readIndices(const Json& p, const std::string& ptr, std::size_t vertexCount, int mode,
                         std::vector<std::uint32_t>& out) {
  std::optional<std::size_t> index;
  if (!f_.index(p, ptr, "indices", arrayOf("accessors").size(), "accessors", index)) return false;
  const std::string where = member(ptr, "indices");
  if (!index) {
    out.resize(vertexCount);
    std::iota(out.begin(), out.end(), 0u);
  } else {
    auto a = layout(*index, limits_.maxIndices);
    if (!a) return false;
    if (a->components != 1 || a->normalized || (a->componentType != 5121 && a->componentType != 5123 &&
                                                 a->componentType != 5125))
      return f_.fail(where, fmt::format("{} must be a SCALAR of unsigned byte, short or int", a->ptr));
    if (!decode(*a, out)) return false;
    for (std::size_t i = 0; i < out.size(); ++i)
      if (out[i] >= vertexCount)
        return f_.fail(where, fmt::format("{} index {} (element {}) is not below the vertex count {}", a->ptr, out[i],
                                          i, vertexCount));
  }
  if (mode == 4 && out.size() % 3 != 0)
    return f_.fail(index ? where : ptr, fmt::format("{} {} not whole triangles (a multiple of 3)", out.size(),
                                                    index ? "indices are" : "vertices without indices are"));
  if (mode != 4) {
    if (out.size() >= 3 && (out.size() - 2) > limits_.maxIndices / 3)
      return f_.fail(where, fmt::format("{} triangles exceed MeshLimits::maxIndices {}", out.size() - 2,
                                        limits_.maxIndices));
    out = triangulate(out, mode);
  }
  return true;
}

/// Decodes one primitive in its mesh's space: attributes, indices, flat
/// normals when it has none, tangents generated when it has none.
bool Loader::buildPrimitive(const Json& p, const std::string& ptr, LocalPrimitive& out) {
  int mode = 4;
  std::optional<std::size_t> material;
  if (!f_.object(p, ptr) || !readMode(p, ptr, mode) ||
      !f_.index(p, ptr, "material", arrayOf("materials").size(), "materials", material))
    return false;
  out.material = material ? static_cast<int>(*material) : -1;
  const std::string ap = member(ptr, "attributes");
  auto attrs = p.find("attributes");
  if (attrs == p.end()) return f_.fail(ptr, "\"attributes\" is missing");
  if (!f_.object(*attrs, ap)) return false;
  if (!attrs->contains("POSITION")) return f_.fail(ap, "no POSITION attribute (render needs positions)");
  std::uint64_t count = 0;
  for (const AttributeSpec& spec : kAttributes)
    if (attrs->contains(spec.name) && !readAttribute(*attrs, ap, spec, count, out)) return false;
  if (!readIndices(p, ptr, static_cast<std::size_t>(count), mode, out.indices)) return false;
  const bool normals = attrs->contains("NORMAL");
  if (!normals) {
    if (out.indices.size() > limits_.maxVertices)
      return f_.fail(ptr, fmt::format("flat normals need {} vertices, over MeshLimits::maxVertices {}",
                                      out.indices.size(), limits_.maxVertices));
    flattenNormals(out);
  }
  // glTF: without normals, given tangents are ignored.
  const bool tangents = normals && attrs->contains("TANGENT");
  sanitizeVertices(out, tangents);
  if (!tangents) {
    generateTangents(out.vertices, out.indices);
    out.generatedTangents = true;
  }
  return true;
}

/// Primitive `prim` of mesh `mesh` decoded (once; later instances share it); null after an error.
std::shared_ptr<const LocalPrimitive> Loader::localPrimitive(std::size_t mesh, std::size_t prim, const Json& p,
                                                             const std::string& ptr) {
  const auto key = std::make_pair(mesh, prim);
  if (auto it = primitives_.find(key); it != primitives_.end()) return it->second;
  auto lp = std::make_shared<LocalPrimitive>();
  if (!buildPrimitive(p, ptr, *lp)) lp = nullptr;
  else if (lp->indices.empty()) f_.diags().warning(ptr, "the primitive has no triangles; nothing is drawn");
  primitives_[key] = lp;
  return lp;
}

/// The nodes the scene starts from: `scene`'s, else scene 0's, else every node
/// no node lists as a child. `where` names the list for messages.
bool Loader::sceneRoots(std::vector<std::size_t>& roots, std::string& where) {
  const Json& scenes = arrayOf("scenes");
  const std::size_t nodeCount = arrayOf("nodes").size();
  std::optional<std::size_t> chosen;
  if (!f_.index(doc_, "", "scene", scenes.size(), "scenes", chosen)) return false;
  if (!chosen && !scenes.empty()) chosen = 0;
  if (!chosen) {
    std::vector<char> child(nodeCount, 0);
    for (const Json& n : arrayOf("nodes"))
      if (n.is_object() && n.contains("children") && n["children"].is_array())
        for (const Json& c : n["children"])
          if (c.is_number_unsigned() && c.get<std::uint64_t>() < nodeCount) child[c.get<std::size_t>()] = 1;
    for (std::size_t i = 0; i < nodeCount; ++i)
      if (!child[i]) roots.push_back(i);
    where = "";
    return true;
  }
  std::string ptr;
  const Json* s = element("scenes", *chosen, ptr);
  if (!s) return false;
  where = member(ptr, "nodes");
  auto list = s->find("nodes");
  if (list == s->end()) return true;
  if (!list->is_array()) return f_.fail(where, fmt::format("expected an array of node indices, not {}", kindOfJson(*list)));
  for (std::size_t i = 0; i < list->size(); ++i) {
    std::size_t n = 0;
    if (!f_.indexValue((*list)[i], fmt::format("{}/{}", where, i), nodeCount, "nodes", n)) return false;
    roots.push_back(n);
  }
  return true;
}

/// The node's local matrix: `matrix`, or translation * rotation * scale.
bool Loader::nodeMatrix(const Json& node, const std::string& ptr, Mat4& out) {
  if (node.contains("matrix")) return f_.numbers(node, ptr, "matrix", 16, out.data());
  double t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
  if (!f_.numbers(node, ptr, "translation", 3, t) || !f_.numbers(node, ptr, "rotation", 4, q) ||
      !f_.numbers(node, ptr, "scale", 3, s))
    return false;
  const double ql = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (!std::isfinite(ql) || ql < 1e-12) return f_.fail(member(ptr, "rotation"), "the rotation quaternion has no length");
  for (double& c : q) c /= ql;
  out = composeTrs(t, q, s);
  return true;
}

/// Visits node `node` under the world transform `parent`: its mesh and camera,
/// then its children; cycles, depth and the number of visits checked.
bool Loader::visit(std::size_t node, const Mat4& parent, const std::string& from, int depth) {
  const std::string ptr = fmt::format("/nodes/{}", node);
  if (node >= onPath_.size()) return f_.fail(from, fmt::format("node {} does not exist", node));
  if (onPath_[node]) return f_.fail(ptr, fmt::format("node cycle: nodes[{}] is its own ancestor (through {})", node, from));
  if (depth > limits_.maxDepth)
    return f_.fail(ptr, fmt::format("the node hierarchy is deeper than {} (MeshLimits::maxDepth)", limits_.maxDepth));
  if (++visited_ > limits_.maxNodes)
    return f_.fail(ptr, fmt::format("more than {} nodes visited (MeshLimits::maxNodes; instances count)", limits_.maxNodes));
  std::string p;
  const Json* n = element("nodes", node, p);
  Mat4 local = kIdentity;
  std::optional<std::size_t> mesh, camera;
  if (!n || !nodeMatrix(*n, ptr, local) || !f_.index(*n, ptr, "mesh", arrayOf("meshes").size(), "meshes", mesh) ||
      !f_.index(*n, ptr, "camera", arrayOf("cameras").size(), "cameras", camera))
    return false;
  Instance inst;
  inst.world = multiply(parent, local);
  inst.det = determinant3(inst.world);
  inst.mirrored = inst.det < 0;
  if (mesh && !emitMesh(*mesh, inst, ptr)) return false;
  if (camera && !emitCamera(*camera, inst.world, ptr)) return false;
  onPath_[node] = 1;
  const bool ok = visitChildren(*n, ptr, inst.world, depth);
  onPath_[node] = 0;
  return ok;
}

/// Visits the children of the node at `ptr` under its world transform.
bool Loader::visitChildren(const Json& node, const std::string& ptr, const Mat4& world, int depth) {
  auto children = node.find("children");
  if (children == node.end()) return true;
  const std::string cp = member(ptr, "children");
  if (!children->is_array()) return f_.fail(cp, fmt::format("expected an array of node indices, not {}", kindOfJson(*children)));
  for (std::size_t i = 0; i < children->size(); ++i) {
    const std::string from = fmt::format("{}/{}", cp, i);
    std::size_t c = 0;
    if (!f_.indexValue((*children)[i], from, onPath_.size(), "nodes", c) || !visit(c, world, from, depth + 1))
      return false;
  }
  return true;
}

/// Emits every primitive of mesh `mesh` under the node at `nodePtr`.
bool Loader::emitMesh(std::size_t mesh, const Instance& inst, const std::string& nodePtr) {
  std::string ptr;
  const Json* m = element("meshes", mesh, ptr);
  if (!m) return false;
  auto prims = m->find("primitives");
  if (prims == m->end() || !prims->is_array())
    return f_.fail(prims == m->end() ? ptr : member(ptr, "primitives"), "expected a \"primitives\" array");
  for (std::size_t i = 0; i < prims->size(); ++i) {
    const std::string pp = fmt::format("{}/primitives/{}", ptr, i);
    auto lp = localPrimitive(mesh, i, (*prims)[i], pp);
    if (!lp) return false;
    if (!lp->indices.empty() && !emitPrimitive(*lp, inst, pp, nodePtr)) return false;
  }
  return true;
}

/// Appends one instance of `lp` in world space, within the vertex and index limits.
bool Loader::emitPrimitive(const LocalPrimitive& lp, const Instance& inst, const std::string& primPtr,
                           const std::string& nodePtr) {
  const std::size_t nv = lp.vertices.size() / kVertexFloats, ni = lp.indices.size();
  if (nv > limits_.maxVertices - std::min(scene_.vertexCount, limits_.maxVertices))
    return f_.fail(nodePtr, fmt::format("{} under this node brings the vertices to {}, over the limit of {} "
                                        "(MeshLimits::maxVertices)", primPtr, scene_.vertexCount + nv,
                                        limits_.maxVertices));
  if (ni > limits_.maxIndices - std::min(scene_.indexCount, limits_.maxIndices))
    return f_.fail(nodePtr, fmt::format("{} under this node brings the indices to {}, over the limit of {} "
                                        "(MeshLimits::maxIndices)", primPtr, scene_.indexCount + ni,
                                        limits_.maxIndices));
  Primitive out;
  out.vertices = lp.vertices;
  out.indices = lp.indices;
  out.material = lp.material;
  out.location = primPtr;
  out.node = nodePtr;
  out.generatedNormals = lp.generatedNormals;
  out.generatedTangents = lp.generatedTangents;
  if (!transformVertices(out, inst)) return false;
  scene_.vertexCount += nv;
  scene_.indexCount += ni;
  scene_.primitives.push_back(std::move(out));
  return true;
}

/// Transforms `out`'s vertices to world space (normals by the inverse
/// transpose, tangents by the matrix with w flipped and the winding reversed
/// under a mirroring), and sets its bounds.
bool Loader::transformVertices(Primitive& out, const Instance& inst) {
  constexpr double kMax = std::numeric_limits<float>::max();
  const double sign = inst.mirrored ? -1 : 1;
  out.boundsMin = {kMax, kMax, kMax};
  out.boundsMax = {-kMax, -kMax, -kMax};
  for (std::size_t v = 0; v < out.vertices.size(); v += kVertexFloats) {
    float* x = out.vertices.data() + v;
    const Vec3 p = transformPoint(inst.world, load3(x + kPositionOffset));
    for (int i = 0; i < 3; ++i) {
      if (!(std::fabs(p[i]) <= kMax))
        return f_.fail(out.node, fmt::format("{}: a vertex's world position is not a finite float", out.location));
      out.boundsMin[i] = std::min(out.boundsMin[i], p[i]);
      out.boundsMax[i] = std::max(out.boundsMax[i], p[i]);
    }
    store3(x + kPositionOffset, p);
    const Vec3 n = vec::normalizeOr(vec::scale(cofactorTimes(inst.world, load3(x + kNormalOffset)), sign),
                                    load3(x + kNormalOffset));
    store3(x + kNormalOffset, n);
    store3(x + kTangentOffset, vec::orthonormalTo(transformDirection(inst.world, load3(x + kTangentOffset)), n));
    x[kTangentOffset + 3] = static_cast<float>(x[kTangentOffset + 3] * sign);
  }
  if (inst.mirrored)
    for (std::size_t t = 0; t + 2 < out.indices.size(); t += 3) std::swap(out.indices[t + 1], out.indices[t + 2]);
  return true;
}

/// Reads a perspective camera's projection into `out`.
bool Loader::perspective(const Json& cam, const std::string& ptr, Camera& out) {
  const std::string pp = member(ptr, "perspective");
  auto p = cam.find("perspective");
  if (p == cam.end()) return f_.fail(ptr, "\"perspective\" is missing");
  if (!f_.object(*p, pp) || !f_.number(*p, pp, "yfov", out.yfov, true) ||
      !f_.number(*p, pp, "znear", out.znear, true) || !f_.number(*p, pp, "zfar", out.zfar, false) ||
      !f_.number(*p, pp, "aspectRatio", out.aspectRatio, false))
    return false;
  const double pi = std::acos(-1.0);
  if (!(out.yfov > 0 && out.yfov < pi)) return f_.fail(member(pp, "yfov"), fmt::format("yfov {} is not in (0, pi)", out.yfov));
  if (!(out.znear > 0)) return f_.fail(member(pp, "znear"), fmt::format("znear {} is not positive", out.znear));
  if (p->contains("zfar") && !(out.zfar > out.znear))
    return f_.fail(member(pp, "zfar"), fmt::format("zfar {} is not beyond znear {}", out.zfar, out.znear));
  if (p->contains("aspectRatio") && !(out.aspectRatio > 0))
    return f_.fail(member(pp, "aspectRatio"), fmt::format("aspectRatio {} is not positive", out.aspectRatio));
  return true;
}

/// Appends camera `camera` as the node at `nodePtr` places it (orthographic ones: a warning, skipped).
bool Loader::emitCamera(std::size_t camera, const Mat4& world, const std::string& nodePtr) {
  std::string ptr, type;
  const Json* c = element("cameras", camera, ptr);
  if (!c || !f_.text(*c, ptr, "type", type, true)) return false;
  if (type == "orthographic") {
    if (warnedCameras_.insert(camera).second)
      f_.diags().warning(ptr, "an orthographic camera; render draws through perspective cameras only, it is skipped");
    return true;
  }
  if (type != "perspective")
    return f_.fail(member(ptr, "type"), fmt::format("type {} is not \"perspective\" or \"orthographic\"",
                                                    quoteForDiagnostic(type)));
  Camera out;
  if (!perspective(*c, ptr, out) || !f_.text(*c, ptr, "name", out.name, false)) return false;
  out.location = ptr;
  const Vec3 position = transformPoint(world, {0, 0, 0});
  if (!vec::finite(position)) return f_.fail(nodePtr, "the camera's world position is not finite");
  out.position = position;
  out.forward = vec::normalizeOr(transformDirection(world, {0, 0, -1}), Vec3{0, 0, -1});
  out.up = vec::orthonormalTo(transformDirection(world, {0, 1, 0}), out.forward);
  scene_.cameras.push_back(std::move(out));
  return true;
}

std::optional<Scene> Loader::run() {
  if (!readTopLevel()) return std::nullopt;
  std::vector<std::size_t> roots;
  std::string where;
  if (!sceneRoots(roots, where)) return std::nullopt;
  for (std::size_t i = 0; i < roots.size(); ++i)
    if (!visit(roots[i], kIdentity, where.empty() ? fmt::format("/nodes/{}", roots[i]) : fmt::format("{}/{}", where, i), 1))
      return std::nullopt;
  if (f_.diags().errorCount() > errorsBefore_) return std::nullopt;
  for (std::size_t i = 0; i < scene_.primitives.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const Primitive& p = scene_.primitives[i];
      scene_.boundsMin[k] = i == 0 ? p.boundsMin[k] : std::min(scene_.boundsMin[k], p.boundsMin[k]);
      scene_.boundsMax[k] = i == 0 ? p.boundsMax[k] : std::max(scene_.boundsMax[k], p.boundsMax[k]);
    }
  return std::move(scene_);
}

/// The JSON reader's limits for a glTF document: the file limit for the text
/// and its strings (data: URIs hold whole buffers).
ReadLimits documentLimits(const MeshLimits& limits) {
  ReadLimits r;
  r.maxInputBytes = limits.maxFileBytes;
  r.maxStringBytes = limits.maxFileBytes;
  r.maxKeyBytes = 4096;
  return r;
}

}  // namespace

std::optional<Scene> loadGltfSceneFromBytes(const std::string& bytes, const std::string& baseDir,
                                            const MeshLimits& limits, Diagnostics& diags) {
  if (bytes.size() > limits.maxFileBytes) {
    diags.errorAt(0, 0, fmt::format("the document holds {} bytes, over the limit of {} (MeshLimits::maxFileBytes)",
                                    bytes.size(), limits.maxFileBytes));
    return std::nullopt;
  }
  const bool glb = import::looksLikeGlb(bytes);
  std::string json;
  std::optional<std::string> bin;
  if (glb) {
    auto chunk = import::glbJsonChunk(bytes, diags);
    if (!chunk) return std::nullopt;
    json = std::move(*chunk);
    bin = import::glbBinChunk(bytes);
  }
  std::optional<Json> doc;
  try {
    doc = parseJsonDocument(glb ? json : bytes, documentLimits(limits), diags);
  } catch (const std::exception& e) {  // the reader reports its errors; this is a last resort
    diags.errorAt(0, 0, fmt::format("cannot parse the glTF document: {}", e.what()));
  }
  if (!doc) return std::nullopt;
  if (glb) diags.setLocator(nullptr);  // the JSON chunk's lines are not the file's
  try {
    Loader loader(*doc, baseDir, bin ? &*bin : nullptr, limits, diags);
    return loader.run();
  } catch (const std::exception& e) {  // allocation failures, mostly: never past the loader
    diags.errorAt(0, 0, fmt::format("cannot load the glTF geometry: {}", e.what()));
    return std::nullopt;
  }
}

std::optional<Scene> loadGltfScene(const std::string& path, const MeshLimits& limits, Diagnostics& diags) {
  auto bytes = readSourceFile(path, documentLimits(limits), diags);
  if (!bytes) return std::nullopt;
  std::string dir = std::filesystem::path(path).parent_path().string();
  auto scene = loadGltfSceneFromBytes(*bytes, dir.empty() ? "." : dir, limits, diags);
  if (scene) scene->files.insert(scene->files.begin(), path);
  return scene;
}

Camera framingCamera(const Scene& scene, double aspect) {
  const double pi = std::acos(-1.0);
  Vec3 centre{0, 0, 0};
  double radius = 1;
  if (!scene.primitives.empty()) {
    const Vec3 lo{scene.boundsMin[0], scene.boundsMin[1], scene.boundsMin[2]};
    const Vec3 hi{scene.boundsMax[0], scene.boundsMax[1], scene.boundsMax[2]};
    const Vec3 c = vec::scale(vec::add(lo, hi), 0.5);
    const double r = 0.5 * vec::length(vec::sub(hi, lo));
    if (vec::finite(c)) centre = c;
    radius = std::isfinite(r) && r > 0 ? r : 1e-3;
  }
  if (!(aspect > 0) || !std::isfinite(aspect)) aspect = 1;
  Camera cam;
  cam.name = "frame";
  cam.yfov = 35.0 * pi / 180.0;
  // The half angle of the smaller image side; the sphere's silhouette at 90 % of it.
  const double halfTan = std::tan(cam.yfov / 2) * std::min(1.0, aspect);
  const double distance = radius / std::sin(std::atan(0.9 * halfTan));
  const double elevation = 15.0 * pi / 180.0, azimuth = 20.0 * pi / 180.0;
  const Vec3 back{std::sin(azimuth) * std::cos(elevation), std::sin(elevation), std::cos(azimuth) * std::cos(elevation)};
  cam.position = vec::add(centre, vec::scale(back, distance));
  cam.forward = vec::scale(back, -1);
  cam.up = vec::orthonormalTo(Vec3{0, 1, 0}, cam.forward);
  cam.znear = distance / 100;
  cam.zfar = 0;
  return cam;
}

}  // namespace substratec::mesh
