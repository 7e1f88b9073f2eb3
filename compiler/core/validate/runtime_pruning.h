// Not parsing what no one calls: an entry shader includes the whole runtime
// library, and glslang parses every function of it, called or not, then drops
// the uncalled ones before SPIR-V generation. This unit removes, before glslang
// sees them, the runtime's function definitions that nothing the entry compiles
// can reach, and names the "runtime configuration" an entry compiles the
// runtime under, so that the runtime's whole text is still compiled once per
// configuration (compileAndValidateShared).
//
// Reachability is over identifiers, not calls, and is conservative: every
// identifier of the entry, of the non-runtime files it includes, of the
// preamble's defines, of every preprocessor line and of every runtime text
// that is not a prunable function definition is a root; a definition is kept
// when its name is reached, with every overload of that name, and its own
// identifiers are then reached. A definition is prunable only when it is a
// plain top-level function definition (`T name(...) {...}`, optionally with an
// HLSL `: SEMANTIC`) with no preprocessor line inside it. Any `##` (token
// pasting could make a name no text spells) turns pruning off.
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "validate/runtime_files.h"
#include "validate/shader_validate.h"

namespace substratec {

struct RuntimePruning {
  /// False when the entry cannot be pruned soundly (a `##`, an #include the
  /// runtime and the memory files cannot resolve, includes nested too deep):
  /// then nothing below is set and the entry is compiled as it is.
  bool usable = false;
  /// The runtime configuration: a text that determines everything the runtime's
  /// definitions see when this entry compiles them (language, stage, half types,
  /// entry point, preamble defines, and the entry and its non-runtime includes up
  /// to the entry's last #include, with declarations of names the runtime
  /// never spells dropped and macro names only it spells renamed by first
  /// occurrence). Two entries with the same configuration compile every runtime
  /// definition in the same context: if one of them compiled the whole runtime,
  /// the other's removed definitions compile too.
  std::string configuration;
  /// The included runtime files with the unreachable definitions blanked out
  /// (their newlines kept, so line numbers hold), by name.
  std::map<std::string, std::string> prunedFiles;
  std::size_t definitions = 0;  // prunable function definitions in the included runtime files
  std::size_t removed = 0;      // of which unreachable, and blanked out
};

/// Analyses `entry` (its text, memory files and defines) against the runtime
/// files `runtime` (which must be among entry.memoryFiles by the same names).
RuntimePruning pruneRuntime(const ShaderSource& entry, const std::vector<RuntimeFile>& runtime);

/// `entry` with its runtime files served pruned (`pruning` must outlive the result).
ShaderSource withPrunedRuntime(const ShaderSource& entry, const RuntimePruning& pruning);

/// compileAndValidate, with the work shared between entries of one process: the
/// first entry of each runtime configuration is compiled whole and, when valid,
/// marks the configuration as one whose whole runtime compiles; later entries of
/// a marked configuration are compiled with the runtime pruned, and a pruned
/// compile that fails is compiled again whole, so that diagnostics are what a
/// whole compile gives. The SPIR-V is the same either way (glslang drops uncalled
/// functions; tests/unit/runtime_pruning_test.cc compares every example's,
/// corpus and generated material's entries word for word).
/// On success the log holds the warnings of what was compiled (a pruned compile
/// has none from the definitions it did not parse).
ShaderValidation compileAndValidateShared(const ShaderSource& entry, const std::vector<RuntimeFile>& runtime,
                                          const ValidateOptions& options = {});

/// How compileAndValidateShared's calls in this process went so far: compiled
/// whole (first of a configuration, or not prunable), pruned, and pruned but
/// failed, so compiled again whole (counted in `whole` too).
struct SharedCompileCounts {
  std::size_t whole = 0, pruned = 0, retried = 0;
};
SharedCompileCounts sharedCompileCounts();

}  // namespace substratec
