// Self-contained entry shaders (a stock glslangValidator compiles them with
// -I DIR -I runtime_shaders): the forward pass (closures evaluated inline and
// lit, no packing; unrolled per closure, so a one-closure material has no
// loop) and the base pass (closures packed into the material buffer: the
// first 3 words to render targets, the rest to a storage image array; the
// top-layer word to its own target). GLSL and HLSL through one Syntax table.
#pragma once
#include <string>

#include "emit/material_emitter.h"

namespace substratec {

/// The forward pass lights closures: `precision` selects the runtime's (the base pass only packs, in float32).
std::string emitForwardEntry(const Material& m, const StorageLayout& layout, const Syntax& syn,
                             Precision precision = Precision::Float);
std::string emitBasePassEntry(const Material& m, const StorageLayout& layout, const Syntax& syn);

/// The packing function `<name>_pack(closures, dither, words, topLayer)`,
/// static bit offsets following `layout` (appended to the material file);
/// with `dynamicSimplification`, a pixel where one plain closure is left is
/// packed in the SIMPLE layout instead (storage/layout.h, runtimeSimpleClosures).
std::string emitPackFunction(const Material& m, const StorageLayout& layout, const Syntax& syn,
                             bool dynamicSimplification = true);

/// A volume's entry (isVolumeMaterial; it has no forward or base pass): the
/// froxel pass, a compute shader that samples the medium at the centre of
/// every froxel of a grid and stores its payload (docs/codegen.md, "Volumes").
/// Set 0: binding 0 the grid (SubstrateVolumeGrid: origin, cell size, counts),
/// binding 1 the froxels (uint words, `<NAME>_WORD_COUNT` a froxel, x fastest,
/// then y, then z). Dispatched as ceil(n.x n.y / kVolumeLocalSize) x n.z groups:
/// a row of groups a slice.
std::string emitVolumeEntry(const Material& m, const StorageLayout& layout, const Syntax& syn);
inline constexpr int kVolumeLocalSize = 64;  // invocations a group, one froxel each

/// File names: `<name>.forward.frag` / `<name>.forward.ps.hlsl`, ...
std::string forwardFileName(const Material& m, const Syntax& syn);
std::string basePassFileName(const Material& m, const Syntax& syn);
std::string volumeFileName(const Material& m, const Syntax& syn);  // `<name>.volume.comp` / `.volume.cs.hlsl`

}  // namespace substratec
