// The images a rendered material's textures are bound to: an image the user
// names (--texture NAME=PATH), else the input's own `file`, else the input's
// neutral texel (gpu::neutralTexel, by the texture's role) with a note. Images
// are decoded (image/decode.h), colour-decoded by the input's colour space and
// mipmapped; a missing or undecodable image is an error at the input's
// pointer, never a silent placeholder.
#pragma once
#include <map>
#include <set>
#include <string>
#include <vector>

#include "diag/diagnostics.h"
#include "gpu/harness.h"
#include "ir/material.h"

namespace substratec::preview {

/// Where a material's texture images come from.
struct TextureSources {
  /// The directory a `file` is relative to: the material file's ("" for the
  /// working directory). An imported material's files are relative to the
  /// document it was imported from.
  std::string baseDir;
  /// Further directories a relative `file` is looked for in, in order, when it
  /// is not under baseDir (--search-path, as MaterialX's tools resolve images).
  std::vector<std::string> searchPaths;
  /// --texture NAME=PATH: PATH (relative to the working directory) for input NAME.
  std::map<std::string, std::string> overrides;
  /// Images embedded in an imported document, by the `file` its inputs name
  /// them with (import::MaterialSource::images); looked up before the disk.
  const std::map<std::string, std::string>* embedded = nullptr;
  /// The material was imported: its inputs' descriptions name their source
  /// (the glTF texture and image, the MaterialX element), and messages quote them.
  bool imported = false;
};

/// A material's textures by input name, ready to bind: linear RGBA32F with
/// their full mip chains, addressed and filtered as the input says (`wrap`,
/// `filter`: repeat and trilinear by default).
struct BoundTextures {
  std::map<std::string, gpu::ImageResource> images;
  std::map<std::string, std::string> sources;  // input -> the image's path, "embedded:<file>" or "neutral"
  std::set<std::string> files;                 // every image file read from disk (inputs of the command)
};

/// The path `file` resolves to: `file` when it is absolute, baseDir/file when
/// it exists, else the first that exists of searchPaths[i]/file and then
/// searchPaths[i]/tail for the tails of `file` without its leading folders,
/// longest first ("../../Images/a.jpg" is found as DIR/Images/a.jpg or
/// DIR/a.jpg); else baseDir/file (which the caller reports as missing).
std::string resolveImagePath(const std::string& file, const TextureSources& sources);

/// Binds every texture input of `m` from `sources`. An input with no image
/// gets a 1 x 1 texture of its neutral texel and a note saying so. False, with
/// errors, when an override names no texture input of `m`, or an image cannot
/// be read or decoded: at the input's `file` (its description, which names
/// the glTF pointer or MaterialX element of an imported material, is quoted).
bool bindTextures(const Material& m, const TextureSources& sources, BoundTextures* out, Diagnostics& diags);

/// The harness's address mode of a texture input's `wrap`.
gpu::Address addressOf(Wrap wrap);

/// A 1 x 1 texture of `texel` (RGBA), for a binding that has no image.
gpu::ImageResource solidTexture(const std::array<double, 4>& texel);

/// The specular profile a profile input without an image is bound to (so that
/// a profile shows: white would be no profile at all): a 32 x 32 view/light
/// LUT (u = NoV, v = NoL), white where both are 1 and shifting through a
/// pearlescent hue toward grazing: with m = (2 − NoV − NoL) / 2,
/// rgb = 1 − 0.6 m (0.5 − 0.5 cos(2π (0.8 m + (0, 1/3, 2/3)))).
gpu::ImageResource defaultSpecularProfile();

}  // namespace substratec::preview
