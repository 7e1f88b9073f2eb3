#include "validate/shader_validate.h"

#include <fmt/format.h>
#include <glslang/Public/ResourceLimits.h>
#include <glslang/MachineIndependent/localintermediate.h>
#include <glslang/Public/ShaderLang.h>
#include <glslang/SPIRV/GlslangToSpv.h>
#include <spirv-tools/libspirv.hpp>
#include <spirv-tools/optimizer.hpp>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <string_view>
#include <memory>
#include <mutex>
#include <sstream>
#include <system_error>

namespace substratec {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kMaxIncludeDepth = 64;
constexpr uint32_t kOpEntryPoint = 15;

// glslang::InitializeProcess() builds the built-in symbol tables shared by all
// threads; it is called once and never finalized (the tables live as long as
// the process).
void initializeGlslangOnce() {
  static std::once_flag once;
  std::call_once(once, [] { glslang::InitializeProcess(); });
}

EShLanguage toGlslangStage(ShaderStage stage) {
  switch (stage) {
    case ShaderStage::Vertex: return EShLangVertex;
    case ShaderStage::Fragment: return EShLangFragment;
    case ShaderStage::Compute: return EShLangCompute;
  }
  return EShLangFragment;
}

bool readWholeFile(const fs::path& path, std::string& out) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return false;
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::ostringstream s;
  s << in.rdbuf();
  out = s.str();
  return true;
}

// Resolves `#include "x"` relative to the including file (glslang passes the
// resolved name of the including file, or the top-level source name), then
// through the include directories; `#include <x>` only through the include
// directories. glslang calls includeLocal first for "" includes and falls back
// to includeSystem when it returns nullptr.
class FileIncluder final : public glslang::TShader::Includer {
 public:
  FileIncluder(const std::vector<std::string>& dirs, const std::map<std::string, std::string_view>& memory)
      : dirs_(dirs), memory_(memory) {}

  IncludeResult* includeLocal(const char* headerName, const char* includerName, std::size_t depth) override {
    if (depth > kMaxIncludeDepth) return depthError(headerName);
    fs::path header(headerName);
    if (header.is_absolute()) return tryOpen(header);
    // A top-level source given by bare name has no location: don't resolve
    // against the working directory (but a memory file of that name is found).
    fs::path dir = fs::path(includerName ? includerName : "").parent_path();
    if (IncludeResult* r = tryMemory((dir / header).lexically_normal().string())) return r;
    if (dir.empty()) return nullptr;
    return tryOpen(dir / header);
  }

  IncludeResult* includeSystem(const char* headerName, const char* /*includerName*/, std::size_t depth) override {
    if (depth > kMaxIncludeDepth) return depthError(headerName);
    fs::path header(headerName);
    if (header.is_absolute()) return tryOpen(header);
    if (IncludeResult* r = tryMemory(header.lexically_normal().string())) return r;
    for (const std::string& d : dirs_) {
      if (IncludeResult* r = tryOpen(fs::path(d) / header)) return r;
    }
    return nullptr;
  }

  void releaseInclude(IncludeResult* result) override {
    if (!result) return;
    delete static_cast<std::string*>(result->userData);  // null for memory files
    delete result;
  }

 private:
  IncludeResult* tryMemory(const std::string& name) {
    auto it = memory_.find(name);
    if (it == memory_.end()) return nullptr;
    return new IncludeResult(it->first, it->second.data(), it->second.size(), nullptr);
  }

  IncludeResult* tryOpen(const fs::path& path) {
    std::string text;
    if (!readWholeFile(path, text)) return nullptr;
    auto* content = new std::string(std::move(text));
    return new IncludeResult(path.lexically_normal().string(), content->data(), content->size(), content);
  }

  IncludeResult* depthError(const char* headerName) {
    auto* msg = new std::string(fmt::format("include depth exceeds {} (recursive include of \"{}\"?)",
                                            kMaxIncludeDepth, headerName));
    return new IncludeResult("", msg->data(), msg->size(), msg);
  }

