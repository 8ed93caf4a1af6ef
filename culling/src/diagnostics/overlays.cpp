// Overlay geometry (tile frustums, depth cells, light cell ranges, reverse
// look-up, per-tile heat) and the overlays.vtm writer. See overlays.hpp.
//
// The VTK XML is written by hand (culling/ must not link VTK): binary
// appended DataArrays, zlib-compressed (AppendedData below), Float64 points,
// so a reader gets exactly the corners the culling used.
#include "culling/diagnostics/overlays.hpp"

#include "culling/core/errors.hpp"
#include "culling/core/file_io.hpp"
#include "truth/light_grid.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <deque>
#include <filesystem>
#include <limits>
#include <unordered_map>

#include <fcntl.h>
#include <zlib.h>
#include <unistd.h>

namespace lc {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool tileHasGeometry(const CullResult& r, std::uint32_t t) {
    return t < r.tileDepthMin.size() && t < r.tileDepthMax.size() && r.tileDepthMin[t] <= r.tileDepthMax[t];
}

} // namespace

glm::dmat4 worldFromView(const Camera& camera) { return glm::inverse(camera.viewFromWorld()); }

std::optional<FrustumChunk> tileFrustum(const CullResult& r, const Projection& proj,
                                        const ViewLights& lights, std::uint32_t tile) {
    if (tile >= r.grid.tileCount()) return std::nullopt;
    const auto rect = r.grid.tileRect(tile % r.grid.tilesX, tile / r.grid.tilesX);
    if (r.algorithm == Algorithm::Naive || r.algorithm == Algorithm::All || r.algorithm == Algorithm::ZBin)
        return makeFrustumChunk(proj, rect, r.cameraNear, r.cameraFar); // the range its masks were culled over
    if (!tileHasGeometry(r, tile)) return std::nullopt;
    return makeFrustumChunk(proj, rect, r.tileDepthMin[tile], r.tileDepthMax[tile]);
}

namespace {

// zbin: the view depth where bin b starts (b == bins: the far end).
double zbinBoundary(const CullResult& r, std::uint32_t b) {
    return r.zbinNear + (r.zbinFar - r.zbinNear) * double(b) / double(std::max<std::size_t>(r.zbinLo.size(), 1));
}

// zbin: the bins of a tile's depth range in at most 32 groups of
// consecutive bins: [first, last] of group g.
struct BinGroups {
    std::uint32_t b0 = 0, count = 0, groups = 0;
    std::uint32_t first(std::uint32_t g) const { return b0 + std::uint32_t(std::uint64_t(g) * count / groups); }
    std::uint32_t last(std::uint32_t g) const { return first(g + 1) - 1; }
};
BinGroups zbinGroups(const CullResult& r, std::uint32_t tile) {
    BinGroups g;
    if (r.zbinLo.empty() || !tileHasGeometry(r, tile)) return g;
    g.b0 = r.zbinOf(r.tileDepthMin[tile]);
    g.count = r.zbinOf(r.tileDepthMax[tile]) - g.b0 + 1;
    g.groups = std::min(g.count, 32u);
    return g;
}

} // namespace

std::optional<FrustumChunk> zbinLightSlab(const CullResult& r, const Projection& proj, const ViewLights& lights,
                                          std::uint32_t light) {
    if (r.algorithm != Algorithm::ZBin || r.zbinLo.empty() || light >= lights.size()) return std::nullopt;
    const BoundingSphere s = lights.cullSphere(light, r.settings.spotTest);
    const double a = -s.center.z - s.radius, b = -s.center.z + s.radius;
    if (b < r.zbinNear || a > r.zbinFar) return std::nullopt;
    const TileGrid::Rect screen{0, 0, r.grid.width, r.grid.height};
    return makeFrustumChunk(proj, screen, zbinBoundary(r, r.zbinOf(a)), zbinBoundary(r, r.zbinOf(b) + 1));
}

