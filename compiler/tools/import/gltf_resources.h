// The files a .gltf or .glb refers to — `buffers` (geometry) and `images`
// (textures) — checked when a document is imported: a resource that cannot
// be read is a warning per file, or an error for an image a material samples.
//
// What "needs" means here: importing a material reads no texel and no vertex
// (an imported material's textures are texture2d inputs the renderer binds by
// name). Geometry is therefore never needed: a missing or short buffer is a
// warning. An image that a texture of one of the document's materials samples
// is needed by that material — without it the renderer has nothing to bind —
// so an image that cannot be read (a missing or unreadable file, a malformed
// data: URI, a bufferView into a buffer that cannot be read or is too short)
// is an error at /images/N; an image no material samples is a warning. The
// corpus' .materials.json extracts carry no resources and are not checked.
#pragma once
#include <optional>
#include <string>

#include "diag/diagnostics.h"
#include "blocks/material_writer.h"

namespace substratec::import {

// The value writer, the layered surface and the glTF model live in blocks/,
// shared with the building blocks' expansion.
using namespace substratec::blocks;  // NOLINT(google-build-using-namespace)

/// Most missing-resource warnings reported one by one (then one line for the rest).
inline constexpr int kMaxResourceWarnings = 32;

/// Checks `doc`'s buffers and images: file URIs relative to `baseDir`
/// (percent-decoded), data: URIs decoded, a .glb's buffer 0 without a URI
/// against `glbBinBytes` (the size of its binary chunk; nullopt for a .gltf or
/// a .glb without one). Diagnostics located by JSON pointer. False on errors.
bool checkGltfResources(const Json& doc, const std::string& baseDir, std::optional<std::size_t> glbBinBytes,
                        Diagnostics& diags);

/// The bytes of a base64 data: URI (data:[<media type>];base64,<data>), or
/// nullopt with `*why` when it is not one or is malformed.
std::optional<std::string> decodeDataUri(const std::string& uri, std::string* why);

/// The bytes of `doc`'s image `index` when it is embedded — a data: URI, or a
/// bufferView of a .glb's binary chunk `glbBin` (null for none) or of a buffer
/// given as a data: URI — and its file extension by its MIME type ("png",
/// "jpg"; "img" for another). nullopt with `*why` when the image is a file
/// (`*why` empty) or its bytes cannot be had.
struct EmbeddedImage {
  std::string bytes, extension;
};
std::optional<EmbeddedImage> embeddedImage(const Json& doc, int index, const std::string* glbBin, std::string* why);

/// A relative URI as a path (percent-decoded), or nullopt when it is not one
/// (a scheme such as data: or http:).
std::optional<std::string> uriPath(const std::string& uri);

}  // namespace substratec::import