  const std::vector<std::string>& dirs_;
  const std::map<std::string, std::string_view>& memory_;
};

void appendLog(std::string& log, const std::string& text) {
  if (text.empty()) return;
  log += text;
  if (log.back() != '\n') log += '\n';
}

bool containsLine(const std::string& log, const char* prefix) {
  std::istringstream in(log);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(prefix, 0) == 0) return true;
  }
  return false;
}

spvtools::MessageConsumer collectInto(std::string& log, const std::string& name, const char* tool) {
  return [&log, name, tool](spv_message_level_t level, const char* /*source*/, const spv_position_t& pos,
                            const char* message) {
    const char* kind = level <= SPV_MSG_ERROR ? "error" : level == SPV_MSG_WARNING ? "warning" : "info";
    log += fmt::format("{}: {}: {}: {} (instruction word {})\n", name, tool, kind, message, pos.index);
  };
}

// Names of the module's OpEntryPoint instructions.
std::vector<std::string> entryPointNames(const std::vector<uint32_t>& words) {
  std::vector<std::string> names;
  if (words.size() < 5) return names;
  for (std::size_t i = 5; i < words.size();) {
    uint32_t count = words[i] >> 16;
    if (count == 0 || i + count > words.size()) break;
    if ((words[i] & 0xffffu) == kOpEntryPoint && count > 3) {
      std::string name;
      for (std::size_t w = i + 3; w < i + count; ++w) {
        bool end = false;
        for (int b = 0; b < 4; ++b) {
          char c = static_cast<char>((words[w] >> (8 * b)) & 0xffu);
          if (c == '\0') {
            end = true;
            break;
          }
          name += c;
        }
        if (end) break;
      }
      names.push_back(std::move(name));
    }
    i += count;
  }
  return names;
}

// spirv-val. Friendly names in its messages cost more than the validation
// itself (SPIRV-Tools builds a name for every id up front), so a module is
// validated without them, and only a rejected one again with them, for the log.
bool spirvValid(const std::vector<uint32_t>& words, std::string* log, const std::string& name, const char* tool) {
  spvtools::SpirvTools tools(SPV_ENV_VULKAN_1_2);
  spvtools::ValidatorOptions quick;
  quick.SetFriendlyNames(false);
  if (tools.Validate(words.data(), words.size(), quick)) return true;
  if (!log) return false;
  tools.SetMessageConsumer(collectInto(*log, name, tool));
  spvtools::ValidatorOptions named;
  named.SetFriendlyNames(true);
  tools.Validate(words.data(), words.size(), named);
  return false;
}

}  // namespace

bool spirvValidates(const std::vector<uint32_t>& words, std::string* log) {
  return spirvValid(words, log, "module", "spirv-val");
}

std::size_t spirvInstructionCount(const std::vector<uint32_t>& words) {
  if (words.size() < 5) return 0;
  std::size_t n = 0;
  for (std::size_t i = 5; i < words.size();) {
    uint32_t count = words[i] >> 16;
    if (count == 0 || i + count > words.size()) return 0;
    ++n;
    i += count;
  }
  return n;
}

