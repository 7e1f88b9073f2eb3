// Tests for the run-time value library runtime_shaders/substrate_values.h.
//
// The shader functions cannot run in a unit test, so this checks what can be
// checked on the CPU:
// - the header keeps compiling in both languages: two small compute shaders
//   (GLSL and HLSL) that include the prelude and the header and call every
//   public function go through Debian's glslangValidator (and spirv-val when
//   installed), which must exit with status 0;
// - the header declares exactly the public functions listed here, so that a
//   function added to it is also added to the shaders above;
// - substrate_variance_to_roughness inverts substrate_roughness_to_variance to
//   1e-4, checked on a C++ port of the two functions that mirrors the shader
//   line for line (in double, and in float like the shader).
#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <regex>
#include <set>
#include <sstream>
#include <string>

namespace substratec {
namespace values_shader_test {

namespace fs = std::filesystem;

constexpr const char* kGlslangValidator = "/usr/bin/glslangValidator";
constexpr const char* kSpirvVal = "/usr/bin/spirv-val";

fs::path shaderDir() { return fs::path(SUBSTRATEC_SOURCE_DIR) / "runtime_shaders"; }

std::string readFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// A fresh directory under the system temp dir, removed with the object.
class TempDir {
 public:
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "substratec_values_XXXXXX").string();
    if (mkdtemp(pattern.data())) path_ = pattern;
  }
  ~TempDir() {
    std::error_code ec;
    if (!path_.empty()) fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

std::string quoted(const fs::path& p) { return "'" + p.string() + "'"; }

// Runs `command` through the shell with its output in `log`; returns the exit
// status (-1 if it did not exit normally).
int run(const std::string& command, const fs::path& log) {
  const int status = std::system((command + " >" + quoted(log) + " 2>&1").c_str());
  if (status == -1 || !WIFEXITED(status)) return -1;
  return WEXITSTATUS(status);
}

// Every public function of the header, called once from a function written in
// the common dialect (shared by the two shaders). The results are summed into
// the output so that nothing is unused.
constexpr const char* kCallEverything = R"(
float4 substrate_values_test(float4 a, float4 b, float4 c, float4 d) {
  float4 o = SUBSTRATE_SPLAT4(0.0);
  // Math nodes, every overload.
  o.x += substrate_safe_div(a.x, b.x);
  o.xy += substrate_safe_div(a.xy, b.xy);
  o.xyz += substrate_safe_div(a.xyz, b.xyz);
  o += substrate_safe_div(a, b);
  o.x += substrate_value_pow(a.x, b.x);
  o.xy += substrate_value_pow(a.xy, b.xy);
  o.xyz += substrate_value_pow(a.xyz, b.xyz);
  o += substrate_value_pow(a, b);
  o.x += substrate_value_sqrt(a.x);
  o.xy += substrate_value_sqrt(a.xy);
  o.xyz += substrate_value_sqrt(a.xyz);
  o += substrate_value_sqrt(a);
  o.x += substrate_value_normalize(a.x);
  o.xy += substrate_value_normalize(a.xy);
  o.xyz += substrate_value_normalize(a.xyz);
  o += substrate_value_normalize(a);
  o.x += substrate_value_exp(a.x);
  o.xy += substrate_value_exp(a.xy);
  o.xyz += substrate_value_exp(a.xyz);
  o += substrate_value_exp(a);
  // Helper nodes.
  o.xyz += substrate_metalness_to_diffuse(a.xyz, b.x, b.y);
  o.xyz += substrate_metalness_to_f0(a.xyz, b.x, b.y);
  o.x += substrate_ior_to_f0(b.z);
  o.y += substrate_haziness_second_roughness(b.x, b.w);
  o.z += substrate_haziness_weight(b.x, b.w);
  o.xyz += substrate_transmittance_to_mfp(c.xyz, c.w);
  o.w += substrate_transmittance_to_mfp_thickness(c.xyz, c.w);
  o.xyz += substrate_thin_film_f0(d.xyz, a.xyz, b.xyz, c.w, b.z, c.xyz);
  o.xyz += substrate_thin_film_f90(d.xyz, a.xyz, b.xyz, c.w, b.z, c.xyz);
  o.xyz += substrate_rotation_to_tangent(d.w, d.xyz);
  o.w += substrate_view_dependent_coverage(a.w, d.xyz, c.xyz);
  // Tree-walk helpers.
  o.x += substrate_roughness_to_variance(b.x);
  o.y += substrate_variance_to_roughness(c.w);
  o.xyz += substrate_tangent_to_world(a.xyz, d.xyz, c.xyz);
  o.xyz += substrate_orthogonal_tangent(d.xyz, c.xyz);
  return o;
}
)";

// The public functions of the header (one name per overload set).
const std::set<std::string> kPublicFunctions = {
    "substrate_safe_div",
    "substrate_value_pow",
    "substrate_value_sqrt",
    "substrate_value_normalize",
    "substrate_value_exp",
    "substrate_metalness_to_diffuse",
    "substrate_metalness_to_f0",
    "substrate_ior_to_f0",
    "substrate_haziness_second_roughness",
    "substrate_haziness_weight",
    "substrate_transmittance_to_mfp",
    "substrate_transmittance_to_mfp_thickness",
    "substrate_thin_film_f0",
    "substrate_thin_film_f90",
    "substrate_rotation_to_tangent",
    "substrate_view_dependent_coverage",
    "substrate_roughness_to_variance",
    "substrate_variance_to_roughness",
    "substrate_tangent_to_world",
    "substrate_orthogonal_tangent",
};

std::string glslShader() {
  return std::string(R"(#version 450
#extension GL_GOOGLE_include_directive : require
#include "substrate_prelude.glsl"
#include "substrate_values.h"
)") + kCallEverything +
         R"(
layout(local_size_x = 1) in;
layout(std430, binding = 0) buffer Data { vec4 v[]; } data;
void main() {
  data.v[4] = substrate_values_test(data.v[0], data.v[1], data.v[2], data.v[3]);
}
)";
}

