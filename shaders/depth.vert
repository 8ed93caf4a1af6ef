#version 450
// Depth pre-pass: model-space positions straight to Vulkan clip space.
// clipFromModel = Projection::clipFromView() * viewFromWorld * mesh transform,
// composed in double on the host, so y already points down and z/w is window
// depth in [0,1] for every projection kind (reversed-Z included).
layout(location = 0) in vec3 inPosition; // model space
layout(push_constant) uniform Push { mat4 clipFromModel; } pc;
void main() { gl_Position = pc.clipFromModel * vec4(inPosition, 1.0); }