std::vector<DepthCell> tileCells(const CullResult& r, const Projection& proj, std::uint32_t tile) {
    std::vector<DepthCell> cells;
    if (tile >= r.grid.tileCount()) return cells;
    const auto rect = r.grid.tileRect(tile % r.grid.tilesX, tile / r.grid.tilesX);
    const Slicing s = r.settings.slicing;
    const std::uint32_t mask = tile < r.cellMask.size() ? r.cellMask[tile] : 0u;
    switch (r.layout()) {
    case Algorithm::TwoPointFiveD: {
        if (!tileHasGeometry(r, tile)) break;
        const double lo = r.tileDepthMin[tile], hi = r.tileDepthMax[tile];
        const std::uint32_t n = r.settings.cells;
        for (std::uint32_t k = 0; k < n; ++k) {
            DepthCell c;
            c.cell = k;
            c.list = r.cellLists ? tile * n + k : tile;
            c.occupied = (mask >> k) & 1u;
            c.chunk = makeFrustumChunk(proj, rect, sliceBoundary(s, lo, hi, n, k), sliceBoundary(s, lo, hi, n, k + 1));
            cells.push_back(c);
        }
        break;
    }
    case Algorithm::HalfZ: {
        if (!tileHasGeometry(r, tile) || tile >= r.halfzSplit.size()) break;
        const double lo = r.tileDepthMin[tile], hi = r.tileDepthMax[tile], split = r.halfzSplit[tile];
        cells.push_back({0, 2 * tile, true, makeFrustumChunk(proj, rect, lo, split)});
        cells.push_back({1, 2 * tile + 1, true, makeFrustumChunk(proj, rect, split, hi)});
        break;
    }
    case Algorithm::ZBin: {
        const BinGroups g = zbinGroups(r, tile);
        for (std::uint32_t k = 0; k < g.groups; ++k)
            cells.push_back({k, tile, true,
                             makeFrustumChunk(proj, rect, zbinBoundary(r, g.first(k)), zbinBoundary(r, g.last(k) + 1))});
        break;
    }
    case Algorithm::Clustered: {
        const std::uint32_t n = r.listsPerTile;
        for (std::uint32_t k = 0; k < n; ++k) {
            DepthCell c;
            c.cell = k;
            c.list = tile * n + k;
            c.occupied = (mask >> k) & 1u;
            c.chunk = makeFrustumChunk(proj, rect, sliceBoundary(s, r.clusterNear, r.clusterFar, n, k),
                                       sliceBoundary(s, r.clusterNear, r.clusterFar, n, k + 1));
            cells.push_back(c);
        }
        break;
    }
    default: break;
    }
    return cells;
}

std::uint32_t lightCellRange(const CullResult& r, std::uint32_t tile, const glm::dvec3& centerView,
                             double radius) {
    if (tile >= r.grid.tileCount()) return 0;
    const double a = -centerView.z - radius, b = -centerView.z + radius;
    switch (r.layout()) {
    case Algorithm::TwoPointFiveD:
        if (!tileHasGeometry(r, tile)) return 0;
        return sliceRangeMask(r.settings.slicing, r.tileDepthMin[tile], r.tileDepthMax[tile], r.settings.cells, a, b);
    case Algorithm::Clustered:
        return sliceRangeMask(r.settings.slicing, r.clusterNear, r.clusterFar, r.listsPerTile, a, b);
    case Algorithm::ZBin: {
        const BinGroups g = zbinGroups(r, tile);
        if (g.groups == 0 || b < r.zbinNear || a > r.zbinFar) return 0;
        const std::uint32_t la = r.zbinOf(a), lb = r.zbinOf(b);
        std::uint32_t m = 0;
        for (std::uint32_t k = 0; k < g.groups; ++k)
            if (la <= g.last(k) && lb >= g.first(k)) m |= 1u << k;
        return m;
    }
    case Algorithm::HalfZ: {
        if (!tileHasGeometry(r, tile) || tile >= r.halfzSplit.size()) return 0;
        const double lo = r.tileDepthMin[tile], hi = r.tileDepthMax[tile], split = r.halfzSplit[tile];
        std::uint32_t m = 0;
        if (a <= split && b >= lo) m |= 1u;
        if (b >= split && a <= hi) m |= 2u;
        return m;
    }
    default: return 0;
    }
}

std::vector<std::uint32_t> listsHoldingLight(const CullResult& r, std::uint32_t light) {
    std::vector<std::uint32_t> out;
    for (std::uint32_t l = 0; l < r.listCount.size(); ++l) {
        const auto first = r.lightIndices.begin() + r.listOffset[l];
        if (std::binary_search(first, first + r.listCount[l], light)) out.push_back(l);
    }
    return out;
}

