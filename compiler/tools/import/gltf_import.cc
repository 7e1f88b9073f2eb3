#include "import/gltf_import.h"

#include <cctype>
#include <cmath>
#include <filesystem>
#include <map>
#include <tuple>

#include <fmt/format.h>

#include "blocks/gltf_pbr.h"
#include "import/gltf_resources.h"

namespace substratec::import {

namespace {

constexpr int kRepeat = 10497;
constexpr double kBig = 1e30;  // no upper bound on a factor

std::string wrapName(int mode) {
  switch (mode) {
    case 10497: return "REPEAT";
    case 33071: return "CLAMP_TO_EDGE";
    case 33648: return "MIRRORED_REPEAT";
    case -1: return "(not a wrap mode)";
  }
  return std::to_string(mode);
}

/// An index or enum `j[key]`: a non-negative integer of at most 2^31 - 1, else
/// -1 (a float, a string, a huge number: never converted out of range).
int smallIndex(const Json& j, const char* key, int absent = -1) {
  auto it = j.find(key);
  if (it == j.end()) return absent;
  if (!it->is_number_integer()) return -1;
  if (it->is_number_unsigned()) return it->get<std::uint64_t>() <= 0x7fffffffu ? static_cast<int>(it->get<std::uint64_t>()) : -1;
  const long long v = it->get<long long>();
  return v >= 0 && v <= 0x7fffffff ? static_cast<int>(v) : -1;
}

/// How a factor becomes a value: always an input when given (Plain), or a
/// literal at the values that switch its feature off or fully on (Switch:
/// 0 and 1 for a weight; the neutral colour for a colour), so the compiler can
/// cull what the switch turns off.
enum class Kind { Plain, Switch };

/// factor · texture channel, without the product when the factor is the literal 1 or 0.
Value times(const Value& factor, const Value& texture) {
  if (isLiteral(factor, 1)) return texture;
  if (isLiteral(factor, 0) && literalOf(factor)->size() == 1) return 0.0;
  return mul(factor, texture);
}

/// Where a document's embedded images come from, and the stem their file names take.
struct EmbeddedSource {
  const std::string* glbBin;  // a .glb's binary chunk (null: none)
  std::string stem;
};

/// `stem` with characters other than letters, digits, '-', '_' and '.' as '_'
/// ("image" when nothing is left): a file name in any file system.
std::string sanitizeFileStem(std::string stem) {
  for (char& c : stem)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_' && c != '.') c = '_';
  return stem.empty() || stem[0] == '.' ? "image" + stem : stem;
}

/// Reads one material into GltfPbr, writing its inputs and value nodes.
class MaterialReader {
 public:
  MaterialReader(const Json& doc, const Json& material, std::string pointer, std::string label, Diagnostics& d,
                 MaterialWriter& w, const EmbeddedSource& embedded)
      : doc_(doc), m_(material), ptr_(std::move(pointer)), label_(std::move(label)), d_(d), w_(w), embedded_(embedded) {}

  /// The embedded images the material's texture inputs name as their `file`.
  std::map<std::string, std::string>& images() { return images_; }

  /// Reads the core material, then each extension by its reader.
  bool read(GltfPbr& g);

 private:
  /// An extension's reader: (extension object, its pointer, its name, into).
  using ExtensionReader = void (MaterialReader::*)(const Json&, const std::string&, const std::string&, GltfPbr&);
  static const std::map<std::string, ExtensionReader>& extensionReaders();
  void readAlpha(GltfPbr& g);
  /// pbrMetallicRoughness, the normal and occlusion textures and the emissive factor.
  void readCore(GltfPbr& g);
  void readEmissiveStrength(const Json& ext, const std::string& xp, const std::string& name, GltfPbr& g);
  void readIor(const Json& ext, const std::string& xp, const std::string& name, GltfPbr& g);
  void readSpecular(const Json& ext, const std::string& xp, const std::string& name, GltfPbr& g);
  void readClearcoat(const Json& ext, const std::string& xp, const std::string& name, GltfPbr& g);
  void readSheen(const Json& ext, const std::string& xp, const std::string& name, GltfPbr& g);
  void readTransmission(const Json& ext, const std::string& xp, const std::string& name, GltfPbr& g);
  void readVolume(const Json& ext, const std::string& xp, const std::string& name, GltfPbr& g);
  void readIridescence(const Json& ext, const std::string& xp, const std::string& name, GltfPbr& g);
  void readAnisotropy(const Json& ext, const std::string& xp, const std::string& name, GltfPbr& g);
  void readDispersion(const Json& ext, const std::string& xp, const std::string& name, GltfPbr& g);
  void readDiffuseTransmission(const Json& ext, const std::string& xp, const std::string& name, GltfPbr& g);
  void readUnlit(const Json& ext, const std::string& xp, const std::string& name, GltfPbr& g);
  void readCoat(const Json& ext, const std::string& xp, const std::string& name, GltfPbr& g);
  void readFuzz(const Json& ext, const std::string& xp, const std::string& name, GltfPbr& g);
  void readDiffuseRoughness(const Json& ext, const std::string& xp, const std::string& name, GltfPbr& g);
  /// factor times the `channel` of the textureInfo ext[key] when it is given.
  Value textured(const Value& factor, const Json& ext, const char* key, const std::string& xp, bool srgb,
                 const char* channel);

