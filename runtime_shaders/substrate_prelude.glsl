// substratec runtime shaders: GLSL prelude of the common dialect.
// The runtime library (substrate_*.h) is written once in a small dialect with
// HLSL spellings; this file maps it to GLSL 4.50 (Vulkan). Include it first.
#ifndef SUBSTRATE_PRELUDE
#define SUBSTRATE_PRELUDE 1
#define SUBSTRATE_GLSL 1

#define float2 vec2
#define float3 vec3
#define float4 vec4
#define int2 ivec2
#define int3 ivec3
#define int4 ivec4
#define uint2 uvec2
#define uint3 uvec3
#define uint4 uvec4
#define bool2 bvec2
#define bool3 bvec3
#define float3x3 mat3

#define lerp mix
#define frac fract
#define rsqrt inversesqrt
#define atan2 atan
#define ddx dFdx
#define ddy dFdy
#define asuint floatBitsToUint
#define asfloat uintBitsToFloat
#define saturate(x) clamp((x), 0.0, 1.0)
#define rcp(x) (1.0 / (x))

// Constants at file scope, and splats of a scalar to a vector.
#define SUBSTRATE_CONST const
#define SUBSTRATE_SPLAT2(x) vec2(x)
#define SUBSTRATE_SPLAT3(x) vec3(x)
#define SUBSTRATE_SPLAT4(x) vec4(x)
// float <-> half bits (low 16 bits).
#define substrate_f32tof16(v_) (packHalf2x16(vec2((v_), 0.0)) & 0xffffu)
#define substrate_f16tof32(h_) (unpackHalf2x16(uint(h_)).x)
// A constant array: SUBSTRATE_CONST float NAME[4] = SUBSTRATE_ARRAY_BEGIN(float, 4) a, b, c, d SUBSTRATE_ARRAY_END;
#define SUBSTRATE_ARRAY_BEGIN(T, N) T[N](
#define SUBSTRATE_ARRAY_END )
// Textures (the sampler argument is for HLSL: a GLSL texture carries its own)
// and storage images: words in layers of an array, or a colour at a pixel.
#define SUBSTRATE_TEXTURE_SAMPLE(t, s, uv) texture(t, uv)
#define SUBSTRATE_TEXTURE_SAMPLE_LEVEL(t, s, uv, lod) textureLod(t, uv, lod)
#define SUBSTRATE_TEXTURE_SAMPLE_GRAD(t, s, uv, dx, dy) textureGrad(t, uv, dx, dy)
#define SUBSTRATE_IMAGE_LOAD_LAYER(img, p, layer) imageLoad(img, ivec3(int((p).x), int((p).y), int(layer))).x
#define SUBSTRATE_IMAGE_STORE_LAYER(img, p, layer, v) imageStore(img, ivec3(int((p).x), int((p).y), int(layer)), uvec4((v), 0u, 0u, 0u))
#define SUBSTRATE_IMAGE_STORE(img, p, v) imageStore(img, ivec2(int((p).x), int((p).y)), v)
// Compute: group-shared memory, its barrier and atomics (HLSL spellings).
#define groupshared shared
#define GroupMemoryBarrierWithGroupSync() memoryBarrierShared(); barrier()
#define InterlockedMax(dest, value) atomicMax(dest, value)
#define InterlockedAdd(dest, value, original) (original) = atomicAdd(dest, value)

// Medium precision (docs/stability.md, "Half precision"): the runtime keeps
// colours, albedos, Fresnel, energy weights and throughputs in mfloat types,
// float unless the includer defines SUBSTRATE_PRECISION_HALF 1 before this
// file (float16_t then: the device needs shaderFloat16). Conversions are
// explicit (SUBSTRATE_M*: to mfloat, SUBSTRATE_F*: back to float) and vanish
// in float, so the float32 SPIR-V is the same as without this block.
#ifndef SUBSTRATE_PRECISION_HALF
#define SUBSTRATE_PRECISION_HALF 0
#endif
#if SUBSTRATE_PRECISION_HALF
#extension GL_EXT_shader_explicit_arithmetic_types_float16 : require
#define mfloat float16_t
#define mfloat3 f16vec3
#define SUBSTRATE_M(x) float16_t(x)
#define SUBSTRATE_M3(x) f16vec3(x)
#define SUBSTRATE_F(x) float(x)
#define SUBSTRATE_F3(x) vec3(x)
// A float of any magnitude to mfloat: clamped to half's finite range (+-65504)
// first, where the conversion would give +-inf.
#define SUBSTRATE_M_CLAMPED(x) float16_t(clamp((x), -65504.0, 65504.0))
#define msaturate(x) clamp((x), float16_t(0.0), float16_t(1.0))
#else
#define mfloat float
#define mfloat3 vec3
#define SUBSTRATE_M(x) (x)
#define SUBSTRATE_M3(x) (x)
#define SUBSTRATE_F(x) (x)
#define SUBSTRATE_F3(x) (x)
#define SUBSTRATE_M_CLAMPED(x) (x)
#define msaturate saturate
#endif
#define mlerp mix
#define SUBSTRATE_MSPLAT3(x) mfloat3(x)

#endif