std::string hlslShader() {
  return std::string(R"(#include "substrate_prelude.hlsl"
#include "substrate_values.h"
)") + kCallEverything +
         R"(
RWStructuredBuffer<float4> data : register(u0);
[numthreads(1, 1, 1)]
void main() {
  data[4] = substrate_values_test(data[0], data[1], data[2], data[3]);
}
)";
}

// Writes `source` to dir/name, compiles it with glslangValidator `flags` to
// SPIR-V, validates the result with spirv-val when installed; returns "" on
// success, else the failing command's output.
std::string compile(const fs::path& dir, const std::string& name, const std::string& source,
                    const std::string& flags, const std::string& spirvValFlags) {
  const fs::path src = dir / name, spv = dir / (name + ".spv"), log = dir / (name + ".log");
  std::ofstream(src, std::ios::binary) << source;
  const std::string glslang = std::string(kGlslangValidator) + " " + flags + " -I" + quoted(shaderDir()) + " -o " +
                              quoted(spv) + " " + quoted(src);
  if (int status = run(glslang, log); status != 0)
    return glslang + "\nexit status " + std::to_string(status) + "\n" + readFile(log);
  if (fs::exists(kSpirvVal)) {
    const std::string val = std::string(kSpirvVal) + " " + spirvValFlags + " " + quoted(spv);
    if (int status = run(val, log); status != 0)
      return val + "\nexit status " + std::to_string(status) + "\n" + readFile(log);
  }
  return "";
}

TEST(ValuesShader, HeaderDeclaresExactlyThePublicFunctions) {
  const std::string header = readFile(shaderDir() / "substrate_values.h");
  ASSERT_FALSE(header.empty());
  EXPECT_NE(header.find("#ifndef SUBSTRATE_VALUES_H"), std::string::npos);
  std::set<std::string> found;
  const std::regex definition(R"((?:^|\n)float[234]? (substrate_[a-z0-9_]+)\()");
  for (auto it = std::sregex_iterator(header.begin(), header.end(), definition); it != std::sregex_iterator(); ++it) {
    const std::string name = (*it)[1];
    if (name.rfind("substrate_values_", 0) != 0) found.insert(name);  // substrate_values_*: internal
  }
  EXPECT_EQ(found, kPublicFunctions);
  for (const std::string& f : kPublicFunctions)
    EXPECT_NE(std::string(kCallEverything).find(f + "("), std::string::npos) << f << " is not called by the shaders";
}

TEST(ValuesShader, CompilesAsGlsl) {
  if (!fs::exists(kGlslangValidator)) GTEST_SKIP() << kGlslangValidator << " is not installed";
  TempDir dir;
  ASSERT_FALSE(dir.path().empty());
  EXPECT_EQ(compile(dir.path(), "values_test.comp", glslShader(), "-V --target-env vulkan1.2",
                    "--target-env vulkan1.2"),
            "");
}

TEST(ValuesShader, CompilesAsHlsl) {
  if (!fs::exists(kGlslangValidator)) GTEST_SKIP() << kGlslangValidator << " is not installed";
  TempDir dir;
  ASSERT_FALSE(dir.path().empty());
  EXPECT_EQ(compile(dir.path(), "values_test.hlsl", hlslShader(), "-V -D -e main -S comp", ""), "");
}

