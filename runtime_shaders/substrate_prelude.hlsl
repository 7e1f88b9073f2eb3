// substratec runtime shaders: HLSL prelude of the common dialect (the dialect
// uses HLSL spellings, so this file mostly adds the few shared macros).
// Include it first. Compiled by glslang's HLSL front end (and DXC-compatible).
#ifndef SUBSTRATE_PRELUDE
#define SUBSTRATE_PRELUDE 1
#define SUBSTRATE_HLSL 1

#define SUBSTRATE_CONST static const
#define SUBSTRATE_SPLAT2(x) ((float2)(x))
#define SUBSTRATE_SPLAT3(x) ((float3)(x))
#define SUBSTRATE_SPLAT4(x) ((float4)(x))
#define substrate_f32tof16(x) (f32tof16(x) & 0xffffu)
#define substrate_f16tof32(x) f16tof32(uint(x))
#define SUBSTRATE_ARRAY_BEGIN(T, N) {
#define SUBSTRATE_ARRAY_END }

#endif