  void warn(const std::string& pointer, const std::string& what) {
    d_.warning(pointer, fmt::format("material {}: {}", label_, what));
  }
  void error(const std::string& pointer, const std::string& what) {
    d_.error(pointer, what);
    ok_ = false;
  }

  const Json* object(const Json& parent, const char* key, const std::string& ptr);
  std::optional<double> number(const Json& parent, const char* key, const std::string& ptr, double lo, double hi);
  std::optional<std::vector<double>> numbers(const Json& parent, const char* key, const std::string& ptr,
                                             std::size_t n, double lo, double hi);
  Value scalar(const Json& parent, const char* key, const std::string& ptr, double def, double lo, double hi,
               Kind kind, const std::string& what);
  Value color(const Json& parent, const char* key, const std::string& ptr, std::vector<double> def, double neutral,
              Kind kind, const std::string& what, double hi = 1);
  /// The sample node of the textureInfo `parent[key]` (null when absent).
  Value sample(const Json& parent, const char* key, const std::string& ptr, bool srgb);
  /// A tangent-space normal from a normal textureInfo (its `scale` an input).
  Value normalFrom(const Json& parent, const char* key, const std::string& ptr);
  Value uvOf(const Json& info, const std::string& ptr);
  std::string imageDescription(int texture);
  std::string imageFile(int texture);
  /// Texture `texture`'s image index (its own `source`, or an extension's,
  /// e.g. KHR_texture_basisu; -1 for none) and " (<extension>)" for each
  /// extension that gives one.
  std::pair<int, std::string> imageSource(int texture) const;
  /// Texture `texture`'s sampler as the format spells it: wrap u, wrap v, nearest.
  std::tuple<std::string, std::string, bool> sampling(int texture) const;

