// The vertex stage of the generated base and forward passes (HLSL): the twin
// of substrate_vertex.vert, which documents the contract. Outputs at
// locations 0-5 match the fragment entries' PSInput.

struct SubstrateView {
  float4 viewProjection[4];  // rows
};
[[vk::binding(0, 2)]] ConstantBuffer<SubstrateView> view;

struct VSInput {
  [[vk::location(0)]] float3 position : POSITION0;
  [[vk::location(1)]] float3 normal : NORMAL0;
  [[vk::location(2)]] float4 tangent : TANGENT0;
  [[vk::location(3)]] float2 uv0 : TEXCOORD0;
  [[vk::location(4)]] float2 uv1 : TEXCOORD1;
  [[vk::location(5)]] float4 color : COLOR0;
};

struct VSOutput {
  float4 position : SV_Position;  // bit-identical in a depth pre-pass and the base pass (the .vert says why)
  [[vk::location(0)]] float3 worldPosition : POSITION0;
  [[vk::location(1)]] float3 normal : NORMAL0;
  [[vk::location(2)]] float4 tangent : TANGENT0;
  [[vk::location(3)]] float2 uv0 : TEXCOORD0;
  [[vk::location(4)]] float2 uv1 : TEXCOORD1;
  [[vk::location(5)]] float4 color : COLOR0;
};

VSOutput main(VSInput i) {
  VSOutput o;
  const float4 p = float4(i.position, 1.0);
  o.position = float4(dot(view.viewProjection[0], p), dot(view.viewProjection[1], p),
                      dot(view.viewProjection[2], p), dot(view.viewProjection[3], p));
  o.worldPosition = i.position;
  o.normal = i.normal;
  o.tangent = i.tangent;
  o.uv0 = i.uv0;
  o.uv1 = i.uv1;
  o.color = i.color;
  return o;
}
