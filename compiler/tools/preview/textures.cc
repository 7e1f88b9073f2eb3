#include "preview/textures.h"

#include <cmath>
#include <filesystem>
#include <set>
#include <system_error>

#include <fmt/format.h>

#include "gpu/sample_run.h"
#include "image/decode.h"

namespace substratec::preview {

namespace fs = std::filesystem;

namespace {

bool pathExists(const fs::path& p) {
  std::error_code ec;
  return fs::exists(p, ec);
}

/// "texture input 'x'" and, for an imported material, what it came from.
std::string describeInput(const Input& in, bool imported) {
  std::string s = fmt::format("texture input {}", quoteForDiagnostic(in.name));
  if (imported && !in.description.empty()) s += fmt::format(" ({})", in.description);
  return s;
}

/// The decoded, mipmapped image at `path` (or, when `bytes` is not null, of
/// those bytes) into `*out`; false with `*why`.
bool loadTexture(const std::string& path, const std::string* bytes, bool srgb, gpu::ImageResource* out,
                 std::string* why) {
  image::Rgba8 rgba;
  if (bytes ? !image::decode(reinterpret_cast<const std::uint8_t*>(bytes->data()), bytes->size(), &rgba, why)
            : !image::load(path, &rgba, why))
    return false;
  image::MipChain chain = image::mipChain(rgba, srgb);
  out->width = chain.widths[0];
  out->height = chain.heights[0];
  out->layers = 1;
  out->mips = std::move(chain.levels);
  out->filter = gpu::Filter::Linear;
  out->address = gpu::Address::Repeat;
  return true;
}

}  // namespace

std::string resolveImagePath(const std::string& file, const TextureSources& sources) {
  const fs::path f(file);
  if (f.is_absolute()) return f.string();
  const fs::path first = fs::path(sources.baseDir) / f;
  if (pathExists(first)) return first.lexically_normal().string();
  // Along the search paths: the path itself, then its tails without their
  // leading folders ("../../../Images/a.jpg", "Images/a.jpg", "a.jpg"), so
  // that a document's fileprefix need not match the directory layout.
  std::vector<fs::path> tails;
  for (auto it = f.begin(); it != f.end(); ++it) {  // one tail per component
    fs::path tail;
    for (auto jt = it; jt != f.end(); ++jt) tail /= *jt;
    if (*it != ".." && *it != ".") tails.push_back(tail);
    else if (it == f.begin()) tails.push_back(f);
  }
  for (const fs::path& tail : tails)
    for (const std::string& dir : sources.searchPaths)  // bounded by the command line
      if (const fs::path p = fs::path(dir) / tail; pathExists(p)) return p.lexically_normal().string();
  return first.lexically_normal().string();
}

gpu::Address addressOf(Wrap wrap) {
  switch (wrap) {
    case Wrap::Clamp: return gpu::Address::ClampToEdge;
    case Wrap::Mirror: return gpu::Address::MirroredRepeat;
    case Wrap::Repeat: break;
  }
  return gpu::Address::Repeat;
}

gpu::ImageResource solidTexture(const std::array<double, 4>& texel) {
  gpu::ImageResource img;
  img.width = img.height = 1;
  img.mips = {{static_cast<float>(texel[0]), static_cast<float>(texel[1]), static_cast<float>(texel[2]),
               static_cast<float>(texel[3])}};
  img.filter = gpu::Filter::Linear;
  return img;
}

gpu::ImageResource defaultSpecularProfile() {
  constexpr int kSize = 32;
  gpu::ImageResource img;
  img.width = img.height = kSize;
  std::vector<float> texels;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const double noV = (x + 0.5) / kSize, noL = (y + 0.5) / kSize, m = (2.0 - noV - noL) / 2.0;
      for (int c = 0; c < 3; ++c)
        texels.push_back(static_cast<float>(1.0 - 0.6 * m * (0.5 - 0.5 * std::cos(2.0 * M_PI * (0.8 * m + c / 3.0)))));
      texels.push_back(1.0f);
    }
  img.mips = {std::move(texels)};
  img.filter = gpu::Filter::Linear;
  img.address = gpu::Address::ClampToEdge;
  return img;
}