  const Json& doc_;
  const Json& m_;
  std::string ptr_, label_;
  Diagnostics& d_;
  MaterialWriter& w_;
  bool ok_ = true;
  std::map<std::pair<int, bool>, Value> inputs_;  // (texture index, sRGB) -> "$input"
  const EmbeddedSource& embedded_;
  std::map<std::string, std::string> images_;  // file name -> bytes, of embedded images
  std::map<std::string, Value> samples_;          // input + uv -> sample node
};

const Json* MaterialReader::object(const Json& parent, const char* key, const std::string& ptr) {
  auto it = parent.find(key);
  if (it == parent.end()) return nullptr;
  if (!it->is_object()) {
    error(ptr + "/" + key, "expected an object");
    return nullptr;
  }
  return &*it;
}

std::optional<double> MaterialReader::number(const Json& parent, const char* key, const std::string& ptr, double lo,
                                             double hi) {
  auto it = parent.find(key);
  if (it == parent.end()) return std::nullopt;
  const std::string p = ptr + "/" + key;
  if (!it->is_number()) {
    error(p, "expected a number");
    return std::nullopt;
  }
  double v = it->get<double>();
  if (v < lo || v > hi) {
    const double c = std::clamp(v, lo, hi);
    warn(p, fmt::format("{} is {}, outside [{}, {}]: clamped to {}", key, v, lo, hi, c));
    v = c;
  }
  return v;
}

std::optional<std::vector<double>> MaterialReader::numbers(const Json& parent, const char* key,
                                                           const std::string& ptr, std::size_t n, double lo,
                                                           double hi) {
  auto it = parent.find(key);
  if (it == parent.end()) return std::nullopt;
  const std::string p = ptr + "/" + key;
  if (!it->is_array() || it->size() != n) {
    error(p, fmt::format("expected an array of {} numbers", n));
    return std::nullopt;
  }
  std::vector<double> v;
  for (std::size_t i = 0; i < n; ++i) {
    if (!(*it)[i].is_number()) {
      error(p + "/" + std::to_string(i), "expected a number");
      return std::nullopt;
    }
    double x = (*it)[i].get<double>();
    if (x < lo || x > hi) {
      const double c = std::clamp(x, lo, hi);
      warn(p + "/" + std::to_string(i), fmt::format("{}[{}] is {}, outside [{}, {}]: clamped to {}", key, i, x, lo, hi, c));
      x = c;
    }
    v.push_back(x);
  }
  return v;
}

Value MaterialReader::scalar(const Json& parent, const char* key, const std::string& ptr, double def, double lo,
                             double hi, Kind kind, const std::string& what) {
  const auto v = number(parent, key, ptr, lo, hi);
  if (!v) return def;
  if (kind == Kind::Switch && (*v == 0 || *v == 1)) return *v;
  return w_.floatInput(key, *v, lo, hi >= 1e300 ? std::optional<double>() : std::optional<double>(hi), what);
}

Value MaterialReader::color(const Json& parent, const char* key, const std::string& ptr, std::vector<double> def,
                            double neutral, Kind kind, const std::string& what, double hi) {
  const auto v = numbers(parent, key, ptr, 3, 0, hi);
  if (!v) return literal(def);
  if (kind == Kind::Switch && std::all_of(v->begin(), v->end(), [neutral](double x) { return x == neutral; }))
    return literal(*v);
  return w_.colorInput(key, *v, what);
}

std::tuple<std::string, std::string, bool> MaterialReader::sampling(int texture) const {
  const Json& t = doc_["textures"][texture];
  const Json samplers = doc_.value("samplers", Json::array());
  const int si = t.contains("sampler") ? smallIndex(t, "sampler") : -1;
  if (!samplers.is_array() || si < 0 || si >= static_cast<int>(samplers.size()) || !samplers[si].is_object())
    return {"repeat", "repeat", false};
  auto mode = [](int m) { return m == 33071 ? "clamp" : m == 33648 ? "mirror" : "repeat"; };
  const Json& s = samplers[si];
  return {mode(smallIndex(s, "wrapS", kRepeat)), mode(smallIndex(s, "wrapT", kRepeat)),
          smallIndex(s, "magFilter", 9729) == 9728};  // NEAREST
}

/// The image file of texture `texture`: a path relative to the document (its
/// percent-decoded URI); for an embedded image (a data: URI or a buffer view)
/// "<document stem>_image<N>.<ext>", its bytes kept in images_; "" when it has
/// no image (imageDescription reports a bad source) or its bytes cannot be had
/// (a warning).
std::string MaterialReader::imageFile(int texture) {
  const int source = imageSource(texture).first;
  const Json images = doc_.value("images", Json::array());
  if (source < 0 || !images.is_array() || source >= static_cast<int>(images.size()) || !images[source].is_object())
    return "";
  const Json& img = images[source];
  std::string why;
  if (auto e = embeddedImage(doc_, source, embedded_.glbBin, &why)) {
    const std::string name = fmt::format("{}_image{}.{}", embedded_.stem, source, e->extension);
    images_[name] = std::move(e->bytes);
    return name;
  }
  if (!why.empty()) {
    warn(fmt::format("/images/{}", source), fmt::format("the embedded image cannot be read: {}", why));
    return "";
  }
  if (!img.contains("uri") || !img["uri"].is_string()) return "";
  return uriPath(img["uri"].get<std::string>()).value_or("");
}

std::pair<int, std::string> MaterialReader::imageSource(int texture) const {
  const Json& t = doc_["textures"][texture];
  std::pair<int, std::string> out{t.contains("source") ? smallIndex(t, "source") : -1, ""};
  if (auto e = t.find("extensions"); e != t.end() && e->is_object())
    for (const auto& [name, ext] : e->items())
      if (ext.is_object() && ext.contains("source") && ext["source"].is_number_integer()) {
        out.first = smallIndex(ext, "source");
        out.second += " (" + name + ")";
      }
  return out;
}

std::string MaterialReader::imageDescription(int texture) {
  const Json& t = doc_["textures"][texture];
  const auto [source, extensions] = imageSource(texture);
  std::string out = fmt::format("textures[{}]{}", texture, extensions);
  const Json images = doc_.value("images", Json::array());
  if (source < 0 || !images.is_array() || source >= static_cast<int>(images.size()) || !images[source].is_object()) {
    error(fmt::format("/textures/{}/source", texture),
          fmt::format("expected the index of one of the document's {} images", images.is_array() ? images.size() : 0));
    return out;
  }
  {
    const Json& img = images[source];
    std::string label;
    if (img.contains("uri") && img["uri"].is_string()) {
      std::string uri = img["uri"].get<std::string>();
      if (uri.rfind("data:", 0) == 0 || uri == "<embedded>") label = "embedded";
      else label = uri.substr(uri.find_last_of('/') == std::string::npos ? 0 : uri.find_last_of('/') + 1);
    } else if (img.contains("name") && img["name"].is_string()) {
      label = descriptionText(img["name"].get<std::string>());
    } else {
      label = "bufferView";
    }
    out += fmt::format(", images[{}] '{}'", source, label);
  }
  if (auto s = t.find("sampler"); s != t.end() && s->is_number_integer()) {
    const Json samplers = doc_.value("samplers", Json::array());
    const int si = smallIndex(t, "sampler");
    if (samplers.is_array() && si >= 0 && si < static_cast<int>(samplers.size()) && samplers[si].is_object()) {
      const int ws = smallIndex(samplers[si], "wrapS", kRepeat), wt = smallIndex(samplers[si], "wrapT", kRepeat);
      if (ws != kRepeat || wt != kRepeat) out += fmt::format(", wrap {}/{}", wrapName(ws), wrapName(wt));
    }
  }
  return out;
}

Value MaterialReader::uvOf(const Json& info, const std::string& ptr) {
  int set = 0;
  if (auto v = number(info, "texCoord", ptr, 0, 1e9)) set = static_cast<int>(*v);
  const Json* ext = info.contains("extensions") && info["extensions"].is_object() ? &info["extensions"] : nullptr;
  const Json* tt = nullptr;
  if (ext) tt = object(*ext, "KHR_texture_transform", ptr + "/extensions");
  const std::string tptr = ptr + "/extensions/KHR_texture_transform";
  if (tt)
    if (auto v = number(*tt, "texCoord", tptr, 0, 1e9)) set = static_cast<int>(*v);
  if (set > 1) {
    warn(ptr, fmt::format("texCoord {} : a material reads uv0 and uv1 only; uv1 is used", set));
    set = 1;
  }
  Value uv = set == 0 ? Value() : geometry("uv1");
  if (!tt) return uv;
  const auto offset = numbers(*tt, "offset", tptr, 2, -1e30, 1e30).value_or(std::vector<double>{0, 0});
  const auto scale = numbers(*tt, "scale", tptr, 2, -1e30, 1e30).value_or(std::vector<double>{1, 1});
  const double rotation = number(*tt, "rotation", tptr, -1e30, 1e30).value_or(0);
  const Value base = uv.is_null() ? geometry("uv0") : uv;
  if (rotation == 0) {
    // uv' = uv · scale + offset
    return add(mul(base, literal(scale)), literal(offset));
  }
  // uv' = T · R · S · uv with R = [cos sin; −sin cos] (KHR_texture_transform).
  const double c = std::cos(rotation), s = std::sin(rotation);
  const Value u = Json{{"kind", "dot"}, {"a", base}, {"b", literal({c * scale[0], s * scale[1]})}};
  const Value v = Json{{"kind", "dot"}, {"a", base}, {"b", literal({-s * scale[0], c * scale[1]})}};
  return combine({add(u, offset[0]), add(v, offset[1])});
}

Value MaterialReader::sample(const Json& parent, const char* key, const std::string& parentPtr, bool srgb) {
  const std::string ptr = parentPtr + "/" + key;
  const Json* info = object(parent, key, parentPtr);
  if (!info) return Value();
  const auto idx = info->find("index");
  const int count = doc_.contains("textures") && doc_["textures"].is_array() ? static_cast<int>(doc_["textures"].size()) : 0;
  if (idx == info->end() || !idx->is_number_integer() || idx->get<long long>() < 0 || idx->get<long long>() >= count) {
    error(ptr + "/index", fmt::format("expected the index of one of the document's {} textures", count));
    return Value();
  }
  const int texture = idx->get<int>();
  if (!doc_["textures"][texture].is_object()) {
    error(fmt::format("/textures/{}", texture), "expected an object");
    return Value();
  }
  Value& input = inputs_[{texture, srgb}];
  if (input.is_null()) {
    const auto [wrapU, wrapV, nearest] = sampling(texture);
    input = w_.textureInput(key, srgb, imageDescription(texture), imageFile(texture), wrapU, wrapV, nearest);
  }
  const Value uv = uvOf(*info, ptr);
  Value& node = samples_[input.get<std::string>() + "|" + uv.dump()];
  if (node.is_null()) node = w_.node(input.get<std::string>().substr(1) + "_sample", textureSample(input, uv));
  return node;
}

Value MaterialReader::normalFrom(const Json& parent, const char* key, const std::string& ptr) {
  const Value tex = sample(parent, key, ptr, false);
  if (tex.is_null()) return Value();
  // n = vnormalize((2·rgb − 1) · (scale, scale, 1))
  Value n = sub(mul(outputOf(tex, "rgb"), 2.0), 1.0);
  const Json& info = parent[key];
  const std::string what = fmt::format("{}.scale: the normal map's strength", key);
  const std::string name = std::string(key) + "_scale";
  if (auto s = number(info, "scale", ptr + "/" + key, -1e30, 1e30); s && *s != 1) {
    const Value scale = w_.floatInput(name, *s, std::nullopt, std::nullopt, what);
    n = mul(n, combine({scale, scale, 1.0}));
  }
  return vnormalize(n);
}

bool MaterialReader::read(GltfPbr& g) {
  readAlpha(g);
  readCore(g);
  const Json* exts = object(m_, "extensions", ptr_);
  const std::string ep = ptr_ + "/extensions";
  if (exts) {
    for (const auto& [name, ext] : exts->items()) {
      const std::string xp = ep + "/" + pointerToken(name);
      if (!ext.is_object()) {
        error(xp, "expected an object");
        continue;
      }
      const auto& readers = extensionReaders();
      if (auto r = readers.find(name); r != readers.end()) (this->*(r->second))(ext, xp, name, g);
      else warn(xp, fmt::format("extension {} is not imported; ignored", name));
    }
  }
  if (isLiteral(g.emissive, 0)) g.emissive = Value();
  if (g.unlit && exts && exts->size() > 1)
    warn(ep, "KHR_materials_unlit: the material is its base colour, unlit; its other extensions are ignored");
  return ok_;
}

void MaterialReader::readAlpha(GltfPbr& g) {
  std::string alphaMode = "OPAQUE";
  if (auto a = m_.find("alphaMode"); a != m_.end()) {
    if (!a->is_string() || (*a != "OPAQUE" && *a != "MASK" && *a != "BLEND"))
      error(ptr_ + "/alphaMode", "expected \"OPAQUE\", \"MASK\" or \"BLEND\"");
    else alphaMode = a->get<std::string>();
  }
  g.alphaMode = alphaMode == "MASK" ? AlphaMode::Mask : alphaMode == "BLEND" ? AlphaMode::Blend : AlphaMode::Opaque;
  g.alphaCutoff = number(m_, "alphaCutoff", ptr_, 0, kBig).value_or(0.5);
  if (g.alphaMode != AlphaMode::Mask && m_.contains("alphaCutoff"))
    warn(ptr_ + "/alphaCutoff", "alphaCutoff applies to alphaMode MASK only; ignored");
}

void MaterialReader::readCore(GltfPbr& g) {
  const Json empty = Json::object();
  const Json* pbr = object(m_, "pbrMetallicRoughness", ptr_);
  const std::string pp = ptr_ + "/pbrMetallicRoughness";
  const Json& p = pbr ? *pbr : empty;

  // Base colour and alpha.
  const auto bc = numbers(p, "baseColorFactor", pp, 4, 0, 1);
  Value baseFactor = literal3(1, 1, 1), alphaFactor = 1.0;
  if (bc) {
    baseFactor = w_.colorInput("baseColorFactor", {(*bc)[0], (*bc)[1], (*bc)[2]}, "pbrMetallicRoughness.baseColorFactor (rgb)");
    if (g.alphaMode != AlphaMode::Opaque)
      alphaFactor = w_.floatInput("baseColorFactor_alpha", (*bc)[3], 0.0, 1.0, "pbrMetallicRoughness.baseColorFactor (alpha)");
  }
  const Value baseTex = sample(p, "baseColorTexture", pp, true);
  g.baseColor = baseTex.is_null() ? baseFactor : times(baseFactor, outputOf(baseTex, "rgb"));
  g.alpha = baseTex.is_null() ? alphaFactor : times(alphaFactor, outputOf(baseTex, "a"));
  if (g.alphaMode == AlphaMode::Opaque) g.alpha = Value();

  g.metallic = scalar(p, "metallicFactor", pp, 1, 0, 1, Kind::Switch, "pbrMetallicRoughness.metallicFactor");
  g.roughness = scalar(p, "roughnessFactor", pp, 1, 0, 1, Kind::Plain, "pbrMetallicRoughness.roughnessFactor");
  if (const Value mr = sample(p, "metallicRoughnessTexture", pp, false); !mr.is_null()) {
    g.metallic = times(g.metallic, outputOf(mr, "b"));
    g.roughness = times(g.roughness, outputOf(mr, "g"));
  }
  g.normal = normalFrom(m_, "normalTexture", ptr_);
  if (m_.contains("occlusionTexture"))
    warn(ptr_ + "/occlusionTexture", "occlusionTexture: ambient occlusion is the renderer's (a Substrate material "
                                     "has no occlusion pin); ignored");

  g.emissive = color(m_, "emissiveFactor", ptr_, {0, 0, 0}, 0, Kind::Switch, "emissiveFactor", kBig);
  const Value emissiveTex = sample(m_, "emissiveTexture", ptr_, true);
  if (!isLiteral(g.emissive, 0) && !emissiveTex.is_null()) g.emissive = times(g.emissive, outputOf(emissiveTex, "rgb"));
}

Value MaterialReader::textured(const Value& factor, const Json& ext, const char* key, const std::string& xp, bool srgb,
                               const char* channel) {
  const Value t = sample(ext, key, xp, srgb);
  return t.is_null() ? factor : times(factor, outputOf(t, channel));
}

const std::map<std::string, MaterialReader::ExtensionReader>& MaterialReader::extensionReaders() {
  static const std::map<std::string, ExtensionReader> table = {
      {"KHR_materials_emissive_strength", &MaterialReader::readEmissiveStrength},
      {"KHR_materials_ior", &MaterialReader::readIor},
      {"KHR_materials_specular", &MaterialReader::readSpecular},
      {"KHR_materials_clearcoat", &MaterialReader::readClearcoat},
      {"KHR_materials_sheen", &MaterialReader::readSheen},
      {"KHR_materials_transmission", &MaterialReader::readTransmission},
      {"KHR_materials_volume", &MaterialReader::readVolume},
      {"KHR_materials_iridescence", &MaterialReader::readIridescence},
      {"KHR_materials_anisotropy", &MaterialReader::readAnisotropy},
      {"KHR_materials_dispersion", &MaterialReader::readDispersion},
      {"KHR_materials_diffuse_transmission", &MaterialReader::readDiffuseTransmission},
      {"KHR_materials_unlit", &MaterialReader::readUnlit},
      {"KHR_materials_coat", &MaterialReader::readCoat},
      {"KHR_materials_fuzz", &MaterialReader::readFuzz},
      {"KHR_materials_diffuse_roughness", &MaterialReader::readDiffuseRoughness}};
  return table;
}

void MaterialReader::readEmissiveStrength(const Json& ext, const std::string& xp, const std::string& name, GltfPbr& g) {
  const Value strength = scalar(ext, "emissiveStrength", xp, 1, 0, kBig, Kind::Plain, name + ".emissiveStrength");
  if (!isLiteral(g.emissive, 0)) g.emissive = mul(g.emissive, strength);
}

void MaterialReader::readIor(const Json& ext, const std::string& xp, const std::string& name, GltfPbr& g) {
  g.ior = scalar(ext, "ior", xp, 1.5, 0, kBig, Kind::Plain, name + ".ior: index of refraction of the dielectric");
  if (g.ior.is_number() && g.ior.get<double>() == 1.5 && !ext.contains("ior")) g.ior = Value();
}

void MaterialReader::readSpecular(const Json& ext, const std::string& xp, const std::string& name, GltfPbr& g) {
  g.specular = textured(scalar(ext, "specularFactor", xp, 1, 0, 1, Kind::Switch, name + ".specularFactor"), ext,
                        "specularTexture", xp, false, "a");
  g.specularColor = textured(color(ext, "specularColorFactor", xp, {1, 1, 1}, 1, Kind::Switch, name + ".specularColorFactor", kBig),
                             ext, "specularColorTexture", xp, true, "rgb");
}

void MaterialReader::readClearcoat(const Json& ext, const std::string& xp, const std::string& name, GltfPbr& g) {
  g.clearcoat = textured(scalar(ext, "clearcoatFactor", xp, 0, 0, 1, Kind::Switch, name + ".clearcoatFactor"), ext,
                         "clearcoatTexture", xp, false, "r");
  g.clearcoatRoughness =
      textured(scalar(ext, "clearcoatRoughnessFactor", xp, 0, 0, 1, Kind::Plain, name + ".clearcoatRoughnessFactor"), ext,
               "clearcoatRoughnessTexture", xp, false, "g");
  g.clearcoatNormal = normalFrom(ext, "clearcoatNormalTexture", xp);
}

void MaterialReader::readSheen(const Json& ext, const std::string& xp, const std::string& name, GltfPbr& g) {
  g.sheenColor = textured(color(ext, "sheenColorFactor", xp, {0, 0, 0}, 0, Kind::Switch, name + ".sheenColorFactor"), ext,
                          "sheenColorTexture", xp, true, "rgb");
  g.sheenRoughness = textured(scalar(ext, "sheenRoughnessFactor", xp, 0, 0, 1, Kind::Plain, name + ".sheenRoughnessFactor"),
                              ext, "sheenRoughnessTexture", xp, false, "a");
}

void MaterialReader::readTransmission(const Json& ext, const std::string& xp, const std::string& name, GltfPbr& g) {
  g.transmission = textured(scalar(ext, "transmissionFactor", xp, 0, 0, 1, Kind::Switch, name + ".transmissionFactor"),
                            ext, "transmissionTexture", xp, false, "r");
  if (!isLiteral(g.transmission, 0)) warn(xp, name + ": " + kTransmissionNote);
}

void MaterialReader::readVolume(const Json& ext, const std::string& xp, const std::string& name, GltfPbr& g) {
  g.thickness = textured(scalar(ext, "thicknessFactor", xp, 0, 0, kBig, Kind::Plain, name + ".thicknessFactor (metres)"),
                         ext, "thicknessTexture", xp, false, "g");
  g.attenuationDistance = number(ext, "attenuationDistance", xp, 0, kBig).value_or(0);
  g.attenuationColor = color(ext, "attenuationColor", xp, {1, 1, 1}, 1, Kind::Switch, name + ".attenuationColor");
}

void MaterialReader::readIridescence(const Json& ext, const std::string& xp, const std::string& name, GltfPbr& g) {
  g.iridescence = textured(scalar(ext, "iridescenceFactor", xp, 0, 0, 1, Kind::Switch, name + ".iridescenceFactor"), ext,
                           "iridescenceTexture", xp, false, "r");
  g.iridescenceIor = scalar(ext, "iridescenceIor", xp, 1.3, 1, 5, Kind::Plain, name + ".iridescenceIor");
  const Value hi = scalar(ext, "iridescenceThicknessMaximum", xp, 400, 0, kBig, Kind::Plain,
                          name + ".iridescenceThicknessMaximum (nanometres)");
  if (const Value t = sample(ext, "iridescenceThicknessTexture", xp, false); !t.is_null()) {
    const Value lo = scalar(ext, "iridescenceThicknessMinimum", xp, 100, 0, kBig, Kind::Plain,
                            name + ".iridescenceThicknessMinimum (nanometres)");
    g.iridescenceThickness = vlerp(lo, hi, outputOf(t, "g"));
  } else {
    g.iridescenceThickness = hi;
  }
}

void MaterialReader::readAnisotropy(const Json& ext, const std::string& xp, const std::string& name, GltfPbr& g) {
  g.anisotropyStrength = scalar(ext, "anisotropyStrength", xp, 0, 0, 1, Kind::Switch, name + ".anisotropyStrength");
  g.anisotropyRotation = number(ext, "anisotropyRotation", xp, -kBig, kBig).value_or(0);
  if (const Value t = sample(ext, "anisotropyTexture", xp, false); !t.is_null()) {
    g.anisotropyStrength = times(g.anisotropyStrength, outputOf(t, "b"));
    g.anisotropyDirection = sub(mul(swizzle(outputOf(t, "rgb"), "xy"), 2.0), 1.0);
  }
}

void MaterialReader::readDispersion(const Json& ext, const std::string& xp, const std::string& name, GltfPbr&) {
  if (number(ext, "dispersion", xp, 0, kBig).value_or(0) > 0)
    warn(xp, name + ": dispersion (an IOR per wavelength) is not represented; one IOR for every colour");
}

void MaterialReader::readDiffuseTransmission(const Json& ext, const std::string& xp, const std::string& name, GltfPbr& g) {
  g.diffuseTransmission = textured(scalar(ext, "diffuseTransmissionFactor", xp, 0, 0, 1, Kind::Switch,
                                          name + ".diffuseTransmissionFactor"),
                                   ext, "diffuseTransmissionTexture", xp, false, "a");
  g.diffuseTransmissionColor = textured(color(ext, "diffuseTransmissionColorFactor", xp, {1, 1, 1}, 1, Kind::Switch,
                                              name + ".diffuseTransmissionColorFactor"),
                                        ext, "diffuseTransmissionColorTexture", xp, true, "rgb");
  if (!isLiteral(g.diffuseTransmission, 0))
    warn(xp, name + ": light diffusely transmitted through a thin surface is approximated by wrap lighting "
                    "(sss_type wrap, light reaching past the horizon)");
}

void MaterialReader::readUnlit(const Json&, const std::string&, const std::string&, GltfPbr& g) { g.unlit = true; }

void MaterialReader::readCoat(const Json& ext, const std::string& xp, const std::string& name, GltfPbr& g) {
  g.coat = textured(scalar(ext, "coatFactor", xp, 0, 0, 1, Kind::Switch, name + ".coatFactor"), ext, "coatTexture", xp,
                    false, "r");
  g.coatRoughness = textured(scalar(ext, "coatRoughnessFactor", xp, 0, 0, 1, Kind::Plain, name + ".coatRoughnessFactor"),
                             ext, "coatRoughnessTexture", xp, false, "g");
  g.coatIor = scalar(ext, "coatIor", xp, 1.5, 0, kBig, Kind::Plain, name + ".coatIor");
  g.coatColor = textured(color(ext, "coatColorFactor", xp, {1, 1, 1}, 1, Kind::Switch, name + ".coatColorFactor"), ext,
                         "coatColorTexture", xp, true, "rgb");
  g.coatNormal = normalFrom(ext, "coatNormalTexture", xp);
  g.coatAnisotropyStrength = scalar(ext, "coatAnisotropyStrength", xp, 0, 0, 1, Kind::Switch, name + ".coatAnisotropyStrength");
  g.coatAnisotropyRotation = number(ext, "coatAnisotropyRotation", xp, -kBig, kBig).value_or(0);
  if (ext.contains("coatAnisotropyTexture"))
    warn(xp + "/coatAnisotropyTexture", name + ": a textured coat anisotropy direction is not imported; the "
                                               "factors alone are used");
  if (number(ext, "coatDarkeningFactor", xp, 0, 1).value_or(1) > 0 && !isLiteral(g.coat, 0))
    warn(xp, name + ": coat darkening (light trapped under the coat by internal reflection) is not modelled; "
                    "the base is seen through the coat's transmittance only");
}

void MaterialReader::readFuzz(const Json& ext, const std::string& xp, const std::string& name, GltfPbr& g) {
  g.fuzz = textured(scalar(ext, "fuzzFactor", xp, 0, 0, 1, Kind::Switch, name + ".fuzzFactor"), ext, "fuzzTexture", xp,
                    false, "r");
  g.fuzzColor = textured(color(ext, "fuzzColorFactor", xp, {1, 1, 1}, 1, Kind::Plain, name + ".fuzzColorFactor"), ext,
                         "fuzzColorTexture", xp, true, "rgb");
  g.fuzzRoughness = textured(scalar(ext, "fuzzRoughnessFactor", xp, 0.5, 0, 1, Kind::Plain, name + ".fuzzRoughnessFactor"),
                             ext, "fuzzRoughnessTexture", xp, false, "a");
}

void MaterialReader::readDiffuseRoughness(const Json& ext, const std::string& xp, const std::string& name, GltfPbr&) {
  if (number(ext, "diffuseRoughnessFactor", xp, 0, 1).value_or(0) > 0 || ext.contains("diffuseRoughnessTexture"))
    warn(xp, name + ": a slab's diffuse roughness is its specular roughness; the diffuse roughness is ignored");
}

}  // namespace

bool importGltfDocument(const Json& doc, const std::string& fileName, Diagnostics& diags,
                        std::vector<ImportedMaterial>* out, const std::string* glbBin, ImportForm form) {
  if (!doc.is_object()) {
    diags.error("", "expected a glTF document (a JSON object)");
    return false;
  }
  auto mats = doc.find("materials");
  if (mats == doc.end() || !mats->is_array()) {
    diags.error(mats == doc.end() ? "" : "/materials", "expected a \"materials\" array");
    return false;
  }
  for (const char* key : {"textures", "samplers", "images"})
    if (doc.contains(key) && !doc[key].is_array()) {
      diags.error(std::string("/") + key, "expected an array");
      return false;
    }
  bool ok = true;
  NameSet used(/*caseInsensitive=*/true);
  const EmbeddedSource embedded{glbBin, sanitizeFileStem(std::filesystem::path(fileName).stem().string())};
  for (std::size_t i = 0; i < mats->size(); ++i) {
    const std::string ptr = "/materials/" + std::to_string(i);
    const Json& m = (*mats)[i];
    if (!m.is_object()) {
      diags.error(ptr, "expected an object");
      ok = false;
      continue;
    }
    std::string sourceName = m.contains("name") && m["name"].is_string() ? m["name"].get<std::string>() : "";
    const std::string name = uniqueMaterialName(used, sourceName, "material_" + std::to_string(i));
    const std::string label = sourceName.empty() ? fmt::format("materials[{}]", i) : quoteForDiagnostic(sourceName);
    MaterialWriter w(name);
    w.setDescription(fmt::format("Imported from {} materials[{}]{} (glTF 2.0 PBR).", fileName, i,
                                 sourceName.empty() ? "" : " " + quoteForDescription(sourceName)));
    GltfPbr g;
    MaterialReader reader(doc, m, ptr, label, diags, w, embedded);
    if (!reader.read(g)) {
      ok = false;
      continue;
    }
    if (form == ImportForm::Expanded)
      writeLayeredSurface(gltfPbrSurface(g, w), w);
    else
      writeGltfPbrBlock(g, w);
    out->push_back({sourceName, name, ptr, w.text(), std::move(reader.images())});
  }
  return ok;
}

}  // namespace substratec::import
