#include "gpu/gbuffer.h"

#include <cmath>
#include <cstring>
#include <stdexcept>

#include "gpu/sample_run.h"
#include "reference/bsdf.h"
#include "storage/pack.h"
#include "validate/runtime_files.h"

namespace substratec::gpu {

namespace {

/// Copies the fields a reference closure and the packer's ClosureValues share (either way:
/// closureValues packs a closure, closureOf reads one back).
template <class From, class To>
void copySharedFields(const From& from, To& to) {
  to.diffuseAlbedo = from.diffuseAlbedo;
  to.f0 = from.f0;
  to.f90 = from.f90;
  to.roughness = from.roughness;
  to.anisotropy = from.anisotropy;
  to.sssMfp = from.sssMfp;
  to.sssPhaseAnisotropy = from.sssPhaseAnisotropy;
  to.sssType = from.sssType;
  to.secondRoughness = from.secondRoughness;
  to.secondRoughnessWeight = from.secondRoughnessWeight;
  to.fuzzAmount = from.fuzzAmount;
  to.fuzzColor = from.fuzzColor;
  to.fuzzRoughness = from.fuzzRoughness;
  to.glintValue = from.glintValue;
  to.glintUv = from.glintUv;
  to.glintUvDerivatives = from.glintUvDerivatives;
  to.specularProfile = from.specularProfile;
  to.hair = from.hair;
  to.irisN = from.irisN;
  to.irisPlaneN = from.irisPlaneN;
  to.iris = from.iris;
  to.weight = from.weight;
  to.topTransmittance = from.topTransmittance;
  to.coverageAbove = from.coverageAbove;
  to.extraInterfaces = from.extraInterfaces;
}

}  // namespace

ClosureValues closureValues(const reference::Closure<double>& c) {
  ClosureValues v;
  copySharedFields(c, v);
  return v;
}

namespace {

reference::Closure<double> closureOf(const ClosureValues& v, const BasisValues& b) {
  reference::Closure<double> c;
  copySharedFields(v, c);
  c.N = b.normal;
  c.T_ = b.tangent;
  c.features = v.features;
  c.isTop = v.isTop;
  return c;
}

std::vector<std::byte> bytesOf(const std::vector<uint32_t>& w) {
  std::vector<std::byte> b(w.size() * 4);
  std::memcpy(b.data(), w.data(), b.size());
  return b;
}

}  // namespace

BufferResource sceneFrameBlock(const SceneFrame& f) {
  std::vector<float> v;
  auto push = [&](const std::array<double, 3>& a, double w) {
    for (double c : a) v.push_back(static_cast<float>(c));
    v.push_back(static_cast<float>(w));
  };
  push(f.forward, f.tanHalfFov);
  push(f.right, 0);
  push(f.up, 0);
  push(f.light, 0);
  push(f.radiance, 0);
  push({f.envMips, 0, 0}, 0);  // envParams
  BufferResource b;
  b.data.resize(v.size() * 4 + 16);
  std::memcpy(b.data.data(), v.data(), v.size() * 4);
  const uint32_t viewport[4] = {f.width, f.height, f.tiles(), 0};
  std::memcpy(b.data.data() + v.size() * 4, viewport, 16);
  return b;
}

namespace {

ImageResource constantCube(const std::array<double, 3>& c) {
  ImageResource img;
  img.width = img.height = 2;
  img.layers = 6;
  std::vector<float> texels;
  for (int i = 0; i < 2 * 2 * 6; ++i)
    for (double x : {c[0], c[1], c[2], 1.0}) texels.push_back(static_cast<float>(x));
  img.mips = {texels};
  return img;
}

}  // namespace

std::array<double, 3> SceneFrame::view(uint32_t x, uint32_t y) const {
  const double nx = (x + 0.5) / width * 2 - 1, ny = (y + 0.5) / height * 2 - 1;
  const double aspect = double(width) / height;
  std::array<double, 3> d;
  for (int c = 0; c < 3; ++c) d[c] = forward[c] + nx * aspect * tanHalfFov * right[c] - ny * tanHalfFov * up[c];
  const double l = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  return {-d[0] / l, -d[1] / l, -d[2] / l};
}

reference::Geometry pixelGeometry(const SceneFrame& f, uint32_t x, uint32_t y, std::array<double, 2> uv) {
  reference::Geometry g;
  g.V = f.view(x, y);
  std::array<double, 3> n{g.V[0] + 0.3 * std::sin(x * 1.7), g.V[1] + 0.3 * std::cos(y * 2.3), g.V[2]};
  const double ln = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  for (double& c : n) c /= ln;
  g.N = n;
  const double lt = std::sqrt(n[2] * n[2] + n[0] * n[0]);
  g.T = {n[2] / lt, 0, -n[0] / lt};
  g.uv0 = g.uv1 = uv;
  g.uvDerivatives = {1e-3, 0, 0, 1e-3};
  g.dither = std::fmod(0.37 + 0.618033988749895 * (x * 31 + y * 17), 1.0);
  return g;
}

GbufferPixel packPixel(const CompileResult& r, const reference::Geometry& g, const reference::InputValues& inputs) {
  GbufferPixel p;
  const auto ref = reference::evaluateMaterial<double>(r, g, inputs, sampleTexture);
  const StorageLayout& L = r.after;
  if (L.closures.empty()) {  // an unlit material: the no-closure header; the top-layer word's normal is g.N's
    p.cls = L.layoutClass;
    p.words = packMaterial(L, {}, {}, g.dither);
    p.topLayer = packTopLayer({g.N, 1.0}, g.dither);
    return p;
  }
  std::vector<ClosureValues> values;
  for (const auto& c : ref.closures) values.push_back(closureValues(c));
  std::vector<BasisValues> bases;
  for (int b = 0; b < L.basisCount; ++b) {  // a basis's normal, and the tangent of its anisotropic closure
    BasisValues bv;
    bool found = false;
    for (std::size_t i = 0; i < L.closures.size(); ++i)
      if (L.closures[i].basis == b && (!found || (L.closures[i].storedFeatures & kTangentFeatures))) {
        bv = {ref.closures[i].N, ref.closures[i].T_};
        found = true;
      }
    bases.push_back(bv);
  }
  StorageLayout layout = L;
  if (auto k = runtimeSimpleClosure(r.material, L, values)) {  // the base pass stores it SIMPLE
    layout = simpleLayoutOf(L, *k);
    values = {values[*k]};
    bases = {{ref.closures[*k].N, ref.closures[*k].T_}};
  }
  p.cls = layout.layoutClass;
  p.words = packMaterial(layout, values, bases, g.dither);
  // The top-layer word holds basis 0's normal when it is elided (any normal otherwise).
  const bool elided = layout.closures.size() == 1 || layout.basis0NormalElided;
  // Its roughness: the top closures' (the emitted pack's topRoughness); a pixel
  // stored as one closure keeps that closure's.
  const double topR = layout.closures.size() == 1 ? values[0].roughness : reference::topRoughness(ref.closures);
  p.topLayer = packTopLayer({elided ? bases[0].normal : ref.closures[0].N, topR}, g.dither);
  const UnpackedMaterial back = unpackMaterial(p.words.data(), p.words.size(), p.topLayer);
  for (const ClosureValues& c : back.closures) p.closures.push_back(closureOf(c, back.bases.at(c.basis)));
  reference::setCoatFloor(p.closures, back.topLayer.roughness);  // substrate_unpack_material: the word's roughness
  reference::setCoversLayers(p.closures);
  reference::setCoatInterface(p.closures);                        // from the unpacked top closure's F0
  return p;
}

Gbuffer::Gbuffer(uint32_t width, uint32_t height, int slices)
    : width_(width), height_(height), slices_(std::max(slices, 1)),
      layers_(std::size_t{width} * height * 4, 0u), material_(std::size_t{width} * height * slices_, 0u) {}

void Gbuffer::set(uint32_t x, uint32_t y, const GbufferPixel& p) {
  const std::size_t plane = std::size_t{width_} * height_, i = std::size_t{y} * width_ + x;
  if (p.words.size() > 3 + static_cast<std::size_t>(slices_))
    throw std::invalid_argument("a pixel has more words than the material buffer holds");
  for (std::size_t w = 0; w < p.words.size(); ++w) {
    if (w < 3) layers_[w * plane + i] = p.words[w];
    else material_[(w - 3) * plane + i] = p.words[w];
  }
  layers_[3 * plane + i] = p.topLayer;
}

StorageImageResource Gbuffer::gbufferImage() const {
  StorageImageResource img{width_, height_, 4, StorageFormat::R32Uint, bytesOf(layers_), true};
  return img;
}

StorageImageResource Gbuffer::materialBufferImage() const {
  StorageImageResource img{width_, height_, static_cast<uint32_t>(slices_), StorageFormat::R32Uint, bytesOf(material_),
                           true};
  return img;
}

bool classifyTiles(Context& ctx, const ComputePipeline& classify, const SceneFrame& f, const Gbuffer& gbuffer,
                   TileLists* out, Diagnostics& diags) {
  return classifyTiles(ctx, classify, f, gbuffer.gbufferImage(), out, diags);
}

bool classifyTiles(Context& ctx, const ComputePipeline& classify, const SceneFrame& f,
                   const StorageImageResource& gbufferImage, TileLists* out, Diagnostics& diags, double* ns) {
  Resources res;
  res[{0, 0}] = sceneFrameBlock(f);
  res[{0, 6}] = gbufferImage;
  BufferResource tiles;
  tiles.data.resize(std::size_t{4} * f.tiles() * 4);
  tiles.output = true;
  res[{0, 7}] = tiles;
  BufferResource args;
  std::vector<uint32_t> init;
  for (int c = 0; c < 4; ++c) init.insert(init.end(), {0u, 1u, 1u, 0u});
  args.data = bytesOf(init);
  args.output = args.initialized = true;
  res[{0, 9}] = args;
  if (!ctx.dispatch(classify, res, f.tilesX(), f.tilesY(), 1, diags, ns)) return false;
  std::vector<uint32_t> counts(16);
  std::memcpy(counts.data(), std::get<BufferResource>(res[{0, 9}]).data.data(), 64);
  out->raw.resize(std::size_t{4} * f.tiles());
  std::memcpy(out->raw.data(), std::get<BufferResource>(res[{0, 7}]).data.data(), out->raw.size() * 4);
  for (int c = 0; c < 4; ++c) {
    out->tiles[c].clear();
    if (counts[c * 4] > f.tiles() || counts[c * 4 + 1] != 1 || counts[c * 4 + 2] != 1) {
      diags.fail("classification wrote bad dispatch arguments for class " + std::to_string(c));
      return false;
    }
    for (uint32_t t = 0; t < counts[c * 4]; ++t) {
      const uint32_t word = out->raw[c * f.tiles() + t];
      out->tiles[c].push_back((word >> 16) * f.tilesX() + (word & 0xffffu));
    }
  }
  return true;
}

Resources lightingResources(const ComputePipeline& lighting, const SceneFrame& f, const Gbuffer& gbuffer,
                            const TileLists& lists) {
  Resources res;
  for (const DescriptorBinding& b : lighting.reflection().bindings) {
    const auto key = std::make_pair(b.set, b.binding);
    switch (b.binding) {
      case 0: res[key] = sceneFrameBlock(f); break;
      case 1: res[key] = constantCube(f.prefiltered); break;
      case 2: res[key] = constantCube(f.irradiance); break;
      case 3: res[key] = SamplerResource{}; break;
      case 4: res[key] = gbuffer.materialBufferImage(); break;
      case 5: {
        auto lut = energyLutTables();
        BufferResource buf;
        buf.data.resize(lut.size_bytes());
        std::memcpy(buf.data.data(), lut.data(), lut.size_bytes());
        res[key] = buf;
        break;
      }
      case 6: res[key] = gbuffer.gbufferImage(); break;
      case 7: res[key] = BufferResource{bytesOf(lists.raw), false, false}; break;
      case 8: res[key] = StorageImageResource{f.width, f.height, 1, StorageFormat::R32G32B32A32Sfloat, {}, false}; break;
      default: break;  // anything else stays unbound: the harness names it
    }
  }
  return res;
}

}  // namespace substratec::gpu
