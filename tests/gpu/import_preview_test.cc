// Issue 10: every material of the import corpora (tests/import/corpus)
// renders a preview on lavapipe, through one context: a 32 x 32 sphere with
// every texture input at its neutral texel (what `substratec preview` binds
// to a texture without an image; the corpus extracts carry none), without a NaN. Each
// material is compiled under one name, so materials that differ only in their
// inputs' values share a kernel and its pipeline (preview::PipelineCache):
// lavapipe builds each of the corpus' distinct kernels once.
#include <gtest/gtest.h>

#include <cmath>

#include "../import/corpus.h"
#include "material_fixture.h"
#include "preview/render.h"

using namespace substratec;

TEST(ImportCorpusPreview, EveryMaterialRendersOnLavapipe) {
  Diagnostics diags("test");
  gpu::Context* ctx = gputest::sharedContext(diags);
  ASSERT_NE(ctx, nullptr) << diags.errorMessages();
  preview::PipelineCache pipelines;
  preview::RenderOptions ro;
  ro.size = 32;
  ro.pipelines = &pipelines;
  std::size_t rendered = 0;
  for (const auto& f : importtest::corpusFiles()) {
    const importtest::CorpusImport r = importtest::importCorpusFile(f);
    if (importtest::corpusExceptions().count(f.display)) continue;
    ASSERT_TRUE(r.ok) << f.display << "\n" << r.diagnostics;
    for (const auto& m : r.materials) {
      SCOPED_TRACE(f.display + " [" + m.name + "]");
      nlohmann::ordered_json doc = nlohmann::ordered_json::parse(m.text);
      doc["name"] = "imported";
      Diagnostics diags(m.name);
      auto c = compileText(m.name, doc.dump(), CompileOptions{}, diags);
      ASSERT_TRUE(c.has_value()) << diags.formatAll();
      preview::Image image;
      ASSERT_TRUE(preview::renderSphere(*ctx, *c, ro, &image, diags)) << diags.errorMessages();
      std::size_t nonFinite = 0;
      for (float v : image.rgba) nonFinite += !std::isfinite(v);
      EXPECT_EQ(nonFinite, 0u);
      ++rendered;
    }
  }
  EXPECT_GE(rendered, 538u);
}
