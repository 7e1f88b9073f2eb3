// The binary glTF container (.glb, glTF 2.0 specification section 4.4): a
// 12-byte header (magic "glTF", version 2, total length), then chunks of
// (length, type, data) aligned to 4 bytes; the first chunk is the JSON
// (type "JSON"), an optional second one the binary buffer ("BIN\0"). Every
// field is checked against the bytes actually present; errors name the byte
// offset of the offending field.
#pragma once
#include <optional>
#include <string>

#include "diag/diagnostics.h"

namespace substratec::import {

/// The JSON chunk's text (trailing space padding removed), or nullopt with a
/// diagnostic "byte N: ..." when the container is malformed.
std::optional<std::string> glbJsonChunk(const std::string& bytes, Diagnostics& diags);

/// The size of the binary chunk ("BIN\0", the second chunk) of a container
/// glbJsonChunk accepted, or nullopt when it has none.
std::optional<std::size_t> glbBinChunkSize(const std::string& bytes);

/// The binary chunk's bytes of a container glbJsonChunk accepted, or nullopt.
std::optional<std::string> glbBinChunk(const std::string& bytes);

/// True when `bytes` starts with the .glb magic.
bool looksLikeGlb(const std::string& bytes);

}  // namespace substratec::import
