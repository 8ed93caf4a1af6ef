#pragma once
// A cull result's lists as vectors, for tests to compare.

#include "culling/core/cull_result.hpp"

#include <cstdint>
#include <vector>

namespace lc::test {

// List l's light indices, in the result's order.
inline std::vector<std::uint32_t> listAt(const CullResult& r, std::size_t l) {
    return {r.lightIndices.begin() + r.listOffset[l], r.lightIndices.begin() + r.listOffset[l] + r.listCount[l]};
}

// The lights the engine limits dropped from list l.
inline std::vector<std::uint32_t> droppedAt(const CullResult& r, std::uint32_t l) {
    const auto [a, b] = r.limits.droppedFrom(l);
    return a ? std::vector<std::uint32_t>(a, b) : std::vector<std::uint32_t>{};
}

} // namespace lc::test