std::vector<std::uint32_t> tilesHoldingLight(const CullResult& r, std::uint32_t light) {
    std::vector<std::uint32_t> out;
    const std::vector<std::uint32_t> lists = listsHoldingLight(r, light);
    if (r.algorithm == Algorithm::All) {
        if (!lists.empty())
            for (std::uint32_t t = 0; t < r.grid.tileCount(); ++t) out.push_back(t);
        return out;
    }
    for (std::uint32_t l : lists)
        if (out.empty() || out.back() != r.tileOfList(l)) out.push_back(r.tileOfList(l));
    return out;
}

std::optional<SpotTestPrimitive> spotTestPrimitive(const RunOutput& run, const Projection& proj,
                                                   std::uint32_t light, int tile) {
    const CullResult& r = run.result;
    if (light >= run.lights.size() || !run.lights.isSpot(light)) return std::nullopt;
    SpotTestPrimitive p;
    p.test = r.settings.spotTest;
    p.cone = run.lights.spotCone(light);
    p.cullSphere = run.lights.cullSphere(light, p.test);
    if (tile < 0 || std::uint32_t(tile) >= r.grid.tileCount() || r.algorithm == Algorithm::All) return p;
    const auto t = std::uint32_t(tile);
    auto add = [&](std::uint32_t list, std::uint32_t cell, const FrustumChunk& chunk) {
        SpotTestChunk c;
        c.list = list;
        c.cell = cell;
        c.chunk = chunk;
        c.sphere = chunkBoundingSphere(chunk);
        c.passed = spotIntersectsChunk(p.test, r.settings.test, p.cone, chunk);
        p.chunks.push_back(c);
    };
    switch (r.algorithm) {
    case Algorithm::Naive:
    case Algorithm::MinMax:
    case Algorithm::Fptl:
    case Algorithm::TwoPointFiveD:
        if (const auto chunk = tileFrustum(r, proj, run.lights, t)) add(t, 0, *chunk);
        break;
    case Algorithm::HalfZ:
        for (const DepthCell& c : tileCells(r, proj, t)) add(c.list, c.cell, c.chunk);
        break;
    case Algorithm::Clustered: {
        const std::uint32_t range = lightCellRange(r, t, p.cullSphere.center, p.cullSphere.radius);
        for (const DepthCell& c : tileCells(r, proj, t))
            if (((range >> c.cell) & 1u) && (c.occupied || !r.settings.skipEmpty)) add(c.list, c.cell, c.chunk);
        break;
    }
    default: break;
    }
    return p;
}

const char* toString(Verdict v) {
    switch (v) {
    case Verdict::Needed: return "needed";
    case Verdict::FalsePositive: return "false positive";
    case Verdict::Missing: return "MISSING";
    }
    return "?";
}

