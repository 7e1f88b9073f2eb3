// Scene lighting cost on lavapipe (issue 9, docs/performance.md "Scene
// lighting cost"): what the deferred lighting `substratec scene` emits costs per
// pixel for a scene of simple materials and for the scene of every example,
// against the hand-written minimal GGX + Lambert kernel. Not a test;
// bench/scene_lighting.sh builds and runs it.
//
// The scenes are built as `substratec scene` builds them (scene/scene.h:
// examples/scenes/simple_only.json and all_examples.json, GLSL). A G-buffer of
// --size x --size pixels is filled per scene (gpu/gbuffer.h: each 8x8 tile one
// material, in turn; the reference's closures at default inputs packed as the
// base pass packs them), the scene's tile classification sorts its tiles, and
// these dispatches are timed (GPU timestamps around the dispatch, uploads
// excluded), all in interleaved rounds (one untimed warm-up round, then --runs
// rounds, alternately in order and in reverse; medians reported):
//
//   simple_only: lighting_simple        the simple scene's one shader, on its own G-buffer
//   all_examples: lighting_special      the all-features scene's most general shader, on the SAME
//     (simple pixels)                   simple G-buffer: what the specialization saves
//   all_examples: per class             each class's shader over its tiles of the all-examples
//                                       G-buffer (summed: the scene's lighting)
//   all_examples: lighting_special      that G-buffer, every tile through the SPECIAL shader
//     (every tile)                      (no classification)
//   floor (Karis), floor (tables)       bench/shaders/minimal_ggx_lambert.comp over as many
//                                       invocations (its shading point is hashed, no G-buffer)
//
// Usage: scene_lighting [--size N] [--runs N] [--source DIR] [--dump DIR] [--extra DIR]
//   --dump DIR   writes the timed scene shaders to DIR
//   --extra DIR  also times every DIR/*.comp as a lighting shader over the
//                simple scene's G-buffer (every tile listed under every class),
//                e.g. a dumped shader edited by hand
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "emit/kernel_emitter.h"
#include "emit/scene_emitter.h"
#include "gpu/gbuffer.h"
#include "gpu/harness.h"
#include "gpu/sample_run.h"
#include "scene/manifest.h"
#include "scene/scene.h"
#include "validate/runtime_files.h"
#include "validate/shader_validate.h"

namespace fs = std::filesystem;
using namespace substratec;

namespace {

[[noreturn]] void die(const std::string& message) {
  std::fprintf(stderr, "scene_lighting: %s\n", message.c_str());
  std::exit(2);
}

std::string readAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) die("cannot read " + p.string());
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// A compute shader to time, with the dispatches of one round.
struct Timed {
  std::string label;
  std::size_t instructions = 0, optimizedInstructions = 0;
  struct Dispatch {
    const gpu::ComputePipeline* pipeline;
    gpu::Resources resources;
    uint32_t groupsX, groupsY;
  };
  std::vector<Dispatch> dispatches;  // one round (several for a scene's classes)
  double pixels = 0;                 // shaded per round
  std::vector<double> ns;            // per round, summed over the dispatches
  double median() const {
    std::vector<double> v = ns;
    std::sort(v.begin(), v.end());
    return v.empty() ? 0 : v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
  }
};

struct Compiled {
  std::vector<uint32_t> spirv;
  std::size_t instructions = 0, optimizedInstructions = 0;
  std::unique_ptr<gpu::ComputePipeline> pipeline;
};

Compiled compile(gpu::Context& ctx, const std::string& name, const std::string& text,
                 const std::vector<std::pair<std::string, std::string>>& defines = {}) {
  ShaderSource src;
  src.name = name;
  src.text = text;
  src.stage = ShaderStage::Compute;
  src.defines = defines;
  for (const RuntimeFile& f : runtimeFiles()) src.memoryFiles.emplace(std::string(f.name), f.text);
  ShaderValidation v = compileAndValidate(src, {.optimize = true});
  if (!v.ok) die(name + " does not validate:\n" + v.log);
  Compiled c;
  Diagnostics diags("bench");
  c.pipeline = ctx.createPipeline(v.spirv, diags);
  if (!c.pipeline) die("pipeline of " + name + ": " + diags.errorMessages());
  c.spirv = std::move(v.spirv);
  c.instructions = v.instructionCount;
  c.optimizedInstructions = v.optimizedInstructionCount;
  return c;
}

