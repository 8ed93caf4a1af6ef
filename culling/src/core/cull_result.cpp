// CullResult helpers: size in bytes, the per-pixel list lookup, consistency check.
#include "culling/core/cull_result.hpp"

#include "culling/core/backend.hpp"
#include "culling/core/depth.hpp"
#include "culling/core/errors.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace lc {

// See cull_result.hpp: the lists as a renderer stores them. halfz's far list
// starts where its near list ends (both backends lay lists out in list
// order), so its offset is implied and the 4 bytes go to the split.
long ListLimits::overflowIndex(std::uint32_t list) const {
    const auto it = std::lower_bound(overflowLists.begin(), overflowLists.end(), list);
    return it != overflowLists.end() && *it == list ? long(it - overflowLists.begin()) : -1;
}

std::pair<const std::uint32_t*, const std::uint32_t*> ListLimits::droppedFrom(std::uint32_t list) const {
    const long k = overflowIndex(list);
    if (k < 0) return {nullptr, nullptr};
    const std::uint32_t* base = droppedLights.data();
    return {base + droppedOffset[std::size_t(k)], base + droppedOffset[std::size_t(k) + 1]};
}

bool ListLimits::dropped(std::uint32_t list, std::uint32_t light) const {
    const auto [a, b] = droppedFrom(list);
    return a != b && std::binary_search(a, b, light);
}

std::uint64_t CullResult::bytes() const {
    if (algorithm == Algorithm::ZBin)
        return 4 * std::uint64_t(zbinLo.size()) +
               4 * std::uint64_t(grid.tileCount()) * ((std::uint64_t(zbinRank.size()) + 31) / 32);
    const std::uint64_t lists = listCount.size();
    std::uint64_t b = 4 * entries() + 8 * lists;
    if (settings.maxEntries) b = 4 * std::uint64_t(settings.maxEntries) + 8 * lists;
    else if (settings.cap) b = 4 * (std::uint64_t(settings.cap) + 1) * lists;
    if (settings.clusterLists()) b += 8; // clusterNear, clusterFar as float
    return b;
}

std::uint64_t CullResult::diagnosticBytes() const {
    return 8 * std::uint64_t(tileDepthMin.size()) + 4 * std::uint64_t(cellMask.size());
}

// The lookup every shading pass (and the ground truth) uses: the pixel's tile,
// then for halfz the side of the split, for clustered the depth slice over
// [clusterNear, clusterFar].
std::uint32_t CullResult::zbinOf(double viewDepth) const {
    const std::size_t bins = zbinLo.size();
    if (bins == 0 || !(zbinFar > zbinNear)) return 0;
    const double t = (viewDepth - zbinNear) / (zbinFar - zbinNear) * double(bins);
    if (!(t > 0)) return 0; // also NaN
    return std::uint32_t(std::min(t, double(bins - 1)));
}

