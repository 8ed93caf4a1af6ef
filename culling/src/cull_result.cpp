// CullResult helpers: size in bytes, the per-pixel list lookup, consistency check.
#include "culling/cull_result.hpp"

namespace lc {

// See cull_result.hpp: the lists as a renderer stores them. halfz's far list
// starts where its near list ends (both backends lay lists out in list
// order), so its offset is implied and the 4 bytes go to the split.
std::uint64_t CullResult::bytes() const {
    std::uint64_t b = 4 * entries() + 8 * std::uint64_t(listCount.size());
    if (algorithm == Algorithm::Clustered) b += 8; // clusterNear, clusterFar as float
    return b;
}

std::uint64_t CullResult::diagnosticBytes() const {
    return 8 * std::uint64_t(tileDepthMin.size()) + 4 * std::uint64_t(cellMask.size());
}

// The lookup every shading pass (and the ground truth) uses: the pixel's tile,
// then for halfz the side of the split, for clustered the depth slice over
// [clusterNear, clusterFar].
std::uint32_t CullResult::listOfPixel(std::uint32_t px, std::uint32_t py, double viewDepth) const {
    if (algorithm == Algorithm::All) return 0;
    const std::uint32_t tile = grid.tileOfPixel(px, py);
    switch (algorithm) {
    case Algorithm::HalfZ: return tile * 2 + (viewDepth <= halfzSplit[tile] ? 0u : 1u);
    case Algorithm::Clustered:
        return tile * listsPerTile +
               sliceOfDepth(settings.slicing, clusterNear, clusterFar, listsPerTile, viewDepth);
    case Algorithm::TwoPointFiveD:
        if (!cellLists) return tile;
        return tile * listsPerTile +
               sliceOfDepth(settings.slicing, tileDepthMin[tile], tileDepthMax[tile], listsPerTile, viewDepth);
    default: return tile;
    }
}

std::string CullResult::validate(std::size_t lightCount) const {
    const std::uint64_t tiles = grid.tileCount();
    std::uint32_t expectPerTile = 1;
    if (algorithm == Algorithm::HalfZ) expectPerTile = 2;
    if (algorithm == Algorithm::Clustered) expectPerTile = settings.cells;
    if (algorithm == Algorithm::TwoPointFiveD && cellLists) expectPerTile = settings.cells;
    if (algorithm != Algorithm::All && listsPerTile != expectPerTile)
        return "listsPerTile is " + std::to_string(listsPerTile) + ", expected " +
               std::to_string(expectPerTile);
    const std::uint64_t lists = algorithm == Algorithm::All ? 1 : tiles * listsPerTile;
    if (listOffset.size() != lists || listCount.size() != lists)
        return "list arrays hold " + std::to_string(listOffset.size()) + "/" +
               std::to_string(listCount.size()) + " entries, expected " + std::to_string(lists);
    if (tileDepthMin.size() != tiles || tileDepthMax.size() != tiles)
        return "tile depth bounds hold " + std::to_string(tileDepthMin.size()) + " entries, expected " +
               std::to_string(tiles);
    if (algorithm == Algorithm::HalfZ && halfzSplit.size() != tiles) return "halfzSplit size mismatch";
    if ((algorithm == Algorithm::TwoPointFiveD || algorithm == Algorithm::Clustered) &&
        cellMask.size() != tiles)
        return "cellMask size mismatch";
    std::uint64_t total = 0;
    for (std::size_t l = 0; l < listOffset.size(); ++l) {
        const std::uint64_t o = listOffset[l], c = listCount[l];
        if (o + c > lightIndices.size())
            return "list " + std::to_string(l) + " runs past the index array";
        total += c;
        for (std::uint64_t i = o; i < o + c; ++i) {
            if (lightIndices[i] >= lightCount)
                return "list " + std::to_string(l) + " holds light " +
                       std::to_string(lightIndices[i]) + " of " + std::to_string(lightCount);
            if (i > o && lightIndices[i] <= lightIndices[i - 1])
                return "list " + std::to_string(l) + " is not strictly ascending";
        }
    }
    if (total != lightIndices.size()) return "index array is not compact";
    return {};
}

} // namespace lc
