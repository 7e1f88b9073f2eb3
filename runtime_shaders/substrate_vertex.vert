// The vertex stage of the generated base and forward passes (GLSL): what
// `substratec render` draws them with, and what an engine's vertex shader must
// hand them. Outputs, locations 0-5, are the fragment entries' inputs
// (emit/entry_emitter.cc): world position, unit normal, tangent (xyz, w the
// bitangent's sign, glTF's convention), uv0, uv1, vertex colour.
//
// Vertex inputs are in world space already (the host applies each node's
// transform); set 2, binding 0 holds the view-projection matrix as four row
// vectors, so clip = (dot(row0, p), dot(row1, p), dot(row2, p), dot(row3, p))
// in both languages (no matrix type: the runtime's dialect has none).
// Vulkan clip space: y down, depth 0 (near) to 1 (far).
#version 450

layout(set = 2, binding = 0, std140) uniform SubstrateView {
  vec4 viewProjection[4];  // rows
} view;

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec4 inTangent;
layout(location = 3) in vec2 inUv0;
layout(location = 4) in vec2 inUv1;
layout(location = 5) in vec4 inColor;

layout(location = 0) out vec3 outWorldPosition;
layout(location = 1) out vec3 outNormal;
layout(location = 2) out vec4 outTangent;
layout(location = 3) out vec2 outUv0;
layout(location = 4) out vec2 outUv1;
layout(location = 5) out vec4 outColor;

// A depth pre-pass and the base pass draw the same triangles with this shader
// and test depth for equality: the position must come out bit-identical. It
// does (the same SPIR-V on the same inputs; `render`'s tests check that the
// deferred path covers exactly the pixels the forward path does), without
// `invariant gl_Position`: glslang decorates the gl_PerVertex member, which
// the validation layer's SPIR-V checks warn about.

void main() {
  const vec4 p = vec4(inPosition, 1.0);
  gl_Position = vec4(dot(view.viewProjection[0], p), dot(view.viewProjection[1], p),
                     dot(view.viewProjection[2], p), dot(view.viewProjection[3], p));
  outWorldPosition = inPosition;
  outNormal = inNormal;
  outTangent = inTangent;
  outUv0 = inUv0;
  outUv1 = inUv1;
  outColor = inColor;
}
