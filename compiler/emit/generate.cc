#include "emit/generate.h"

#include <stdlib.h>

#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "emit/entry_emitter.h"
#include "emit/layout_json.h"
#include "validate/runtime_files.h"
#include "validate/shader_validate.h"

namespace substratec {

namespace fs = std::filesystem;

Generated generateFiles(const CompileResult& r, const GenerateOptions& o) {
  Generated g;
  const Material& m = r.material;
  for (Target t : {Target::Glsl, Target::Hlsl}) {
    if ((t == Target::Glsl && !o.glsl) || (t == Target::Hlsl && !o.hlsl)) continue;
    const Syntax& syn = syntaxFor(t);
    std::string material = emitMaterial(m, r.tree, r.after, syn, o.emit);
    // The packing function lives with the material (the base pass calls it).
    auto end = material.rfind("#endif");
    material.insert(end, emitPackFunction(m, r.after, syn) + "\n");
    g.files.push_back({m.name + std::string(syn.materialExtension), material});
    g.files.push_back({basePassFileName(m, syn), emitBasePassEntry(m, r.after, syn)});
    g.files.push_back({forwardFileName(m, syn), emitForwardEntry(m, r.after, syn)});
  }
  g.files.push_back({m.name + ".layout.json", layoutJson(m, r.after).dump(2) + "\n"});
  return g;
}

void validateGenerated(Generated& g) {
  std::string pattern = (fs::temp_directory_path() / "substratec-XXXXXX").string();
  if (!::mkdtemp(pattern.data())) {
    g.valid = false;
    g.failure = "cannot create a temporary directory for validation";
    return;
  }
  const fs::path dir = pattern;
  for (const RuntimeFile& f : runtimeFiles()) std::ofstream(dir / std::string(f.name), std::ios::binary) << f.text;
  for (const OutputFile& f : g.files) std::ofstream(dir / f.name, std::ios::binary) << f.contents;
  for (const OutputFile& f : g.files) {
    bool glsl = f.name.ends_with(".frag");
    bool hlsl = f.name.ends_with(".ps.hlsl");
    if (!glsl && !hlsl) continue;
    ShaderSource src;
    src.name = (dir / f.name).string();
    src.text = f.contents;
    src.language = glsl ? ShaderLanguage::Glsl : ShaderLanguage::Hlsl;
    src.stage = ShaderStage::Fragment;
    src.includeDirs = {dir.string()};
    ShaderValidation v = compileAndValidate(src);
    if (!v.ok) {
      g.valid = false;
      std::string log = v.log;
      // Name files without the private directory.
      for (std::size_t p; (p = log.find(dir.string() + "/")) != std::string::npos;) log.erase(p, dir.string().size() + 1);
      g.failure = fmt::format("{}\n{}\n{}", f.name, numberLines(f.contents), log);
      break;
    }
    g.entries.push_back({f.name, v.instructionCount, v.optimizedInstructionCount});
  }
  std::error_code ec;
  fs::remove_all(dir, ec);
}

}  // namespace substratec
