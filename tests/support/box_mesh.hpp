#pragma once
// An axis-aligned box appended to a mesh: 8 shared corners, 12 triangles.
// The room and block scenes the studio's render and ui tests build by hand.
#include "culling/scene/scene.hpp"

#include <glm/glm.hpp>

#include <cstdint>

namespace lctest {

inline void addBox(lc::Mesh& m, glm::vec3 lo, glm::vec3 hi) {
    const auto base = std::uint32_t(m.vertexCount());
    for (int i = 0; i < 8; ++i) {
        m.positions.push_back((i & 1) ? hi.x : lo.x);
        m.positions.push_back((i & 2) ? hi.y : lo.y);
        m.positions.push_back((i & 4) ? hi.z : lo.z);
    }
    const std::uint32_t faces[12][3] = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                                        {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
    for (const auto& f : faces)
        for (std::uint32_t v : f) m.indices.push_back(base + v);
}

} // namespace lctest