bool bindTextures(const Material& m, const TextureSources& sources, BoundTextures* out, Diagnostics& diags) {
  bool ok = true;
  std::set<std::string> textureNames;
  for (const Input& in : m.inputs)
    if (in.type == VType::Texture) textureNames.insert(in.name);
  for (const auto& [name, path] : sources.overrides)
    if (!textureNames.count(name)) {
      std::string names;
      for (const std::string& n : textureNames) names += (names.empty() ? "" : ", ") + n;
      diags.fail(fmt::format("--texture {}={}: the material has no texture input {} ({})", name, path,
                             quoteForDiagnostic(name),
                             names.empty() ? "it has no texture inputs" : "its texture inputs: " + names));
      ok = false;
    }
  const std::vector<gpu::TextureRole> roles = gpu::textureRoles(m);
  std::set<int> profiles;  // inputs some slab uses as its specular profile
  for (const Slab& slab : m.slabs)
    if (slab.specularProfileInput >= 0) profiles.insert(slab.specularProfileInput);
  for (std::size_t i = 0; i < m.inputs.size(); ++i) {
    const Input& in = m.inputs[i];
    if (in.type != VType::Texture) continue;
    std::string path, why;
    const std::string* embedded = nullptr;
    const auto override = sources.overrides.find(in.name);
    if (override != sources.overrides.end()) {
      path = override->second;
    } else if (!in.file.empty() && sources.embedded && sources.embedded->count(in.file)) {
      embedded = &sources.embedded->at(in.file);
      path = "embedded:" + in.file;
    } else if (!in.file.empty()) {
      path = resolveImagePath(in.file, sources);
    }
    if (path.empty() && profiles.count(static_cast<int>(i))) {
      diags.note(in.pointer, fmt::format("{} has no image: bound to the default specular profile (a pearlescent hue "
                                         "toward grazing); --texture {}=PATH binds one",
                                         describeInput(in, sources.imported), in.name));
      out->images[in.name] = defaultSpecularProfile();
      out->sources[in.name] = "default specular profile";
      continue;
    }
    if (path.empty()) {
      const std::array<double, 4> texel = gpu::neutralTexel(roles[i]);
      diags.note(in.pointer,
                 fmt::format("{} has no image: bound to its neutral texel ({:g}, {:g}, {:g}, {:g}); "
                             "--texture {}=PATH binds one",
                             describeInput(in, sources.imported), texel[0], texel[1], texel[2], texel[3], in.name));
      out->images[in.name] = solidTexture(texel);
      out->sources[in.name] = "neutral";
      continue;
    }
    gpu::ImageResource img;
    if (!loadTexture(path, embedded, in.srgb, &img, &why)) {
      if (override != sources.overrides.end())
        diags.fail(fmt::format("--texture {}={}: cannot use the image: {}", in.name, path, why));
      else
        diags.error(in.pointer + "/file",
                    fmt::format("{}: cannot use the image {} ({}): {}{}", describeInput(in, sources.imported),
                                quoteForDiagnostic(in.file), path, why,
                                sources.searchPaths.empty() && why == "no such file"
                                    ? " (a relative path is looked for beside the material file, "
                                      "then along --search-path)"
                                    : ""));
      ok = false;
      continue;
    }
    img.address = addressOf(in.wrapU);
    img.addressV = addressOf(in.wrapV);
    img.filter = in.nearest ? gpu::Filter::Nearest : gpu::Filter::Linear;
    out->images[in.name] = std::move(img);
    out->sources[in.name] = path;
    if (!embedded) out->files.insert(path);
  }
  return ok;
}

}  // namespace substratec::preview
