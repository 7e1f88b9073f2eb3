// In-process validation of generated shaders: glslang (GLSL front end, and its
// HLSL front end) -> SPIR-V 1.5 for Vulkan 1.2 -> spirv-val; on request, a copy
// run through SPIRV-Tools' performance passes and validated again.
//
// This is the single interface HLSL validation goes through, so another
// validator (e.g. DXC) can slot in behind it: glslang's HLSL front end is
// deprecated upstream.
//
// #include: both languages accept `#include "x"` (searched relative to the
// including file, then in ShaderSource::includeDirs) and `#include <x>`
// (includeDirs only); ShaderSource::memoryFiles are found before any directory.
// GLSL sources need no `#extension` line:
// GL_GOOGLE_include_directive is enabled by a preamble; writing
// `#extension GL_GOOGLE_include_directive : require` as well is harmless.
// Diagnostics inside an included file name its resolved path.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace substratec {

enum class ShaderLanguage { Glsl, Hlsl };
enum class ShaderStage { Vertex, Fragment, Compute };

struct ShaderSource {
  std::string name;  // file name used in diagnostics (e.g. "m.forward.frag")
  std::string text;
  ShaderLanguage language = ShaderLanguage::Glsl;
  ShaderStage stage = ShaderStage::Fragment;
  std::string entryPoint = "main";
  std::vector<std::string> includeDirs;  // searched for #include "x" (relative to the including file first)
  std::vector<std::pair<std::string, std::string>> defines;  // #define first second
  // Files #include finds by name before searching any directory (name -> text;
  // the texts must outlive the call). Diagnostics name them as given.
  std::map<std::string, std::string_view> memoryFiles;
  // HLSL: `half` is a 16-bit float (EShMsgHlslEnable16BitTypes, DXC's -enable-16bit-types), for the
  // runtime's SUBSTRATE_PRECISION_HALF; otherwise a 32-bit one. GLSL asks for float16 by #extension.
  bool hlsl16BitTypes = false;
};

struct ValidateOptions {
  // Also run SPIRV-Tools' performance passes on a copy, validate it and count
  // its instructions (`substratec report --spirv`); `compile` does not need it.
  bool optimize = false;
};

struct ShaderValidation {
  bool ok = false;
  std::string log;              // glslang/SPIRV-Tools messages (empty when ok, except compiler warnings)
  std::vector<uint32_t> spirv;  // SPIR-V 1.5 for Vulkan 1.2, unoptimized (HLSL: legalized by glslang when the
                                // raw module is invalid); kept when spirv-val rejects it, for dumps
  std::size_t instructionCount = 0;           // of `spirv`
  std::vector<uint32_t> optimized;            // ValidateOptions::optimize: after the performance passes
  std::size_t optimizedInstructionCount = 0;  // of `optimized` (0 without ValidateOptions::optimize)
  /// Where the time went, wall-clock milliseconds on the calling thread (bench/compile_bench's
  /// ValidatePhases): glslang's front end with the preprocessor (and, the first time a process
  /// parses a language, its built-in symbol tables), its linker, SPIR-V generation (HLSL:
  /// legalization too, when it runs), and spirv-val (without the optimizer's run).
  struct Timings {
    double parseMs = 0, linkMs = 0, spirvMs = 0, validateMs = 0;
  } timings;
};

/// Compiles (GLSL -> SPIR-V 1.5 / Vulkan 1.2, HLSL through glslang's HLSL front end), links,
/// validates with spirv-val and counts instructions; with `options.optimize` also optimizes a copy with
/// the performance passes (validating it too). Link warnings are errors, and the module must contain exactly one OpEntryPoint,
/// named `entryPoint`. Thread-safe to call from several threads (glslang::InitializeProcess once,
/// guarded). GLSL sources without #version get 450.
/// HLSL: EShMsgReadHlsl | EShMsgHlslOffsets; `half` is 32-bit unless ShaderSource::hlsl16BitTypes
/// (EShMsgHlslEnable16BitTypes, as DXC with -enable-16bit-types); glslang's legalization passes run on
/// HLSL output when spirv-val rejects the raw module (e.g. structs holding resources need them), and
/// `spirv` is then the legalized module.
ShaderValidation compileAndValidate(const ShaderSource& src, const ValidateOptions& options = {});

/// Runs spirv-val (Vulkan 1.2 rules) on a module, as compileAndValidate does: true when it is
/// valid; otherwise false, with the validator's messages appended to `log` when given.
bool spirvValidates(const std::vector<uint32_t>& words, std::string* log = nullptr);

/// Counts the instructions of a SPIR-V module (0 if the header is missing or a word count is bad).
std::size_t spirvInstructionCount(const std::vector<uint32_t>& words);

/// Numbers each line of `text` ("  12 | code") for internal-compiler-error dumps.
std::string numberLines(const std::string& text);

}  // namespace substratec
