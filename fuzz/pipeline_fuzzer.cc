// libFuzzer target: the whole CPU side of `substratec compile`. Arbitrary
// bytes through compileText (parse, expand-blocks, resolve, build-values, build-tree, cull,
// features, shared-bases, price, simplify), then the reports and
// generateFiles (GLSL, HLSL, entry shaders, layout.json). glslang validation
// is left out: it is slow and it is not code this fuzzer should explore.
//
// A failure must come with a diagnostic; a success must generate every file.
// An uncaught exception is a bug (the CLI would report an internal error).
//
// Byte-level mutations almost always break the JSON, so most inputs would
// stop in the parser. Half of the mutations are therefore made on the JSON
// document (LLVMFuzzerCustomMutator below): change a number to an edge value,
// a string to a kind, pin or reference, delete or add a member, copy a
// subtree elsewhere, wrap a value in an inline node. Those keep the input a
// material and reach resolve's deeper checks, the passes and code generation.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "diag/diagnostics.h"
#include "pipeline/generate.h"
#include "pipeline/pipeline.h"
#include "report/report.h"

using namespace substratec;

extern "C" std::size_t LLVMFuzzerMutate(std::uint8_t* data, std::size_t size, std::size_t maxSize);

namespace {

const char* const kWords[] = {
    "slab", "horizontal", "vertical", "add", "coverage_weight", "select", "geometry", "texture", "subtract",
    "multiply", "divide", "min", "max", "lerp", "clamp", "saturate", "one_minus", "abs", "sqrt", "normalize",
    "length", "pow", "dot", "swizzle", "combine", "metalness_to_diffuse_f0", "ior_to_f0",
    "haziness_to_second_roughness", "transmittance_to_mfp", "thin_film", "rotation_to_tangent",
    "view_dependent_coverage", "diffuse_albedo", "f0", "f90", "roughness", "anisotropy", "normal", "tangent",
    "sss_mfp", "sss_mfp_scale", "sss_phase_anisotropy", "emissive", "second_roughness", "second_roughness_weight",
    "fuzz_amount", "fuzz_color", "fuzz_roughness", "glint_value", "glint_uv", "sss_type", "specular_profile",
    "background", "foreground", "mix", "top", "base", "thickness", "a", "b", "weight", "value", "threshold", "x",
    "y", "z", "w", "t", "lo", "hi", "attribute", "uv", "channels", "uv0", "uv1", "position", "view",
    "vertex_color", "rgb", "xyz", "zyx", "wzyx", "none", "wrap", "diffusion", "simple_volume", "opaque", "masked",
    "translucent_grey", "float", "vec2", "vec3", "color", "texture2d"};
const char* const kPins[] = {"diffuse_albedo", "f0", "roughness", "anisotropy", "normal", "tangent", "sss_mfp",
                             "emissive", "fuzz_amount", "glint_value", "second_roughness_weight", "sss_type",
                             "a", "b", "x", "t", "mix", "weight", "top", "base", "background", "foreground",
                             "value", "thickness", "kind", "channels", "uv"};
const char* const kUnary[] = {"saturate", "one_minus", "abs", "sqrt", "normalize", "length"};
const char* const kBinary[] = {"add", "subtract", "multiply", "divide", "min", "max", "pow", "dot"};
const char* const kSubstrate[] = {"horizontal", "vertical", "add", "coverage_weight", "select"};
const double kNumbers[] = {0, 1, -1, 0.5, 2, 1e-7, 1e7, -0.0, 3.4e38, 1e-300, 0.9999, 1024, 8, 80};

template <typename T, std::size_t N>
const T& pick(const T (&a)[N], std::minstd_rand& rng) {
  return a[rng() % N];
}

/// Every value in the document (iterative; parent first), with the names
/// (keys of /nodes and /inputs) that references can use.
void collect(Json& doc, std::vector<Json*>& values, std::vector<std::string>& names) {
  std::vector<Json*> stack{&doc};
  while (!stack.empty() && values.size() < 4096) {
    Json* j = stack.back();
    stack.pop_back();
    values.push_back(j);
    if (j->is_object())
      for (auto it = j->begin(); it != j->end(); ++it) stack.push_back(&*it);
    else if (j->is_array())
      for (auto& e : *j) stack.push_back(&e);
  }
  for (const char* section : {"nodes", "inputs"})
    if (doc.is_object() && doc.contains(section) && doc[section].is_object())
      for (auto it = doc[section].begin(); it != doc[section].end(); ++it)
        names.push_back(std::string(section[0] == 'i' ? "$" : "") + it.key());
}

/// One structural mutation of a parsed material; false if none applied.
bool mutateDocument(Json& doc, std::minstd_rand& rng) {
  std::vector<Json*> values;
  std::vector<std::string> names;
  collect(doc, values, names);
  if (values.size() < 2) return false;
  Json& v = *values[1 + rng() % (values.size() - 1)];
  auto reference = [&]() -> std::string {
    if (names.empty() || rng() % 4 == 0) return pick(kWords, rng);
    std::string n = names[rng() % names.size()];
    if (rng() % 6 == 0) n += std::string(".") + pick(kWords, rng);
    return n;
  };
  switch (rng() % 9) {
    case 0:  // a number to an edge value
      if (!v.is_number()) return false;
      v = rng() % 4 ? pick(kNumbers, rng) : static_cast<double>(static_cast<int>(rng() % 2001) - 1000) / 100.0;
      return true;
    case 1:  // a string to a word or a reference
      if (!v.is_string()) return false;
      v = reference();
      return true;
    case 2:  // delete a member
      if (!v.is_object() || v.empty()) return false;
      v.erase(std::next(v.begin(), static_cast<std::ptrdiff_t>(rng() % v.size())).key());
      return true;
    case 3: {  // add a member: a pin with a number, a reference or a copy of another value
      if (!v.is_object()) return false;
      const Json& other = *values[rng() % values.size()];
      Json value = rng() % 3 == 0 ? Json(pick(kNumbers, rng)) : rng() % 2 ? Json(reference()) : other;
      if (value.dump().size() > 4096) return false;
      v[pick(kPins, rng)] = std::move(value);
      return true;
    }
    case 4: {  // copy another value over this one
      const Json& other = *values[rng() % values.size()];
      if (&other == &v || other.dump().size() > 4096) return false;
      Json copy = other;
      v = std::move(copy);
      return true;
    }
    case 5:  // wrap in an inline value node
      if (rng() % 2) v = Json{{"kind", pick(kUnary, rng)}, {"x", v}};
      else v = Json{{"kind", pick(kBinary, rng)}, {"a", v}, {"b", rng() % 2 ? Json(pick(kNumbers, rng)) : Json(reference())}};
      return true;
    case 6:  // wrap in an inline Substrate operator
      v = Json{{"kind", pick(kSubstrate, rng)}, {"a", v}, {"b", reference()}, {"top", v}, {"base", reference()},
               {"background", v}, {"foreground", reference()}, {"mix", 0.5}, {"weight", 0.5}, {"value", 0.25}};
      for (const char* pin : {"a", "b", "top", "base", "background", "foreground", "mix", "weight", "value"})
        if (rng() % 2) v.erase(pin);
      return true;
    case 7:  // an array to another length
      if (!v.is_array()) return false;
      if (rng() % 2 && !v.empty()) v.erase(v.size() - 1);
      else v.push_back(pick(kNumbers, rng));
      return true;
    default:  // a node's kind to another kind
      if (!v.is_object() || !v.contains("kind")) return false;
      v["kind"] = pick(kWords, rng);
      return true;
  }
}

}  // namespace