/// A scene as `substratec scene` builds it: its shape and its materials.
struct BuiltScene {
  SceneShape shape;
  std::vector<CompileResult> materials;
  std::map<std::string, std::string> files;  // what `scene` writes (GLSL)
};

BuiltScene builtScene(const std::string& source, const std::string& manifest) {
  SceneOptions o;
  o.manifest = source + "/examples/scenes/" + manifest;
  o.batch.generate.hlsl = false;
  SceneBuild b = substratec::buildScene(o);
  if (b.status != SceneStatus::Ok) die("scene " + manifest + ":\n" + b.messages);
  BuiltScene s;
  for (const OutputFile& f : b.files) s.files[f.name] = f.contents;
  // The materials again (their CompileResult, for the reference), in manifest order.
  Diagnostics d(o.manifest);
  auto m = parseSceneManifest(o.manifest, readAll(o.manifest), {}, d);
  std::vector<SceneMaterialShape> shapes;
  for (const SceneMaterialRef& ref : m->materials) {
    Diagnostics md(ref.path);
    CompileOptions co;
    if (m->platform) co.platform = *PlatformTable::builtin().find(*m->platform);
    auto r = compileText(ref.path, readAll(ref.path), co, md);
    if (!r) die(md.formatAll());
    shapes.push_back(summarize(*r).shape());
    s.materials.push_back(std::move(*r));
  }
  s.shape = sceneShape(m->name, shapes, kDefaultDiffuseModel);
  return s;
}

/// A G-buffer of `size` x `size` pixels, tile t holding material t mod n: a
/// pool of 64 packed pixels per material (the tile's 8 x 8) copied into place.
gpu::Gbuffer fill(const gpu::SceneFrame& f, const BuiltScene& s, LayoutClass* worst) {
  gpu::Gbuffer g(f.width, f.height, materialBufferSlices(s.shape));
  std::vector<std::vector<gpu::GbufferPixel>> pools;
  for (const CompileResult& r : s.materials) {
    reference::InputValues in;
    for (const Input& i : r.material.inputs) in.values.push_back(i.defaultValue);
    std::vector<gpu::GbufferPixel> pool;
    for (uint32_t y = 0; y < 8; ++y)
      for (uint32_t x = 0; x < 8; ++x)
        pool.push_back(gpu::packPixel(r, gpu::pixelGeometry(f, x, y, {(x + 0.5) / 8, (y + 0.5) / 8}), in));
    pools.push_back(std::move(pool));
  }
  *worst = LayoutClass::Simple;
  for (uint32_t y = 0; y < f.height; ++y)
    for (uint32_t x = 0; x < f.width; ++x) {
      const uint32_t tile = (y / 8) * f.tilesX() + x / 8;
      const gpu::GbufferPixel& p = pools[tile % pools.size()][(y % 8) * 8 + x % 8];
      g.set(x, y, p);
      if (static_cast<int>(p.cls) > static_cast<int>(*worst)) *worst = p.cls;
    }
  return g;
}

/// Tile lists with every tile under class `cls` (no classification).
gpu::TileLists everyTileAs(const gpu::SceneFrame& f, LayoutClass cls) {
  gpu::TileLists t;
  t.raw.assign(std::size_t{4} * f.tiles(), 0u);
  for (uint32_t i = 0; i < f.tiles(); ++i) {
    t.raw[static_cast<int>(cls) * f.tiles() + i] = (i % f.tilesX()) | ((i / f.tilesX()) << 16);
    t.tiles[static_cast<int>(cls)].push_back(i);
  }
  return t;
}

}  // namespace

