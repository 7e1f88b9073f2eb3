#include "pipeline/generate.h"

#include <algorithm>
#include <map>
#include <string_view>

#include <fmt/format.h>

#include "emit/entry_emitter.h"
#include "emit/layout_json.h"
#include "util/parallel.h"
#include "validate/runtime_files.h"
#include "validate/shader_validate.h"

namespace substratec {

namespace {

/// `<name>.material.{glsl,hlsl}`: the material function, then its packing
/// function (the base pass calls it) before the closing include guard.
std::string materialFile(const CompileResult& r, const Syntax& syn, const EmitOptions& emit) {
  std::string material = emitMaterial(r.material, r.tree, r.after, syn, emit);
  material.insert(material.rfind("#endif"), emitPackFunction(r.material, r.after, syn, emit.dynamicSimplification) + "\n");
  return material;
}

/// The files an entry includes, served from memory: the runtime and `g`'s files.
std::map<std::string, std::string_view> memoryFiles(const Generated& g) {
  std::map<std::string, std::string_view> files;
  for (const RuntimeFile& f : runtimeFiles()) files.emplace(std::string(f.name), f.text);
  for (const OutputFile& f : g.files) files.emplace(f.name, f.contents);
  return files;
}

/// Whether a generated file is an entry shader, and its language and stage by its extension.
bool isEntry(const std::string& name) {
  return name.ends_with(".frag") || name.ends_with(".ps.hlsl") || name.ends_with(".comp") || name.ends_with(".cs.hlsl");
}
ShaderSource entrySource(const OutputFile& f, const std::map<std::string, std::string_view>& files, Precision precision) {
  ShaderSource src;
  src.name = f.name;
  src.text = f.contents;
  src.language = f.name.ends_with(".frag") || f.name.ends_with(".comp") ? ShaderLanguage::Glsl : ShaderLanguage::Hlsl;
  src.stage = f.name.ends_with(".comp") || f.name.ends_with(".cs.hlsl") ? ShaderStage::Compute : ShaderStage::Fragment;
  src.memoryFiles = files;
  src.hlsl16BitTypes = precision == Precision::Half;
  return src;
}

}  // namespace

Generated generateFiles(const CompileResult& r, const GenerateOptions& o) {
  Generated g;
  g.precision = o.emit.precision;
  const Material& m = r.material;
  for (Target t : {Target::Glsl, Target::Hlsl}) {
    if ((t == Target::Glsl && !o.glsl) || (t == Target::Hlsl && !o.hlsl)) continue;
    const Syntax& syn = syntaxFor(t);
    g.files.push_back({m.name + std::string(syn.materialExtension), materialFile(r, syn, o.emit)});
    if (isVolumeMaterial(m)) {  // no surface: the froxel pass instead of the forward and base passes
      g.files.push_back({volumeFileName(m, syn), emitVolumeEntry(m, r.after, syn)});
      continue;
    }
    g.files.push_back({basePassFileName(m, syn), emitBasePassEntry(m, r.after, syn)});
    g.files.push_back({forwardFileName(m, syn), emitForwardEntry(m, r.after, syn, o.emit.precision)});
  }
  g.files.push_back({m.name + ".layout.json", layoutJson(m, r.after).dump(2) + "\n"});
  return g;
}

void validateGenerated(Generated& g, const ValidateOptions& options, std::size_t threads) {
  // The entries include the material files and the runtime by name: both are
  // served from memory, so nothing touches the disk.
  const std::map<std::string, std::string_view> files = memoryFiles(g);
  std::vector<const OutputFile*> entries;
  for (const OutputFile& f : g.files)
    if (isEntry(f.name)) entries.push_back(&f);

  // Entries are independent (glslang and SPIRV-Tools are thread-safe per
  // compilation); results are kept by index, so the outcome does not depend
  // on scheduling.
  std::vector<ShaderValidation> results(entries.size());
  parallelFor(entries.size(), threads, [&](std::size_t i) {
    results[i] = compileAndValidate(entrySource(*entries[i], files, g.precision), options);
  });

  for (std::size_t i = 0; i < entries.size(); ++i) {
    ShaderValidation& v = results[i];
    if (!v.ok) {
      g.valid = false;
      g.failure = fmt::format("{}\n{}\n{}", entries[i]->name, numberLines(entries[i]->contents), v.log);
      return;
    }
    g.entries.push_back({entries[i]->name, v.instructionCount, v.optimizedInstructionCount, std::move(v.optimized)});
  }
}

ShaderValidation compileGeneratedEntry(const Generated& g, const std::string& file) {
  for (const OutputFile& f : g.files) {
    if (f.name != file || !isEntry(f.name)) continue;
    ShaderValidation v = compileAndValidate(entrySource(f, memoryFiles(g), g.precision));
    if (!v.ok) v.log = fmt::format("{}\n{}\n{}", f.name, numberLines(f.contents), v.log);
    return v;
  }
  ShaderValidation missing;
  missing.log = "no entry shader '" + file + "' among the generated files";
  return missing;
}

ShaderValidation compileKernel(const CompileResult& r, Target target, KernelMode mode, const EmitOptions& emit) {
  const Syntax& syn = syntaxFor(target);
  const Material& m = r.material;
  const std::string material = materialFile(r, syn, emit);
  const std::string materialName = m.name + std::string(syn.materialExtension);
  ShaderSource src;
  src.name = kernelFileName(m, syn, mode);
  src.text = emitKernel(m, r.after, syn, mode, emit);
  src.language = target == Target::Glsl ? ShaderLanguage::Glsl : ShaderLanguage::Hlsl;
  src.stage = ShaderStage::Compute;
  src.hlsl16BitTypes = emit.precision == Precision::Half;
  for (const RuntimeFile& f : runtimeFiles()) src.memoryFiles.emplace(std::string(f.name), f.text);
  src.memoryFiles[materialName] = material;
  ShaderValidation v = compileAndValidate(src);
  if (!v.ok) v.log = fmt::format("{}\n{}\n{}", src.name, numberLines(src.text), v.log);
  return v;
}

}  // namespace substratec
