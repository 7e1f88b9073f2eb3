// The importer round trip of the building blocks (issue 23): every corpus
// material imported as what its author wrote, one block (ImportForm::Blocks,
// what `substratec import` writes: `gltf_pbr` for glTF; `standard_surface`,
// `open_pbr_surface`, `disney_principled`, `gltf_pbr` for those MaterialX models),
// compiles to the same closures, bit for bit, as its flat import
// (ImportForm::Expanded, the slabs, operators and value nodes `import
// --expand` writes, which the corpus goldens hold): the block's expansion is
// the same mapping unit.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include "corpus.h"
#include "pipeline/pipeline.h"
#include "reference/reference.h"

namespace substratec {
namespace {

using namespace importtest;

CompileResult compiledOrFail(const import::ImportedMaterial& m, bool& ok) {
  Diagnostics d(m.name);
  auto r = compileText(m.name, m.text, {}, d);
  ok = r.has_value();
  EXPECT_TRUE(ok) << d.formatAll() << m.text;
  return r ? std::move(*r) : CompileResult{};
}

/// Every texture sampled as a function of (u, v) and of its input's name, so
/// that both forms see the same texels whatever their inputs' order.
reference::TextureFn texturesOf(const CompileResult& r) {
  return [&r](int input, double u, double v) {
    const double h = static_cast<double>(std::hash<std::string>{}(r.material.inputs[input].name) % 997) / 997.0;
    auto f = [](double x) { return x - std::floor(x); };
    return std::array<double, 4>{f(u * 1.7 + h), f(v * 2.3 + h * 0.5), f(u + v + h * 0.25), f(0.3 + u * v + h)};
  };
}

/// The bits of every number the reference evaluates for `r` at `g`: each
/// closure's parameters, the coverage, the transmittance and the emission.
std::vector<std::uint64_t> closureBits(const CompileResult& r, const reference::Geometry& g) {
  const auto m = reference::evaluateMaterial<double>(r, g, {}, texturesOf(r));
  std::vector<std::uint64_t> bits;
  auto put = [&](double x) { bits.push_back(std::bit_cast<std::uint64_t>(x)); };
  auto put3 = [&](const auto& v) { for (double x : v) put(x); };
  for (const auto& c : m.closures) {
    put3(c.diffuseAlbedo), put3(c.f0), put3(c.f90), put(c.roughness), put(c.anisotropy), put3(c.N), put3(c.T_);
    put3(c.sssMfp), put(c.sssType), put(c.secondRoughness), put(c.secondRoughnessWeight), put(c.fuzzAmount);
    put3(c.fuzzColor), put(c.fuzzRoughness), put3(c.emissive), put(c.weight), put3(c.topTransmittance);
    put(c.coverageAbove), put(c.features), put(c.isTop);
  }
  put(m.coverage), put3(m.transmittance), put3(m.emission);
  return bits;
}

/// What one corpus file's materials give when compiled as blocks and flat.
struct RoundTrip {
  std::size_t materials = 0, blocks = 0, points = 0;
};

/// Imports `f` in both forms and holds every material written as a block
/// to its flat import: bytes, closures, storage fields, settings, and the
/// reference's every number at 6 shading points, bit for bit.
void roundTrip(const CorpusFile& f, RoundTrip& t) {
  Diagnostics d1(f.display), d2(f.display);
  auto text = readSourceFile(f.path.string(), ReadLimits{}, d1);
  ASSERT_TRUE(text) << f.display;
  const auto kind = import::sourceKindOf(f.display);
  const std::string dir = f.path.parent_path().string(), name = f.path.filename().string();
  auto asBlocks = import::importText(kind, name, *text, dir, ReadLimits{}, d1, import::ImportForm::Blocks);
  auto flat = import::importText(kind, name, *text, dir, ReadLimits{}, d2, import::ImportForm::Expanded);
  if (!flat) return;  // a documented exception (corpusExceptions): no material either way
  ASSERT_TRUE(asBlocks) << f.display << d1.formatAll();
  ASSERT_EQ(asBlocks->size(), flat->size());
  EXPECT_EQ(d1.formatAll(), d2.formatAll()) << "the block form's import says what the flat one says";
  for (std::size_t i = 0; i < flat->size(); ++i) {
    SCOPED_TRACE(f.display + " [" + (*flat)[i].name + "]");
    const auto& b = (*asBlocks)[i];
    bool ok1 = false, ok2 = false;
    const CompileResult rb = compiledOrFail(b, ok1), rf = compiledOrFail((*flat)[i], ok2);
    if (!ok1 || !ok2) continue;
    ++t.materials;
    EXPECT_TRUE(rf.blocks.empty()) << "the flat form holds no block";
    if (rb.blocks.empty()) {
      EXPECT_EQ(b.text, (*flat)[i].text) << "a material without a block model is written alike";
      continue;
    }
    ASSERT_EQ(rb.blocks.size(), 1u);
    EXPECT_EQ(rb.blocks[0].id, "surface");
    ++t.blocks;
    EXPECT_EQ(rb.after.bytes(), rf.after.bytes());
    EXPECT_EQ(rb.after.closures.size(), rf.after.closures.size());
    ASSERT_EQ(rb.after.fields.size(), rf.after.fields.size());
    for (std::size_t k = 0; k < rf.after.fields.size(); ++k) {
      EXPECT_EQ(rb.after.fields[k].bits, rf.after.fields[k].bits);
      EXPECT_EQ(rb.after.fields[k].encoding, rf.after.fields[k].encoding);
    }
    EXPECT_EQ(rb.material.settings.blendMode, rf.material.settings.blendMode);
    EXPECT_EQ(rb.material.settings.thinSurface, rf.material.settings.thinSurface);
    for (double nov : {1.0, 0.5, 0.1})
      for (double u : {0.1, 0.7}) {
        reference::Geometry g;
        g.V = {std::sqrt(1 - nov * nov), 0, nov};
        g.uv0 = {u, 1 - u * 0.5};
        g.uv1 = {u * 0.5, u};
        ASSERT_EQ(closureBits(rb, g), closureBits(rf, g)) << "NoV " << nov << " u " << u;
        ++t.points;
      }
  }
}

TEST(BlockRoundTrip, EveryGltfMaterialAsABlockCompilesToTheClosuresOfItsFlatImport) {
  RoundTrip t;
  for (const CorpusFile& f : corpusFiles())
    if (f.display.starts_with("gltf/")) roundTrip(f, t);
  std::printf("[ round trip ] glTF: %zu materials, %zu as one gltf_pbr block, %zu shading points bit-identical\n",
              t.materials, t.blocks, t.points);
  EXPECT_EQ(t.materials, 477u);  // the corpus README's count
  EXPECT_EQ(t.blocks, t.materials);
}

TEST(BlockRoundTrip, EveryMaterialXModelThatIsABlockCompilesToTheClosuresOfItsFlatImport) {
  RoundTrip t;
  for (const CorpusFile& f : corpusFiles())
    if (!f.display.starts_with("gltf/")) roundTrip(f, t);
  std::printf("[ round trip ] MaterialX: %zu materials, %zu as a standard_surface, open_pbr_surface, "
              "disney_principled or gltf_pbr block, %zu shading points bit-identical\n",
              t.materials, t.blocks, t.points);
  EXPECT_EQ(t.materials, 66u);
  EXPECT_EQ(t.blocks, 59u) << "all but the UsdPreviewSurface and hair materials";
}

}  // namespace
}  // namespace substratec
