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
// Textures and storage images (see substrate_prelude.glsl).
#define SUBSTRATE_TEXTURE_SAMPLE(t, s, uv) t.Sample(s, uv)
#define SUBSTRATE_TEXTURE_SAMPLE_LEVEL(t, s, uv, lod) t.SampleLevel(s, uv, lod)
#define SUBSTRATE_TEXTURE_SAMPLE_GRAD(t, s, uv, dx, dy) t.SampleGrad(s, uv, dx, dy)
#define SUBSTRATE_IMAGE_LOAD_LAYER(img, p, layer) img[uint3((p).x, (p).y, layer)]
#define SUBSTRATE_IMAGE_STORE_LAYER(img, p, layer, v) img[uint3((p).x, (p).y, layer)] = (v)
#define SUBSTRATE_IMAGE_STORE(img, p, v) img[(p)] = (v)

// Medium precision: see substrate_prelude.glsl. With SUBSTRATE_PRECISION_HALF
// the shader must be compiled with native 16-bit types (DXC
// -enable-16bit-types; glslang --hlsl-enable-16bit-types, i.e.
// EShMsgHlslEnable16BitTypes), or `half` is a 32-bit float.
#ifndef SUBSTRATE_PRECISION_HALF
#define SUBSTRATE_PRECISION_HALF 0
#endif
#if SUBSTRATE_PRECISION_HALF
#define mfloat half
#define mfloat3 half3
#define SUBSTRATE_M(x) ((half)(x))
#define SUBSTRATE_M3(x) ((half3)(x))
#define SUBSTRATE_F(x) ((float)(x))
#define SUBSTRATE_F3(x) ((float3)(x))
#define SUBSTRATE_M_CLAMPED(x) ((half)clamp((x), -65504.0, 65504.0))
// glslang's HLSL front end (12.0) has no half overloads of the intrinsics: they
// compute in float and return float. The two the runtime applies to mfloat
// values are written with operators (saturate maps NaN to 0, as HLSL's does).
half msaturate(half x) { return x > 0.0h ? (x < 1.0h ? x : 1.0h) : 0.0h; }
half3 msaturate(half3 v) { return half3(msaturate(v.x), msaturate(v.y), msaturate(v.z)); }
half mlerp(half a, half b, half t) { return a + (b - a) * t; }
half3 mlerp(half3 a, half3 b, half t) { return a + (b - a) * t; }
#else
#define mfloat float
#define mfloat3 float3
#define SUBSTRATE_M(x) (x)
#define SUBSTRATE_M3(x) (x)
#define SUBSTRATE_F(x) (x)
#define SUBSTRATE_F3(x) (x)
#define SUBSTRATE_M_CLAMPED(x) (x)
#define msaturate saturate
#define mlerp lerp
#endif
#define SUBSTRATE_MSPLAT3(x) ((mfloat3)(x))

#endif