int main(int argc, char** argv) {
  uint32_t size = 1024;
  int runs = 9;
  std::string source = SUBSTRATEC_SOURCE_DIR, dump, extra;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--dump" && i + 1 < argc) dump = argv[++i];
    else if (a == "--extra" && i + 1 < argc) extra = argv[++i];
    else if (a == "--size" && i + 1 < argc) size = static_cast<uint32_t>(std::atoi(argv[++i]));
    else if (a == "--runs" && i + 1 < argc) runs = std::atoi(argv[++i]);
    else if (a == "--source" && i + 1 < argc) source = argv[++i];
    else die("usage: scene_lighting [--size N] [--runs N] [--source DIR] [--dump DIR] [--extra DIR]");
  }
  if (size < 8 || size > 4096 || runs < 1) die("--size in [8, 4096], --runs >= 1");
  Diagnostics diags("bench");
  auto ctx = gpu::Context::create({}, diags);
  if (!ctx) die("lavapipe: " + diags.errorMessages());
  std::printf("device: %s, %s\n\n", ctx->deviceName().c_str(), ctx->driverInfo().c_str());

  gpu::SceneFrame frame;
  frame.width = frame.height = size;
  const BuiltScene simple = builtScene(source, "simple_only.json");
  const BuiltScene all = builtScene(source, "all_examples.json");
  LayoutClass worstSimple, worstAll;
  const gpu::Gbuffer simpleG = fill(frame, simple, &worstSimple);
  const gpu::Gbuffer allG = fill(frame, all, &worstAll);
  if (worstSimple != LayoutClass::Simple) die("the simple scene's G-buffer holds non-SIMPLE pixels");

  const Syntax& glsl = syntaxFor(Target::Glsl);
  auto sceneShader = [&](const BuiltScene& s, const std::string& file) {
    auto it = s.files.find(file);
    if (it == s.files.end()) die("scene has no " + file);
    return compile(*ctx, file, it->second);
  };
  std::map<std::string, Compiled> shaders;
  const std::string simpleFile = sceneLightingFileName(simple.shape, LayoutClass::Simple, glsl);
  shaders[simpleFile] = sceneShader(simple, simpleFile);
  for (const SceneLightingClass& k : all.shape.classes) {
    const std::string f = sceneLightingFileName(all.shape, k.cls, glsl);
    shaders[f] = sceneShader(all, f);
  }
  if (!dump.empty()) {
    fs::create_directories(dump);
    for (const BuiltScene* s : {&simple, &all})
      for (const auto& [name, text] : s->files)
        if (name.find(".lighting_") != std::string::npos) std::ofstream(fs::path(dump) / name) << text;
  }
  const std::string classifyFile = tileClassificationFileName(all.shape, glsl);
  shaders[classifyFile] = sceneShader(all, classifyFile);
  const std::string specialFile = sceneLightingFileName(all.shape, LayoutClass::Special, glsl);

  gpu::TileLists allLists;
  if (!gpu::classifyTiles(*ctx, *shaders[classifyFile].pipeline, frame, allG, &allLists, diags))
    die("classification: " + diags.errorMessages());

  std::vector<std::unique_ptr<Timed>> kernels;
  auto timed = [&](const std::string& label, const Compiled& c) {
    kernels.push_back(std::make_unique<Timed>());
    kernels.back()->label = label;
    kernels.back()->instructions = c.instructions;
    kernels.back()->optimizedInstructions = c.optimizedInstructions;
    return kernels.back().get();
  };
  auto lighting = [&](Timed* t, const Compiled& c, const gpu::Gbuffer& g, const gpu::TileLists& lists, LayoutClass cls) {
    const auto& tiles = lists.tiles[static_cast<int>(cls)];
    if (tiles.empty()) return;
    t->dispatches.push_back({c.pipeline.get(), gpu::lightingResources(*c.pipeline, frame, g, lists),
                             static_cast<uint32_t>(tiles.size()), 1});
    t->pixels += 64.0 * tiles.size();
  };
  const gpu::TileLists simpleLists = everyTileAs(frame, LayoutClass::Simple);
  lighting(timed("`simple_only`: `lighting_simple` (its only shader)", shaders[simpleFile]), shaders[simpleFile], simpleG,
           simpleLists, LayoutClass::Simple);
  lighting(timed("`all_examples`: `lighting_special`, on the simple scene's pixels", shaders[specialFile]),
           shaders[specialFile], simpleG, everyTileAs(frame, LayoutClass::Special), LayoutClass::Special);
  Timed* perClass = timed("`all_examples`: each class's shader over its tiles (the scene's lighting)", {});
  std::string perClassSpirv;
  for (const SceneLightingClass& k : all.shape.classes) {
    const Compiled& c = shaders[sceneLightingFileName(all.shape, k.cls, glsl)];
    lighting(perClass, c, allG, allLists, k.cls);
    perClassSpirv += fmt::format("{}{} {}", perClassSpirv.empty() ? "" : ", ", tileClassName(k.cls),
                                 c.optimizedInstructions);
  }
  lighting(timed("`all_examples`: `lighting_special` on every tile (no classification)", shaders[specialFile]),
           shaders[specialFile], allG, everyTileAs(frame, LayoutClass::Special), LayoutClass::Special);

  // --extra: each DIR/*.comp over the simple G-buffer, every tile under every class.
  std::vector<Compiled> extras;
  if (!extra.empty()) {
    gpu::TileLists every = everyTileAs(frame, LayoutClass::Simple);
    for (int c = 1; c < 4; ++c)
      std::copy(every.raw.begin(), every.raw.begin() + frame.tiles(), every.raw.begin() + c * frame.tiles());
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(extra))
      if (e.path().extension() == ".comp") files.push_back(e.path());
    std::sort(files.begin(), files.end());
    extras.reserve(files.size());
    for (const fs::path& f : files) {
      extras.push_back(compile(*ctx, f.filename().string(), readAll(f)));
      Timed* t = timed("extra: " + f.filename().string() + ", on the simple scene's pixels", extras.back());
      t->dispatches.push_back({extras.back().pipeline.get(), gpu::lightingResources(*extras.back().pipeline, frame,
                                                                                    simpleG, every),
                               frame.tiles(), 1});
      t->pixels = 64.0 * frame.tiles();
    }
  }

  // The hand-written floor over as many invocations, with row12_simple's parameters.
  const std::string floorText = readAll(source + "/bench/shaders/minimal_ggx_lambert.comp");
  Diagnostics rd("row12_simple.json");
  auto row12 = compileText("row12_simple.json", readAll(source + "/examples/row12_simple.json"), {}, rd);
  if (!row12) die(rd.formatAll());
  std::vector<Compiled> floors;
  for (const char* lut : {"0", "1"}) floors.push_back(compile(*ctx, "minimal_ggx_lambert.comp", floorText, {{"MINIMAL_ENV_LUT", lut}}));
  const double pixels = double(size) * size;
  for (std::size_t i = 0; i < floors.size(); ++i) {
    Timed* t = timed(i == 0 ? "floor (Karis): hand-written GGX + Lambert, env. BRDF from Karis' fit"
                            : "floor (tables): the same, env. BRDF from the runtime's tables",
                     floors[i]);
    const auto n = static_cast<std::size_t>((pixels + kernel::kLocalSize - 1) / kernel::kLocalSize) * kernel::kLocalSize;
    t->dispatches.push_back({floors[i].pipeline.get(),
                             gpu::kernelResources(row12->material, floors[i].pipeline->reflection(), floors[i].spirv, {},
                                                  {}, n * 4),
                             static_cast<uint32_t>(n / kernel::kLocalSize), 1});
    t->pixels = static_cast<double>(n);
  }

  // Interleaved rounds: one warm-up, then `runs` timed, alternately in order and reversed.
  for (int round = 0; round <= runs; ++round)
    for (std::size_t j = 0; j < kernels.size(); ++j) {
      Timed& k = *kernels[round % 2 ? kernels.size() - 1 - j : j];
      double sum = 0;
      for (Timed::Dispatch& d : k.dispatches) {
        double ns = 0;
        if (!ctx->dispatch(*d.pipeline, d.resources, d.groupsX, d.groupsY, 1, diags, &ns))
          die("dispatch of " + k.label + ": " + diags.errorMessages());
        sum += ns;
      }
      if (round > 0) k.ns.push_back(sum / k.pixels);
    }

  const double karis = kernels[kernels.size() - 2]->median(), tables = kernels.back()->median();
  std::printf("%u x %u pixels (%u tiles); all_examples' tiles by class: simple %zu, single %zu, complex %zu, "
              "special %zu; median of %d rounds\n\n",
              size, size, frame.tiles(), allLists.tiles[0].size(), allLists.tiles[1].size(), allLists.tiles[2].size(),
              allLists.tiles[3].size(), runs);
  std::printf("| lighting | ns/px | min–max | ÷ floor (Karis) | ÷ floor (tables) | SPIR-V (optimized) |\n");
  std::printf("|---|---:|---:|---:|---:|---:|\n");
  for (const auto& k : kernels) {
    const auto [lo, hi] = std::minmax_element(k->ns.begin(), k->ns.end());
    const std::string spirv = k.get() == perClass ? perClassSpirv : std::to_string(k->optimizedInstructions);
    std::printf("| %s | %.2f | %.2f–%.2f | %.2f | %.2f | %s |\n", k->label.c_str(), k->median(), *lo, *hi,
                k->median() / karis, k->median() / tables, spirv.c_str());
  }
  std::printf("\nclassification (tile_classification, %zu SPIR-V instructions optimized) is not in these figures.\n",
              shaders[classifyFile].optimizedInstructions);
  return 0;
}