extern "C" std::size_t LLVMFuzzerCustomMutator(std::uint8_t* data, std::size_t size, std::size_t maxSize,
                                               unsigned int seed) {
  std::minstd_rand rng(seed);
  if (size < 2 || rng() % 2) return LLVMFuzzerMutate(data, size, maxSize);
  int depth = 0, deepest = 0;  // nlohmann's dump() recurses: keep the mutator off deep documents
  for (std::size_t i = 1; i < size; ++i) {
    if (data[i] == '[' || data[i] == '{') deepest = std::max(deepest, ++depth);
    else if (data[i] == ']' || data[i] == '}') --depth;
  }
  if (deepest > 200) return LLVMFuzzerMutate(data, size, maxSize);
  Json doc = Json::parse(data + 1, data + size, nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded() || !doc.is_object()) return LLVMFuzzerMutate(data, size, maxSize);
  bool changed = false;
  for (unsigned n = 1 + rng() % 3, i = 0; i < n; ++i) changed = mutateDocument(doc, rng) || changed;
  if (!changed) return LLVMFuzzerMutate(data, size, maxSize);
  const std::string text = doc.dump(rng() % 2 ? -1 : 1);
  if (text.size() + 1 > maxSize) return LLVMFuzzerMutate(data, size, maxSize);
  if (rng() % 8 == 0) data[0] = static_cast<std::uint8_t>(rng());  // another budget mode
  std::memcpy(data + 1, text.data(), text.size());
  return text.size() + 1;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // The first byte picks the budget options (so simplification, the
  // full-simplification path and the closure limits are all explored); the
  // rest is the material file.
  CompileOptions options;
  if (size > 0) {
    const std::uint8_t mode = data[0];
    switch (mode & 3) {
      case 1: options.budgetOverride = 8 + (mode >> 2) * 4; break;        // 8..260 bytes
      case 2: options.maxClosuresOverride = 1 + ((mode >> 2) & 7); break;  // 1..8 closures
      case 3: options.fullSimplification = true; break;
      default: break;  // the material's own settings
    }
    ++data;
    --size;
  }
  const std::string text(reinterpret_cast<const char*>(data), size);
  Diagnostics diags("fuzz.json");
  auto result = compileText("fuzz.json", text, options, diags);
  if (!result) {
    if (!diags.hasErrors()) std::abort();  // rejected without saying why
    return 0;
  }
  if (diags.hasErrors()) std::abort();  // compiled although an error was reported
  (void)formatReportText(*result);
  (void)reportJson(*result).dump();
  GenerateOptions go;
  go.emit.sourceName = "fuzz.json";
  Generated g = generateFiles(*result, go);
  if (g.files.empty()) std::abort();
  for (const auto& f : g.files)
    if (f.name.empty() || f.name.find('/') != std::string::npos) std::abort();  // names stay inside -o DIR
  return 0;
}