// The ground truth's containment rule is used through pixelsNeedingLights on a
// copy of the depth image in which only the pixels of one list (and cell) of
// the tile keep their depth: one copy, and per list only the tile's pixels are
// rewritten.
std::vector<TileLightRow> tileLightRows(const RunOutput& run, const Projection& proj, std::uint32_t tile,
                                        int cell) {
    std::vector<TileLightRow> rows;
    const CullResult& r = run.result;
    const DepthImage& depth = run.depth;
    if (tile >= r.grid.tileCount() || depth.width != r.grid.width || depth.height != r.grid.height) return rows;
    auto [first, count] = r.tileLists(tile);
    const bool perCellLists = r.algorithm == Algorithm::HalfZ || r.layout() == Algorithm::Clustered;
    if (cell >= 0 && perCellLists) {
        if (std::uint32_t(cell) >= count) return rows;
        first += std::uint32_t(cell);
        count = 1;
    }
    // List l's rows from per-light counts of its pixels that need each light:
    // its lights first (needed or false positive), then the missing ones.
    auto appendRows = [&](std::uint32_t l, const std::vector<std::uint32_t>& neededCount) {
        std::vector<char> listed(run.lights.size(), 0);
        for (std::uint32_t k = 0; k < r.listCount[l]; ++k) {
            const std::uint32_t light = r.lightIndices[r.listOffset[l] + k];
            if (light >= run.lights.size()) continue;
            listed[light] = 1;
            rows.push_back({l, light, neededCount[light], neededCount[light] ? Verdict::Needed : Verdict::FalsePositive});
        }
        for (std::uint32_t i = 0; i < neededCount.size(); ++i)
            if (neededCount[i] && !listed[i]) rows.push_back({l, i, neededCount[i], Verdict::Missing});
    };
    if (r.algorithm == Algorithm::All) {
        // `all`'s one list serves every pixel of the image: a light is needed
        // when some pixel of the image needs it (as Explain judges it), not
        // only a pixel of the tile clicked.
        std::vector<glm::dvec3> points;
        const double inf = std::numeric_limits<double>::infinity();
        glm::dvec3 lo(inf), hi(-inf);
        for (std::uint32_t y = 0; y < depth.height; ++y)
            for (std::uint32_t x = 0; x < depth.width; ++x) {
                if (!depth.hasGeometry(x, y)) continue;
                const glm::dvec3 p = proj.viewPositionFromDepth(x, y, depth.at(x, y));
                if (!std::isfinite(p.x + p.y + p.z)) continue;
                points.push_back(p);
                lo = glm::min(lo, p), hi = glm::max(hi, p);
            }
        std::vector<std::uint32_t> neededCount(run.lights.size(), 0);
        if (!points.empty()) {
            const detail::LightGrid lightGrid(run.lights, lo, hi);
            for (const glm::dvec3& p : points) lightGrid.forEachContaining(p, [&](std::uint32_t i) { ++neededCount[i]; });
        }
        appendRows(first, neededCount);
        return rows;
    }
    const auto rect = r.grid.tileRect(tile % r.grid.tilesX, tile / r.grid.tilesX);
    const bool cellFilter = cell >= 0 && r.algorithm == Algorithm::TwoPointFiveD && tileHasGeometry(r, tile);
    DepthImage masked = depth;
    for (std::uint32_t l = first; l < first + count && l < r.listCount.size(); ++l) {
        for (std::uint32_t y = rect.y0; y < rect.y1; ++y)
            for (std::uint32_t x = rect.x0; x < rect.x1; ++x) {
                float& d = masked.depth[std::size_t(y) * depth.width + x];
                d = depth.clearDepth;
                if (!depth.hasGeometry(x, y)) continue;
                const double v = proj.viewDepthFromWindowDepth(depth.at(x, y));
                if (!std::isfinite(v)) continue;
                if (r.listOfPixel(x, y, v) != l) continue;
                if (cellFilter && sliceOfDepth(r.settings.slicing, r.tileDepthMin[tile], r.tileDepthMax[tile],
                                               r.settings.cells, v) != std::uint32_t(cell))
                    continue;
                d = depth.at(x, y);
            }
        std::vector<std::uint32_t> neededCount(run.lights.size(), 0);
        for (const auto& [light, n] : pixelsNeedingLights(masked, proj, run.lights, r.grid, tile)) neededCount[light] = n;
        appendRows(l, neededCount);
    }
    return rows;
}

const char* toString(HeatMode m) {
    switch (m) {
    case HeatMode::ListLength: return "list-length";
    case HeatMode::FalsePositives: return "false-positives";
    case HeatMode::Efficiency: return "efficiency";
    case HeatMode::FalseNegatives: return "false-negatives";
    case HeatMode::Overflow: return "overflow";
    }
    return "?";
}

std::vector<double> tileHeat(const RunOutput& run, HeatMode mode) {
    const CullResult& r = run.result;
    const GroundTruth& gt = run.truth;
    const std::uint32_t tiles = r.grid.tileCount();
    std::vector<double> heat(tiles, kNaN);
    for (std::uint32_t t = 0; t < tiles; ++t) {
        if (!tileHasGeometry(r, t)) continue;
        const auto [first, count] = r.tileLists(t);
        if (mode == HeatMode::ListLength) {
            std::uint32_t m = 0;
            for (std::uint32_t l = first; l < first + count && l < r.listCount.size(); ++l)
                m = std::max(m, r.listCount[l]);
            heat[t] = m;
            continue;
        }
        if (mode == HeatMode::Overflow) {
            bool over = false;
            std::uint64_t dropped = 0;
            for (std::uint32_t l = first; l < first + count; ++l) {
                const auto [a, b] = r.limits.droppedFrom(l);
                over = over || r.limits.overflowIndex(l) >= 0;
                dropped += std::uint64_t(b - a);
            }
            if (over) heat[t] = double(dropped);
            continue;
        }
        if (mode == HeatMode::FalseNegatives) {
            if (r.algorithm == Algorithm::All) {
                heat[t] = 0; // one list of every light misses none
                continue;
            }
            if (gt.listFalseNegatives.size() < std::size_t(first) + count) continue; // no ground truth
            std::uint64_t fn = 0;
            for (std::uint32_t l = first; l < first + count; ++l) fn += gt.listFalseNegatives[l];
            heat[t] = double(fn);
            continue;
        }
        if (r.algorithm == Algorithm::All) continue;
        std::uint64_t w = 0, e = 0;
        for (std::uint32_t l = first; l < first + count; ++l) {
            if (l < gt.listShadingWork.size()) w += gt.listShadingWork[l];
            if (l < gt.listExactWork.size()) e += gt.listExactWork[l];
        }
        if (gt.listShadingWork.size() < std::size_t(first) + count) continue; // no ground truth
        heat[t] = mode == HeatMode::FalsePositives ? double(w - std::min(w, e)) : w ? double(e) / double(w) : 1.0;
    }
    return heat;
}