// ---------------------------------------------------------------------------
// C++ port of substrate_roughness_to_variance and substrate_variance_to_roughness
// (and of substrate_value_pow, which the first one calls), line for line. F is
// double (the reference) or float (as the shader computes).

template <typename F>
F clampF(F x, F lo, F hi) {  // GLSL/HLSL clamp: min(max(x, lo), hi)
  return std::min(std::max(x, lo), hi);
}

template <typename F>
F substrate_value_pow(F x, F y) {
  if (y == F(0)) return F(1);
  F b = std::max(x, F(0));
  if (b == F(0)) return F(0);
  return std::min(std::pow(b, y), std::numeric_limits<F>::max());
}

template <typename F>
F substrate_roughness_to_variance(F r) {
  F rc = clampF(r, F(0), F(0.999));
  return substrate_value_pow(rc, F(1.1)) / (F(1) - rc);
}

template <typename F>
F substrate_variance_to_roughness(F v) {
  if (!(v > F(0))) return F(0);
  F L = std::log(clampF(v, F(1e-30), substrate_roughness_to_variance(F(0.999))));
  F x = L >= F(0) ? L : L / F(1.1);
  for (int i = 0; i < 2; ++i) {
    F r = F(1) / (F(1) + std::exp(-x));
    F h = F(1.1) * std::log(r) - std::log(F(1) - r) - L;
    x = x - h / (F(1.1) - F(0.1) * r);
  }
  return clampF(F(1) / (F(1) + std::exp(-x)), F(0), F(0.999));
}

template <typename F>
double worstRoundTripError() {
  double worst = 0;
  constexpr int kSteps = 99900;  // r = 0, 1e-5, ..., 0.999
  for (int i = 0; i <= kSteps; ++i) {
    const F r = F(0.999 * i / kSteps);
    const F back = substrate_variance_to_roughness(substrate_roughness_to_variance(r));
    worst = std::max(worst, std::fabs(double(back) - double(r)));
  }
  return worst;
}

TEST(ValuesShader, VarianceToRoughnessInvertsRoughnessToVariance) {
  EXPECT_LT(worstRoundTripError<double>(), 1e-4);
  EXPECT_LT(worstRoundTripError<double>(), 1e-9);  // two Newton steps: ~1e-11
  EXPECT_LT(worstRoundTripError<float>(), 1e-4);   // float rounding only
}

TEST(ValuesShader, RoughnessToVarianceInvertsVarianceToRoughness) {
  // Variances from 1e-30 to the largest (roughness 0.999), log-spaced.
  const double vmax = substrate_roughness_to_variance(0.999);
  for (double e = -30; e <= std::log10(vmax); e += 0.01) {
    const double v = std::pow(10.0, e);
    const double r = substrate_variance_to_roughness(v);
    EXPECT_NEAR(substrate_roughness_to_variance(r), v, 1e-9 * v) << "v = " << v;
  }
}

TEST(ValuesShader, VarianceToRoughnessGuards) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(substrate_variance_to_roughness(0.0), 0.0);
  EXPECT_EQ(substrate_variance_to_roughness(-1.0), 0.0);
  EXPECT_EQ(substrate_variance_to_roughness(nan), 0.0);
  EXPECT_NEAR(substrate_variance_to_roughness(1e6), 0.999, 1e-12);
  EXPECT_NEAR(substrate_variance_to_roughness(std::numeric_limits<double>::max()), 0.999, 1e-12);
  EXPECT_NEAR(substrate_variance_to_roughness<float>(std::numeric_limits<float>::max()), 0.999f, 1e-6f);
  EXPECT_EQ(substrate_roughness_to_variance(0.0), 0.0);
  EXPECT_EQ(substrate_roughness_to_variance(-1.0), 0.0);
  EXPECT_EQ(substrate_roughness_to_variance(2.0), substrate_roughness_to_variance(0.999));
  // Monotone, and finite in float for every input down to the smallest.
  double previous = -1;
  for (double e = -45; e <= 4; e += 0.05) {
    const float v = float(std::pow(10.0, e));
    const float r = substrate_variance_to_roughness(v);
    ASSERT_TRUE(std::isfinite(r)) << "v = " << v;
    EXPECT_GE(r, previous) << "v = " << v;
    EXPECT_GE(r, 0.0f);
    EXPECT_LE(r, 0.999f);
    previous = r;
  }
}

}  // namespace values_shader_test
}  // namespace substratec