namespace {

/// Milliseconds since `start`, and `start` moved to now (the phases of ShaderValidation::timings).
double lap(std::chrono::steady_clock::time_point& start) {
  const auto now = std::chrono::steady_clock::now();
  const double ms = std::chrono::duration<double, std::milli>(now - start).count();
  start = now;
  return ms;
}

/// SPIR-V from a linked program, into result.spirv; for HLSL legalized when
/// spirv-val rejects the raw module. False (the log says why) when it fails.
/// `validated`: the module kept is the raw HLSL one spirv-val has just
/// accepted, with the options validateSpirvModule would use (no need to again).
bool spirvFromProgram(glslang::TProgram& program, EShLanguage stage, bool hlsl, const ShaderSource& src,
                      ShaderValidation& result, bool& validated) {
  validated = false;
  auto clock = std::chrono::steady_clock::now();
  // glslang's GLSL front end declares storage buffers in the StorageBuffer
  // class for SPIR-V >= 1.3, but its HLSL front end (12.0) keeps the
  // Uniform + BufferBlock form that SPIR-V 1.4 removed, which spirv-val rejects
  // for (RW)StructuredBuffer and ByteAddressBuffer. Ask for the 1.3 form.
  program.getIntermediate(stage)->setUseStorageBuffer();

  glslang::SpvOptions spvOptions;
  spvOptions.generateDebugInfo = false;
  spvOptions.validate = false;
  spvOptions.disableOptimizer = true;
  spv::SpvBuildLogger logger;
  glslang::GlslangToSpv(*program.getIntermediate(stage), result.spirv, &logger, &spvOptions);
  const std::string spvLog = logger.getAllMessages();
  appendLog(result.log, spvLog);
  result.timings.spirvMs += lap(clock);
  if (containsLine(spvLog, "error") || result.spirv.empty()) return false;

  // HLSL: glslang's raw output is often not valid Vulkan SPIR-V (e.g. structs
  // holding textures and samplers) until its legalization passes run; they
  // cost more than everything else here, so they run only when spirv-val
  // rejects the raw module. Either way the module kept is one spirv-val accepts.
  if (hlsl) {
    validated = spirvValid(result.spirv, nullptr, src.name, "spirv-val");
    result.timings.validateMs += lap(clock);
  }
  if (hlsl && !validated) {
    std::vector<uint32_t> legalized;
    spv::SpvBuildLogger legalizeLogger;
    spvOptions.disableOptimizer = false;  // glslang runs legalization only with its optimizer on
    glslang::GlslangToSpv(*program.getIntermediate(stage), legalized, &legalizeLogger, &spvOptions);
    const std::string legalizeLog = legalizeLogger.getAllMessages();
    if (legalizeLog != spvLog) appendLog(result.log, legalizeLog);
    result.timings.spirvMs += lap(clock);
    if (containsLine(legalizeLog, "error") || legalized.empty()) return false;
    result.spirv = std::move(legalized);
  }
  return true;
}

/// Checks the module's one entry point and runs spirv-val (unless `validated`:
/// spirvFromProgram has), and, when asked, spirv-opt and spirv-val again, on
/// result.spirv; sets result.ok when all pass.
void validateSpirvModule(const ShaderSource& src, const ValidateOptions& options, bool validated,
                         ShaderValidation& result) {
  auto clock = std::chrono::steady_clock::now();
  const std::vector<std::string> entries = entryPointNames(result.spirv);
  if (entries.size() != 1 || entries.front() != src.entryPoint) {
    appendLog(result.log, fmt::format("{}: expected exactly one entry point \"{}\", the module has {}", src.name,
                                      src.entryPoint, entries.size()));
    return;
  }

  const bool valid = validated || spirvValid(result.spirv, &result.log, src.name, "spirv-val");
  result.timings.validateMs += lap(clock);
  if (!valid) return;
  result.instructionCount = spirvInstructionCount(result.spirv);

  if (options.optimize) {
    std::vector<uint32_t> optimized;
    spvtools::Optimizer optimizer(SPV_ENV_VULKAN_1_2);
    optimizer.SetMessageConsumer(collectInto(result.log, src.name, "spirv-opt"));
    optimizer.RegisterPerformancePasses();
    if (!optimizer.Run(result.spirv.data(), result.spirv.size(), &optimized, spvtools::ValidatorOptions(),
                       /*skip_validation=*/true)) {
      appendLog(result.log, fmt::format("{}: spirv-opt performance passes failed", src.name));
      return;
    }
    if (!spirvValid(optimized, &result.log, src.name, "spirv-val (optimized)")) return;
    result.optimizedInstructionCount = spirvInstructionCount(optimized);
    result.optimized = std::move(optimized);
  }
  result.ok = true;
}

}  // namespace

