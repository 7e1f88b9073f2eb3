// Code generation driver: every output file of `substratec compile` for one
// compiled material, and their in-process validation (glslang + spirv-val).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "emit/kernel_emitter.h"
#include "emit/material_emitter.h"
#include "output/atomic_write.h"
#include "pipeline/pipeline.h"
#include "validate/shader_validate.h"

namespace substratec {

struct GenerateOptions {
  bool glsl = true;
  bool hlsl = true;
  EmitOptions emit;
};

struct EntryReport {
  std::string file;
  std::size_t instructions = 0;           // SPIR-V instructions, as validated
  std::size_t optimizedInstructions = 0;  // after SPIRV-Tools' performance passes (0 unless requested)
  std::vector<uint32_t> optimizedSpirv;   // that module (empty unless requested)
};

struct Generated {
  std::vector<OutputFile> files;   // materials, entries, layout.json
  std::vector<EntryReport> entries;
  Precision precision = Precision::Float;  // of the forward entries (GenerateOptions::emit)
  bool valid = true;               // every entry compiled and validated
  std::string failure;             // the numbered source and the log of the first failure
};

/// Emits every file (no validation).
Generated generateFiles(const CompileResult& r, const GenerateOptions& o);

/// Compiles every entry shader in-process against the generated files and the
/// embedded runtime (all in memory), runs spirv-val and counts instructions;
/// with `options.optimize` also after SPIRV-Tools' performance passes.
/// Entries compile in parallel on up to `threads` threads (0: the machine's).
/// Fills `entries`, `valid`, `failure` (the first failing entry in file order).
void validateGenerated(Generated& g, const ValidateOptions& options = {}, std::size_t threads = 0);

/// Compiles the entry shader `file` of `g` as validateGenerated does and keeps
/// its SPIR-V (what `render` draws with). `ok` false, with the numbered source
/// and the log (or "no entry shader ..."), otherwise.
ShaderValidation compileGeneratedEntry(const Generated& g, const std::string& file);

/// Compiles one compute kernel of the material (emit/kernel_emitter.h) for
/// `target` to validated SPIR-V, against the material file generated with
/// `emit` and the embedded runtime. `ok` false with the numbered kernel source
/// and the log in `log` when it does not validate (a compiler bug).
ShaderValidation compileKernel(const CompileResult& r, Target target, KernelMode mode, const EmitOptions& emit = {});

}  // namespace substratec
