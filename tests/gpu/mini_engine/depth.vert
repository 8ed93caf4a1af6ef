// The mini engine's depth pre-pass: world-space positions through its own
// frame constants (row-major, as many engines upload them).
#version 450
layout(set = 0, binding = 0, row_major, std140) uniform FrameConstants {
    mat4 view;
    mat4 proj;
    uvec4 screen; // width, height, tile size, light count
} frame;
layout(location = 0) in vec3 position;
void main() { gl_Position = frame.proj * frame.view * vec4(position, 1.0); }
