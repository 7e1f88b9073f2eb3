#include "import/glb_container.h"

#include <cstdint>

#include <fmt/format.h>

namespace substratec::import {

namespace {

constexpr std::uint32_t kMagic = 0x46546C67;      // "glTF"
constexpr std::uint32_t kChunkJson = 0x4E4F534A;  // "JSON"
constexpr std::uint32_t kChunkBin = 0x004E4942;   // "BIN\0"

std::uint32_t le32(const std::string& b, std::size_t at) {
  return static_cast<std::uint32_t>(static_cast<unsigned char>(b[at])) |
         static_cast<std::uint32_t>(static_cast<unsigned char>(b[at + 1])) << 8 |
         static_cast<std::uint32_t>(static_cast<unsigned char>(b[at + 2])) << 16 |
         static_cast<std::uint32_t>(static_cast<unsigned char>(b[at + 3])) << 24;
}

}  // namespace

std::optional<std::size_t> glbBinChunkSize(const std::string& b) {
  std::size_t at = 12;
  for (int chunk = 0; at + 8 <= b.size() && chunk < 2; ++chunk) {
    const std::uint32_t length = le32(b, at), type = le32(b, at + 4);
    if (length > b.size() - at - 8) return std::nullopt;
    if (chunk == 1 && type == kChunkBin) return length;
    at += 8 + std::size_t{length};
  }
  return std::nullopt;
}

std::optional<std::string> glbBinChunk(const std::string& b) {
  const std::optional<std::size_t> size = glbBinChunkSize(b);
  if (!size) return std::nullopt;
  const std::size_t jsonLength = le32(b, 12);  // the first chunk's; glbBinChunkSize checked it fits
  return b.substr(12 + 8 + jsonLength + 8, *size);
}

bool looksLikeGlb(const std::string& bytes) { return bytes.size() >= 4 && le32(bytes, 0) == kMagic; }

std::optional<std::string> glbJsonChunk(const std::string& b, Diagnostics& diags) {
  auto fail = [&](std::size_t at, const std::string& what) {
    diags.error(fmt::format("byte {}", at), "malformed .glb container: " + what);
    return std::nullopt;
  };
  if (b.size() < 12) return fail(0, fmt::format("{} bytes, shorter than the 12-byte header", b.size()));
  if (le32(b, 0) != kMagic) return fail(0, "the magic is not \"glTF\"");
  if (const std::uint32_t version = le32(b, 4); version != 2)
    return fail(4, fmt::format("version {} (only glTF 2 containers are read)", version));
  const std::uint32_t length = le32(b, 8);
  if (length != b.size()) return fail(8, fmt::format("the header says {} bytes, the file has {}", length, b.size()));
  std::optional<std::string> json;
  std::size_t at = 12;
  for (int chunk = 0; at < b.size(); ++chunk) {
    if (b.size() - at < 8) return fail(at, "a chunk header is cut short");
    const std::uint32_t chunkLength = le32(b, at), type = le32(b, at + 4);
    if (chunkLength > b.size() - at - 8)
      return fail(at, fmt::format("chunk {} claims {} bytes, {} remain", chunk, chunkLength, b.size() - at - 8));
    if (chunkLength % 4 != 0) return fail(at, fmt::format("chunk {} is {} bytes, not a multiple of 4", chunk, chunkLength));
    if (chunk == 0) {
      if (type != kChunkJson) return fail(at + 4, "the first chunk is not the JSON chunk");
      json = b.substr(at + 8, chunkLength);
      while (!json->empty() && (json->back() == ' ' || json->back() == '\0')) json->pop_back();
    } else if (chunk == 1 && type != kChunkBin) {
      // Unknown chunk types are skipped (the specification lets readers ignore them).
    } else if (type == kChunkJson) {
      return fail(at + 4, "a second JSON chunk");
    }
    at += 8 + chunkLength;
  }
  if (!json) return fail(12, "no JSON chunk");
  return json;
}

}  // namespace substratec::import
