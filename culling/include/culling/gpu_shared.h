// Declarations shared, as text, by C++ and GLSL 450.
//
// GLSL includes this file through glslang's #include (GL_GOOGLE_include_directive);
// C++ includes it through projection.hpp. Keep to the common subset of both
// languages: plain structs of scalars and vec4/uvec4, and functions over them.
// Every struct the GPU reads is declared here once, and C++ checks its size and
// offsets with static_assert (std140/std430 rules: vec4-aligned members).
#ifndef LC_GPU_SHARED_H
#define LC_GPU_SHARED_H

#ifdef __cplusplus
#include <glm/glm.hpp>
#include <cstdint>
#include <cstddef>
namespace lc {
using vec4 = glm::vec4;
using uvec4 = glm::uvec4;
using uint = std::uint32_t;
#define LC_INLINE inline
#else
#define LC_INLINE
#endif

// Linearisation of window depth for every projection kind.
//   perspective kinds: d = A + B / viewDepth   =>  viewDepth = B / (d - A)
//   orthographic kinds: d = A + B * viewDepth  =>  viewDepth = (d - A) / B
// (x, y) = (A, B); z = 1 for orthographic, 0 for perspective; w = clear depth.
struct DepthParams {
    vec4 ab_ortho_clear;
};

// The one depth-linearising formula, written once for both languages. C++
// evaluates it in double through projection.cpp's double overload below.
LC_INLINE float lcViewDepthFromWindowDepth(float d, vec4 p) {
    return (p.z > 0.5f) ? (d - p.x) / p.y : p.y / (d - p.x);
}

#ifdef __cplusplus
inline double lcViewDepthFromWindowDepthD(double d, double a, double b, bool ortho) {
    return ortho ? (d - a) / b : b / (d - a);
}
static_assert(sizeof(DepthParams) == 16, "DepthParams must match std140/std430 layout");
} // namespace lc
#endif

#endif