// ---- overlays.vtm -----------------------------------------------------------

namespace {

namespace fs = std::filesystem;

// One vtkPolyData piece: points, then verts, lines and polys (VTK's cell
// order, which cell data follows).
struct PolyPiece {
    struct Array {
        std::string name, type; // VTK XML type: Float64, Int64, UInt8
        std::vector<double> values;
    };
    std::vector<glm::dvec3> points;
    std::vector<std::int64_t> vertConn, vertOff, lineConn, lineOff, polyConn, polyOff;
    std::deque<Array> pointData, cellData; // deque: references stay valid as arrays are added

    std::int64_t addPoint(const glm::dvec3& p) {
        points.push_back(p);
        return std::int64_t(points.size()) - 1;
    }
    // A point that faces of neighbouring boxes share (a cell's far corners
    // are the next cell's near ones): stored once, by its exact bits.
    std::int64_t addSharedPoint(const glm::dvec3& p) {
        std::array<std::uint64_t, 3> key{};
        std::memcpy(key.data(), &p.x, 8);
        std::memcpy(key.data() + 1, &p.y, 8);
        std::memcpy(key.data() + 2, &p.z, 8);
        const auto [it, fresh] = shared_.try_emplace(key, std::int64_t(points.size()));
        if (fresh) points.push_back(p);
        return it->second;
    }
    void addVert(std::int64_t a) {
        vertConn.push_back(a);
        vertOff.push_back(std::int64_t(vertConn.size()));
    }
    void addLine(std::int64_t a, std::int64_t b) {
        lineConn.insert(lineConn.end(), {a, b});
        lineOff.push_back(std::int64_t(lineConn.size()));
    }
    void addQuad(std::int64_t a, std::int64_t b, std::int64_t c, std::int64_t d) {
        polyConn.insert(polyConn.end(), {a, b, c, d});
        polyOff.push_back(std::int64_t(polyConn.size()));
    }
    Array& cellArray(const std::string& name, const std::string& type) {
        for (auto& a : cellData)
            if (a.name == name) return a;
        cellData.push_back({name, type, {}});
        return cellData.back();
    }
    Array& pointArray(const std::string& name, const std::string& type) {
        for (auto& a : pointData)
            if (a.name == name) return a;
        pointData.push_back({name, type, {}});
        return pointData.back();
    }

private:
    struct KeyHash {
        std::size_t operator()(const std::array<std::uint64_t, 3>& k) const {
            std::uint64_t h = 1469598103934665603ull;
            for (std::uint64_t w : k) h = (h ^ w) * 1099511628211ull;
            return std::size_t(h ^ (h >> 29));
        }
    };
    std::unordered_map<std::array<std::uint64_t, 3>, std::int64_t, KeyHash> shared_;
};

// The pieces' arrays as VTK XML "appended" binary data, each array zlib
// compressed the way vtkZLibDataCompressor writes it (VTK's XML readers and
// ParaView read it): a UInt64 header [blocks, block size, size of the last
// partial block or 0, compressed size of each block], then the blocks. An
// ASCII file of a 1080p run was nearly all digits, about ten times larger.
class AppendedData {
public:
    // Adds an array's bytes; returns the DataArray element that refers to them.
    std::string array(const std::string& type, const std::string& name, const void* data, std::size_t bytes,
                       int components = 1) {
        std::string el = "<DataArray type=\"" + type + "\" Name=\"" + name + "\"";
        if (components > 1) el += " NumberOfComponents=\"" + std::to_string(components) + "\"";
        el += " format=\"appended\" offset=\"" + std::to_string(data_.size()) + "\"/>\n";
        const auto* in = static_cast<const Bytef*>(data);
        const std::uint64_t blocks = (bytes + kBlock - 1) / kBlock;
        std::vector<std::uint64_t> header = {blocks, kBlock, bytes % kBlock};
        std::string packed;
        for (std::uint64_t b = 0; b < blocks; ++b) {
            const std::size_t n = std::size_t(std::min<std::uint64_t>(kBlock, bytes - b * kBlock));
            uLongf size = compressBound(uLong(n));
            std::string block(size, '\0');
            if (compress2(reinterpret_cast<Bytef*>(block.data()), &size, in + b * kBlock, uLong(n), kLevel) != Z_OK)
                throw Error("cannot compress the overlay array '" + name + "'");
            packed.append(block.data(), size);
            header.push_back(size);
        }
        data_.append(reinterpret_cast<const char*>(header.data()), header.size() * 8);
        data_ += packed;
        return el;
    }
    // As Float64, UInt8 or (type Int64) integers per `type`.
    std::string values(const std::string& type, const std::string& name, const std::vector<double>& v) {
        if (type == "Float64") return array(type, name, v.data(), v.size() * 8);
        if (type == "UInt8") {
            std::vector<std::uint8_t> u(v.begin(), v.end());
            return array(type, name, u.data(), u.size());
        }
        std::vector<std::int64_t> i(v.size());
        for (std::size_t k = 0; k < v.size(); ++k) i[k] = std::int64_t(v[k]);
        return integers(name, i);
    }
    // Int32 where every value fits (half the bytes before compression), else Int64.
    std::string integers(const std::string& name, const std::vector<std::int64_t>& v) {
        const bool fits = std::all_of(v.begin(), v.end(), [](std::int64_t x) {
            return x >= std::numeric_limits<std::int32_t>::min() && x <= std::numeric_limits<std::int32_t>::max();
        });
        if (!fits) return array("Int64", name, v.data(), v.size() * 8);
        const std::vector<std::int32_t> narrow(v.begin(), v.end());
        return array("Int32", name, narrow.data(), narrow.size() * 4);
    }
    const std::string& bytes() const { return data_; }

private:
    static constexpr std::uint64_t kBlock = 1u << 16;
    static constexpr int kLevel = 6; // zlib's default: a 1080p export in well under a second here
    std::string data_;
};

std::string polyDataXml(const PolyPiece& p) {
    static_assert(std::endian::native == std::endian::little, "the files say byte_order=LittleEndian");
    AppendedData app;
    std::string out;
    out += "<?xml version=\"1.0\"?>\n"
           "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\" "
           "compressor=\"vtkZLibDataCompressor\">\n"
           "  <PolyData>\n";
    out += "    <Piece NumberOfPoints=\"" + std::to_string(p.points.size()) + "\" NumberOfVerts=\"" +
           std::to_string(p.vertOff.size()) + "\" NumberOfLines=\"" + std::to_string(p.lineOff.size()) +
           "\" NumberOfStrips=\"0\" NumberOfPolys=\"" + std::to_string(p.polyOff.size()) + "\">\n";
    for (const auto& [section, arrays] : {std::pair<const char*, const std::deque<PolyPiece::Array>*>{"PointData", &p.pointData},
                                          {"CellData", &p.cellData}}) {
        out += std::string("      <") + section + ">\n";
        for (const auto& a : *arrays) out += "        " + app.values(a.type, a.name, a.values);
        out += std::string("      </") + section + ">\n";
    }
    static_assert(sizeof(glm::dvec3) == 24, "points are written as packed xyz doubles");
    out += "      <Points>\n        " + app.array("Float64", "Points", p.points.data(), p.points.size() * 24, 3) +
           "      </Points>\n";
    auto cells = [&](const char* tag, const std::vector<std::int64_t>& conn, const std::vector<std::int64_t>& off) {
        out += std::string("      <") + tag + ">\n";
        out += "        " + app.integers("connectivity", conn);
        out += "        " + app.integers("offsets", off);
        out += std::string("      </") + tag + ">\n";
    };
    cells("Verts", p.vertConn, p.vertOff);
    cells("Lines", p.lineConn, p.lineOff);
    cells("Strips", {}, {});
    cells("Polys", p.polyConn, p.polyOff);
    out += "    </Piece>\n  </PolyData>\n  <AppendedData encoding=\"raw\">\n   _";
    out += app.bytes();
    out += "\n  </AppendedData>\n</VTKFile>\n";
    return out;
}

// The six faces of a chunk as quads (corners: near tl,tr,br,bl; far tl,tr,br,bl).
void addChunk(PolyPiece& p, const FrustumChunk& c, const glm::dmat4& worldFromViewM) {
    std::int64_t id[8];
    for (int i = 0; i < 8; ++i)
        id[i] = p.addSharedPoint(glm::dvec3(worldFromViewM * glm::dvec4(c.corners[i], 1.0)));
    p.addQuad(id[0], id[1], id[2], id[3]); // near
    p.addQuad(id[4], id[7], id[6], id[5]); // far
    p.addQuad(id[0], id[3], id[7], id[4]); // left
    p.addQuad(id[1], id[5], id[6], id[2]); // right
    p.addQuad(id[0], id[4], id[5], id[1]); // top
    p.addQuad(id[3], id[2], id[6], id[7]); // bottom
}


} // namespace