std::uint32_t CullResult::listOfPixel(std::uint32_t px, std::uint32_t py, double viewDepth) const {
    if (!pixelList.empty()) return pixelList[std::size_t(py) * grid.width + px];
    if (algorithm == Algorithm::All) return 0;
    const std::uint32_t tile = grid.tileOfPixel(px, py);
    switch (algorithm) {
    case Algorithm::HalfZ: return tile * 2 + (viewDepth <= halfzSplit[tile] ? 0u : 1u);
    case Algorithm::Raster:
        if (!settings.proxySlices) return tile;
        [[fallthrough]];
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

std::vector<SliceLocator> cellSlices(const CullResult& r, std::uint32_t cells) {
    std::vector<SliceLocator> slices;
    if (r.settings.clusterLists()) {
        slices.emplace_back(r.settings.slicing, r.clusterNear, r.clusterFar, cells);
    } else if (r.algorithm == Algorithm::TwoPointFiveD) {
        slices.reserve(r.tileDepthMin.size());
        for (std::size_t t = 0; t < r.tileDepthMin.size(); ++t)
            slices.emplace_back(r.settings.slicing, r.tileDepthMin[t], r.tileDepthMax[t], cells);
    }
    return slices;
}

PixelListLookup::PixelListLookup(const CullResult& result) : r_(result) {
    // 2.5d without cell lists has one list per tile: listOfPixel's own rule.
    if (r_.pixelList.empty() && (r_.settings.clusterLists() || r_.cellLists))
        slices_ = cellSlices(r_, r_.listsPerTile);
}

std::uint32_t PixelListLookup::operator()(std::uint32_t px, std::uint32_t py, double viewDepth) const {
    if (slices_.empty()) return r_.listOfPixel(px, py, viewDepth);
    const std::uint32_t tile = r_.grid.tileOfPixel(px, py);
    const SliceLocator& slice = r_.settings.clusterLists() ? slices_[0] : slices_[tile];
    return tile * r_.listsPerTile + slice(viewDepth);
}

std::pair<std::uint32_t, std::uint32_t> CullResult::tileLists(std::uint32_t tile) const {
    if (algorithm == Algorithm::All) return {0u, listCount.empty() ? 0u : 1u};
    const std::uint32_t per = std::max(listsPerTile, 1u);
    return {tile * per, per};
}

std::uint32_t CullResult::listOf(std::uint32_t tile, int sub) const {
    if (algorithm == Algorithm::All) return 0;
    if (tile >= grid.tileCount())
        throw SettingsError("tile", std::to_string(tile) + " is outside the " + std::to_string(grid.tilesX) + "x" +
                                        std::to_string(grid.tilesY) + " tiles");
    const std::uint32_t per = std::max(listsPerTile, 1u);
    if (sub < 0) {
        if (per > 1)
            throw SettingsError("cell", std::string(toString(algorithm)) + " has " + std::to_string(per) +
                                            " lists per tile: give the cell (0.." + std::to_string(per - 1) + ")");
        return tile;
    }
    if (std::uint32_t(sub) >= per)
        throw SettingsError("cell", std::to_string(sub) + " is outside 0.." + std::to_string(per - 1));
    return tile * per + std::uint32_t(sub);
}

std::uint32_t CullResult::tileOfList(std::uint32_t list) const {
    return algorithm == Algorithm::All ? 0 : list / std::max(listsPerTile, 1u);
}

int CullResult::cellOfList(std::uint32_t list) const {
    return algorithm == Algorithm::All || listsPerTile <= 1 ? -1 : int(list % listsPerTile);
}

std::string CullResult::validate(std::size_t lightCount) const {
    const std::uint64_t tiles = grid.tileCount();
    const std::uint32_t expectPerTile = listsPerTileOf(settings, cellLists);
    if (algorithm != Algorithm::All && listsPerTile != expectPerTile)
        return "listsPerTile is " + std::to_string(listsPerTile) + ", expected " +
               std::to_string(expectPerTile);
    const std::uint64_t lists = algorithm == Algorithm::All ? 1 : tiles * listsPerTile;
    if (algorithm == Algorithm::ZBin && pixelList.empty()) {
        const std::size_t n = lightCount;
        if (zbinOrder.size() != n || zbinRank.size() != n) return "zbin order/rank hold the wrong number of lights";
        for (std::size_t k = 0; k < n; ++k)
            if (zbinOrder[k] >= n || zbinRank[zbinOrder[k]] != k) return "zbin order and rank are not inverse";
        if (zbinLo.size() != settings.bins || zbinHi.size() != settings.bins) return "zbin bins size mismatch";
        for (std::size_t b = 0; b < zbinLo.size(); ++b)
            if (zbinLo[b] <= zbinHi[b] && zbinHi[b] >= n) return "zbin bin " + std::to_string(b) + " out of range";
    }
    if (!pixelList.empty()) {
        // Per-pixel lists (zbinPixelLists): any number, each pixel names one.
        if (pixelList.size() != std::size_t(grid.width) * grid.height) return "pixelList size mismatch";
        for (std::uint32_t l : pixelList)
            if (l != 0xffffffffu && l >= listCount.size()) return "pixelList names a list out of range";
    } else if (listOffset.size() != lists || listCount.size() != lists)
        return "list arrays hold " + std::to_string(listOffset.size()) + "/" +
               std::to_string(listCount.size()) + " entries, expected " + std::to_string(lists);
    if (tileDepthMin.size() != tiles || tileDepthMax.size() != tiles)
        return "tile depth bounds hold " + std::to_string(tileDepthMin.size()) + " entries, expected " +
               std::to_string(tiles);
    if (algorithm == Algorithm::HalfZ && halfzSplit.size() != tiles) return "halfzSplit size mismatch";
    if ((algorithm == Algorithm::TwoPointFiveD || settings.clusterLists()) && cellMask.size() != tiles)
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
    const ListLimits& lim = limits;
    if (!lim.overLightLimit.empty() && lim.overLightLimit.size() != lightCount)
        return "limits: the light-limit flags hold " + std::to_string(lim.overLightLimit.size()) + " lights, expected " +
               std::to_string(lightCount);
    if (!lim.overflowLists.empty() && lim.droppedOffset.size() != lim.overflowLists.size() + 1)
        return "limits: dropped offsets do not match the over-full lists";
    for (std::size_t k = 0; k < lim.overflowLists.size(); ++k) {
        if (lim.overflowLists[k] >= listCount.size() || (k && lim.overflowLists[k] <= lim.overflowLists[k - 1]))
            return "limits: over-full list ids are out of range or not ascending";
        if (lim.droppedOffset[k] > lim.droppedOffset[k + 1] || lim.droppedOffset[k + 1] > lim.droppedLights.size())
            return "limits: dropped offsets run past the dropped lights";
    }
    for (std::uint32_t light : lim.droppedLights)
        if (light >= lightCount) return "limits: a dropped light is out of range";
    return {};
}

void zbinSortLights(const std::vector<double>& centreDepth, std::vector<std::uint32_t>& order,
                    std::vector<std::uint32_t>& rank) {
    order.resize(centreDepth.size());
    std::iota(order.begin(), order.end(), 0u);
    std::stable_sort(order.begin(), order.end(),
                     [&](std::uint32_t a, std::uint32_t b) { return centreDepth[a] < centreDepth[b]; });
    rank.resize(order.size());
    for (std::uint32_t k = 0; k < order.size(); ++k) rank[order[k]] = k;
}

CullResult zbinPixelLists(const CullResult& z, const DepthImage& depth, const Projection& proj) {
    if (z.algorithm != Algorithm::ZBin || !z.pixelList.empty()) return z;
    if (depth.width != z.grid.width || depth.height != z.grid.height)
        throw Error("zbin: depth image does not match the cull result's grid");
    CullResult m;
    m.algorithm = Algorithm::ZBin;
    m.settings = z.settings;
    m.grid = z.grid;
    m.listsPerTile = 1;
    m.tileDepthMin = z.tileDepthMin;
    m.tileDepthMax = z.tileDepthMax;
    m.zbinOrder = z.zbinOrder;
    m.zbinRank = z.zbinRank;
    m.zbinLo = z.zbinLo;
    m.zbinHi = z.zbinHi;
    m.zbinNear = z.zbinNear;
    m.zbinFar = z.zbinFar;
    m.backend = z.backend;
    m.device = z.device;
    m.pixelList.assign(std::size_t(depth.width) * depth.height, 0xffffffffu);
    // Per tile, the (bin, list) pairs made so far: a tile's pixels span few bins.
    std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> made(z.grid.tileCount());
    for (std::uint32_t y = 0; y < depth.height; ++y)
        for (std::uint32_t x = 0; x < depth.width; ++x) {
            if (!depth.hasGeometry(x, y)) continue;
            const std::uint32_t t = z.grid.tileOfPixel(x, y), b = z.zbinOf(proj.viewDepthFromWindowDepth(depth.at(x, y)));
            std::uint32_t list = 0xffffffffu;
            for (const auto& [bin, l] : made[t])
                if (bin == b) list = l;
            if (list == 0xffffffffu) {
                list = std::uint32_t(m.listCount.size());
                made[t].emplace_back(b, list);
                m.listOffset.push_back(std::uint32_t(m.lightIndices.size()));
                const std::uint32_t lo = z.zbinLo[b], hi = z.zbinHi[b];
                std::uint32_t count = 0;
                for (std::uint32_t k = 0; k < z.listCount[t]; ++k) {
                    const std::uint32_t light = z.lightIndices[z.listOffset[t] + k];
                    if (lo <= z.zbinRank[light] && z.zbinRank[light] <= hi) {
                        m.lightIndices.push_back(light);
                        ++count;
                    }
                }
                m.listCount.push_back(count);
                // What the limits dropped from the tile's mask, in this bin.
                if (const auto [a, e] = z.limits.droppedFrom(t); z.limits.overflowIndex(t) >= 0) {
                    m.limits.overflowLists.push_back(list);
                    m.limits.droppedOffset.push_back(std::uint32_t(m.limits.droppedLights.size()));
                    for (const std::uint32_t* d = a; d != e; ++d)
                        if (lo <= z.zbinRank[*d] && z.zbinRank[*d] <= hi) m.limits.droppedLights.push_back(*d);
                }
            }
            m.pixelList[std::size_t(y) * depth.width + x] = list;
        }
    if (!m.limits.overflowLists.empty()) m.limits.droppedOffset.push_back(std::uint32_t(m.limits.droppedLights.size()));
    m.limits.overLightLimit = z.limits.overLightLimit;
    m.limits.lightsOverLimit = z.limits.lightsOverLimit;
    m.limits.longestUncapped = z.limits.longestUncapped;
    m.limits.entriesUncapped = z.limits.entriesUncapped;
    return m;
}

} // namespace lc