ShaderValidation compileAndValidate(const ShaderSource& src, const ValidateOptions& options) {
  initializeGlslangOnce();
  ShaderValidation result;
  const bool hlsl = src.language == ShaderLanguage::Hlsl;
  const EShLanguage stage = toGlslangStage(src.stage);

  std::string preamble;
  if (!hlsl) preamble += "#extension GL_GOOGLE_include_directive : enable\n";
  for (const auto& [name, value] : src.defines) preamble += fmt::format("#define {} {}\n", name, value);

  // TShader must outlive TProgram (the program refers to the shader's tree).
  glslang::TShader shader(stage);
  const char* text = src.text.c_str();
  const int length = static_cast<int>(src.text.size());
  const char* name = src.name.c_str();
  shader.setStringsWithLengthsAndNames(&text, &length, &name, 1);
  shader.setPreamble(preamble.c_str());
  shader.setEntryPoint(src.entryPoint.c_str());
  if (hlsl || src.entryPoint != "main") shader.setSourceEntryPoint(src.entryPoint.c_str());
  shader.setEnvInput(hlsl ? glslang::EShSourceHlsl : glslang::EShSourceGlsl, stage, glslang::EShClientVulkan, 100);
  shader.setEnvClient(glslang::EShClientVulkan, glslang::EShTargetVulkan_1_2);
  shader.setEnvTarget(glslang::EShTargetSpv, glslang::EShTargetSpv_1_5);

  int messages = EShMsgSpvRules | EShMsgVulkanRules;
  if (hlsl) messages |= EShMsgReadHlsl | EShMsgHlslOffsets;
  if (hlsl && src.hlsl16BitTypes) messages |= EShMsgHlslEnable16BitTypes;
  const auto msgs = static_cast<EShMessages>(messages);

  auto clock = std::chrono::steady_clock::now();
  FileIncluder includer(src.includeDirs, src.memoryFiles);
  const bool parsed = shader.parse(GetDefaultResources(), /*defaultVersion=*/hlsl ? 100 : 450,
                                   /*forwardCompatible=*/false, msgs, includer);
  appendLog(result.log, shader.getInfoLog());
  appendLog(result.log, shader.getInfoDebugLog());
  result.timings.parseMs = lap(clock);
  if (!parsed) return result;

  glslang::TProgram program;
  program.addShader(&shader);
  const bool linked = program.link(msgs);
  result.timings.linkMs = lap(clock);
  const std::string linkLog = program.getInfoLog();
  appendLog(result.log, linkLog);
  appendLog(result.log, program.getInfoDebugLog());
  // A missing HLSL entry point is only a link *warning*: every link warning fails.
  if (!linked || containsLine(linkLog, "WARNING:") || containsLine(linkLog, "ERROR:")) {
    if (linked) {
      if (linkLog.find("Entry point not found") != std::string::npos)
        appendLog(result.log, fmt::format("{}: entry point \"{}\" not found", src.name, src.entryPoint));
      appendLog(result.log, fmt::format("{}: link warnings are treated as errors", src.name));
    }
    return result;
  }

  bool validated = false;
  if (!spirvFromProgram(program, stage, hlsl, src, result, validated)) return result;
  validateSpirvModule(src, options, validated, result);
  return result;
}

std::string numberLines(const std::string& text) {
  std::size_t lines = 1;
  for (char c : text) lines += c == '\n';
  if (!text.empty() && text.back() == '\n') --lines;
  const std::size_t width = std::max<std::size_t>(4, std::to_string(lines).size());
  std::string out;
  std::size_t number = 1;
  std::size_t start = 0;
  while (start < text.size() || (start == 0 && text.empty())) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    out += fmt::format("{:>{}} | ", number++, width);
    out.append(text, start, end - start);
    out += '\n';
    start = end + 1;
    if (text.empty()) break;
  }
  return out;
}

}  // namespace substratec