void writeOverlaysVtm(const Scene& scene, const RunOutput& run, const std::string& dir,
                      const OverlayExportOptions& options) {
    const CullResult& r = run.result;
    const Camera& cam = scene.camera;
    if (r.grid.width != cam.width || r.grid.height != cam.height || r.grid.tileSize != cam.tileSize)
        throw Error("cannot write overlays: the run's tile grid (" + std::to_string(r.grid.width) + "x" +
                    std::to_string(r.grid.height) + ", tile " + std::to_string(r.grid.tileSize) +
                    ") does not match the scene's camera; run culling again");
    if (std::string e = cam.validate(); !e.empty()) throw SettingsError("camera", e);
    const Projection proj(cam);
    const glm::dmat4 w = worldFromView(cam);
    const std::uint32_t tiles = r.grid.tileCount();

    // Culling camera frustum: near and far faces, side edges, and (perspective)
    // the edges to the eye.
    PolyPiece camera;
    {
        const double farD = run.result.cameraFar; // an infinite far: the reach naive's masks used
        const glm::dvec2 px[4] = {{0, 0}, {double(cam.width), 0}, {double(cam.width), double(cam.height)},
                                  {0, double(cam.height)}};
        for (double d : {proj.nearPlane(), farD})
            for (const auto& p : px) camera.addPoint(glm::dvec3(w * glm::dvec4(proj.viewPositionAt(p, d), 1.0)));
        camera.addPoint(cam.position);
        for (int i = 0; i < 4; ++i) {
            camera.addLine(i, (i + 1) % 4);
            camera.addLine(4 + i, 4 + (i + 1) % 4);
            camera.addLine(i, 4 + i);
            if (!proj.orthographic()) camera.addLine(8, i);
        }
    }

    // Tile frustums with per-tile figures as cell data (repeated on the 6 faces).
    PolyPiece tileFr;
    {
        const auto fp = tileHeat(run, HeatMode::FalsePositives);
        const auto eff = tileHeat(run, HeatMode::Efficiency);
        const auto fn = tileHeat(run, HeatMode::FalseNegatives);
        auto& aTile = tileFr.cellArray("tile", "Int64");
        auto& aTx = tileFr.cellArray("tile_x", "Int64");
        auto& aTy = tileFr.cellArray("tile_y", "Int64");
        auto& aCount = tileFr.cellArray("count", "Int64");
        auto& aMax = tileFr.cellArray("max_list", "Int64");
        auto& aFp = tileFr.cellArray("false_positives", "Float64");
        auto& aEff = tileFr.cellArray("efficiency", "Float64");
        auto& aFn = tileFr.cellArray("false_negatives", "Float64");
        for (std::uint32_t t = 0; t < tiles; ++t) {
            const auto chunk = tileFrustum(r, proj, run.lights, t);
            if (!chunk) continue;
            addChunk(tileFr, *chunk, w);
            const auto [first, count] = r.tileLists(t);
            std::uint64_t entries = 0;
            std::uint32_t longest = 0;
            for (std::uint32_t l = first; l < first + count && l < r.listCount.size(); ++l) {
                entries += r.listCount[l];
                longest = std::max(longest, r.listCount[l]);
            }
            // A tile without geometry (drawn for naive) shades nothing:
            // W_t = E_t = 0, no false positive, efficiency 1 (the heat map's
            // NaN there means "not tinted", which a threshold in ParaView
            // would trip on).
            const bool empty = !tileHasGeometry(r, t) && r.algorithm != Algorithm::All;
            for (int f = 0; f < 6; ++f) {
                aTile.values.push_back(t);
                aTx.values.push_back(t % r.grid.tilesX);
                aTy.values.push_back(t / r.grid.tilesX);
                aCount.values.push_back(double(entries));
                aMax.values.push_back(longest);
                aFp.values.push_back(empty ? 0.0 : fp[t]);
                aEff.values.push_back(empty ? 1.0 : eff[t]);
                aFn.values.push_back(empty ? 0.0 : fn[t]);
            }
        }
    }

    // Depth cells (2.5d cells, halfz halves, clustered froxels).
    PolyPiece cellsPiece;
    {
        std::size_t total = 0;
        for (std::uint32_t t = 0; t < tiles; ++t) {
            if (r.layout() == Algorithm::Clustered) total += r.listsPerTile;
            else if (r.algorithm == Algorithm::TwoPointFiveD && tileHasGeometry(r, t)) total += r.settings.cells;
            else if (r.algorithm == Algorithm::HalfZ && tileHasGeometry(r, t)) total += 2;
        }
        const bool occupiedOnly = total > options.maxAllCells;
        auto& aTile = cellsPiece.cellArray("tile", "Int64");
        auto& aCell = cellsPiece.cellArray("cell", "Int64");
        auto& aList = cellsPiece.cellArray("list", "Int64");
        auto& aOcc = cellsPiece.cellArray("occupied", "UInt8");
        auto& aCount = cellsPiece.cellArray("count", "Int64");
        for (std::uint32_t t = 0; t < tiles && total > 0; ++t)
            for (const DepthCell& c : tileCells(r, proj, t)) {
                if (occupiedOnly && !c.occupied) continue;
                addChunk(cellsPiece, c.chunk, w);
                for (int f = 0; f < 6; ++f) {
                    aTile.values.push_back(t);
                    aCell.values.push_back(c.cell);
                    aList.values.push_back(c.list);
                    aOcc.values.push_back(c.occupied ? 1 : 0);
                    aCount.values.push_back(c.list < r.listCount.size() ? r.listCount[c.list] : 0);
                }
            }
    }

    // Light spheres: one vertex per light at its centre (world), index and radius.
    PolyPiece spheres;
    {
        auto& aIndex = spheres.pointArray("index", "Int64");
        auto& aRadius = spheres.pointArray("radius", "Float64");
        for (std::size_t l = 0; l < run.lights.size(); ++l) {
            spheres.addVert(spheres.addPoint(glm::dvec3(w * glm::dvec4(run.lights.centers[l], 1.0))));
            aIndex.values.push_back(double(l));
            aRadius.values.push_back(run.lights.radii[l]);
        }
    }

    const fs::path root(dir);
    const fs::path sub = root / "overlays";
    std::error_code ec;
    fs::create_directory(sub, ec);
    if (ec) throw Error("cannot create " + sub.string() + ": " + ec.message());
    const std::pair<const char*, const PolyPiece*> pieces[] = {{"camera_frustum", &camera},
                                                               {"tile_frustums", &tileFr},
                                                               {"depth_cells", &cellsPiece},
                                                               {"light_spheres", &spheres}};
    std::string vtm = "<?xml version=\"1.0\"?>\n"
                      "<VTKFile type=\"vtkMultiBlockDataSet\" version=\"1.0\" byte_order=\"LittleEndian\" "
                      "header_type=\"UInt64\">\n  <vtkMultiBlockDataSet>\n";
    int index = 0;
    for (const auto& [name, piece] : pieces) {
        writeFileSynced((sub / (std::string(name) + ".vtp")).string(), polyDataXml(*piece));
        vtm += "    <DataSet index=\"" + std::to_string(index++) + "\" name=\"" + name + "\" file=\"overlays/" +
               name + ".vtp\"/>\n";
    }
    vtm += "  </vtkMultiBlockDataSet>\n</VTKFile>\n";
    syncFolder(sub.string());
    writeFileSynced((root / "overlays.vtm").string(), vtm);
}

} // namespace lc
