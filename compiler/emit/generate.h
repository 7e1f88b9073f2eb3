// Code generation driver: every output file of `substratec compile` for one
// compiled material, and their in-process validation (glslang + spirv-val).
#pragma once
#include <string>
#include <vector>

#include "emit/material_emitter.h"
#include "output/atomic_write.h"
#include "pipeline/pipeline.h"

namespace substratec {

struct GenerateOptions {
  bool glsl = true;
  bool hlsl = true;
  EmitOptions emit;
};

struct EntryReport {
  std::string file;
  std::size_t instructions = 0;           // SPIR-V instructions
  std::size_t optimizedInstructions = 0;  // after SPIRV-Tools' performance passes
};

struct Generated {
  std::vector<OutputFile> files;   // materials, entries, layout.json
  std::vector<EntryReport> entries;
  bool valid = true;               // every entry compiled and validated
  std::string failure;             // the numbered source and the log of the first failure
};

/// Emits every file (no validation).
Generated generateFiles(const CompileResult& r, const GenerateOptions& o);

/// Compiles every entry shader in-process (files written to a private
/// temporary directory together with the embedded runtime), runs spirv-val
/// and counts instructions. Fills `entries`, `valid`, `failure`.
void validateGenerated(Generated& g);

}  // namespace substratec
