// Overlay geometry (tile frustums, depth cells, light cell ranges, reverse
// look-up, per-tile heat) and the overlays.vtm writer. See overlays.hpp.
//
// The VTK XML is written by hand (culling/ must not link VTK): ASCII
// DataArrays, Float64 points written as the shortest text that reads back as
// the same double, so a reader gets exactly the corners the culling used.
#include "culling/overlays.hpp"

#include "culling/errors.hpp"
#include "culling/file_io.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cstring>
#include <deque>
#include <filesystem>
#include <limits>

#include <fcntl.h>
#include <unistd.h>

namespace lc {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool tileHasGeometry(const CullResult& r, std::uint32_t t) {
    return t < r.tileDepthMin.size() && t < r.tileDepthMax.size() && r.tileDepthMin[t] <= r.tileDepthMax[t];
}

} // namespace

glm::dmat4 worldFromView(const Camera& camera) { return glm::inverse(camera.viewFromWorld()); }

double cameraFarDepth(const Projection& proj, const ViewLights& lights, SpotTest spotTest) {
    if (std::isfinite(proj.farPlane())) return proj.farPlane();
    double lightFar = 0.0;
    for (std::size_t l = 0; l < lights.size(); ++l) {
        const BoundingSphere b = lights.cullSphere(l, spotTest);
        lightFar = std::max(lightFar, -b.center.z + b.radius);
    }
    return std::max(lightFar, proj.nearPlane());
}

std::pair<std::uint32_t, std::uint32_t> tileLists(const CullResult& r, std::uint32_t tile) {
    if (r.algorithm == Algorithm::All) return {0u, r.listCount.empty() ? 0u : 1u};
    const std::uint32_t per = std::max(r.listsPerTile, 1u);
    return {tile * per, per};
}

std::optional<FrustumChunk> tileFrustum(const CullResult& r, const Projection& proj,
                                        const ViewLights& lights, std::uint32_t tile) {
    if (tile >= r.grid.tileCount()) return std::nullopt;
    const auto rect = r.grid.tileRect(tile % r.grid.tilesX, tile / r.grid.tilesX);
    if (r.algorithm == Algorithm::Naive || r.algorithm == Algorithm::All || r.algorithm == Algorithm::ZBin)
        return makeFrustumChunk(proj, rect, proj.nearPlane(), cameraFarDepth(proj, lights, r.settings.spotTest));
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
    switch (r.algorithm) {
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
    switch (r.algorithm) {
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
    const std::uint32_t per = std::max(r.listsPerTile, 1u);
    for (std::uint32_t l : lists)
        if (out.empty() || out.back() != l / per) out.push_back(l / per);
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
    auto [first, count] = tileLists(r, tile);
    const bool perCellLists = r.algorithm == Algorithm::HalfZ || r.algorithm == Algorithm::Clustered;
    if (cell >= 0 && perCellLists) {
        if (std::uint32_t(cell) >= count) return rows;
        first += std::uint32_t(cell);
        count = 1;
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
        const auto needed = pixelsNeedingLights(masked, proj, run.lights, r.grid, tile);
        std::vector<std::uint32_t> neededCount(run.lights.size(), 0);
        for (const auto& [light, n] : needed) neededCount[light] = n;
        std::vector<char> listed(run.lights.size(), 0);
        for (std::uint32_t k = 0; k < r.listCount[l]; ++k) {
            const std::uint32_t light = r.lightIndices[r.listOffset[l] + k];
            if (light >= run.lights.size()) continue;
            listed[light] = 1;
            rows.push_back({l, light, neededCount[light], neededCount[light] ? Verdict::Needed : Verdict::FalsePositive});
        }
        for (const auto& [light, n] : needed)
            if (!listed[light]) rows.push_back({l, light, n, Verdict::Missing});
    }
    return rows;
}

const char* toString(HeatMode m) {
    switch (m) {
    case HeatMode::ListLength: return "list-length";
    case HeatMode::FalsePositives: return "false-positives";
    case HeatMode::Efficiency: return "efficiency";
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
        const auto [first, count] = tileLists(r, t);
        if (mode == HeatMode::ListLength) {
            std::uint32_t m = 0;
            for (std::uint32_t l = first; l < first + count && l < r.listCount.size(); ++l)
                m = std::max(m, r.listCount[l]);
            heat[t] = m;
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

std::string num(double v) {
    std::array<char, 64> buf{};
    const auto res = std::to_chars(buf.data(), buf.data() + buf.size(), v);
    return std::string(buf.data(), res.ptr);
}

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
};

void appendValues(std::string& out, const std::vector<double>& v, bool integer) {
    for (std::size_t i = 0; i < v.size(); ++i) {
        out += (i % 12 == 0) ? "\n          " : " ";
        out += integer ? std::to_string(std::int64_t(v[i])) : num(v[i]);
    }
    out += "\n        ";
}

void appendInts(std::string& out, const char* name, const std::vector<std::int64_t>& v) {
    out += "        <DataArray type=\"Int64\" Name=\"";
    out += name;
    out += "\" format=\"ascii\">";
    for (std::size_t i = 0; i < v.size(); ++i) {
        out += (i % 16 == 0) ? "\n          " : " ";
        out += std::to_string(v[i]);
    }
    out += "\n        </DataArray>\n";
}

void appendArrays(std::string& out, const char* section, const std::deque<PolyPiece::Array>& arrays) {
    out += "      <";
    out += section;
    out += ">\n";
    for (const auto& a : arrays) {
        out += "        <DataArray type=\"" + a.type + "\" Name=\"" + a.name + "\" format=\"ascii\">";
        appendValues(out, a.values, a.type != "Float64");
        out += "</DataArray>\n";
    }
    out += "      </";
    out += section;
    out += ">\n";
}

std::string polyDataXml(const PolyPiece& p) {
    std::string out;
    out.reserve(64 * p.points.size() + 16 * (p.polyConn.size() + p.lineConn.size()) + 1024);
    out += "<?xml version=\"1.0\"?>\n"
           "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
           "  <PolyData>\n";
    out += "    <Piece NumberOfPoints=\"" + std::to_string(p.points.size()) + "\" NumberOfVerts=\"" +
           std::to_string(p.vertOff.size()) + "\" NumberOfLines=\"" + std::to_string(p.lineOff.size()) +
           "\" NumberOfStrips=\"0\" NumberOfPolys=\"" + std::to_string(p.polyOff.size()) + "\">\n";
    appendArrays(out, "PointData", p.pointData);
    appendArrays(out, "CellData", p.cellData);
    out += "      <Points>\n        <DataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\" "
           "format=\"ascii\">";
    std::vector<double> xyz;
    xyz.reserve(3 * p.points.size());
    for (const auto& q : p.points) xyz.insert(xyz.end(), {q.x, q.y, q.z});
    appendValues(out, xyz, false);
    out += "</DataArray>\n      </Points>\n";
    auto cells = [&](const char* tag, const std::vector<std::int64_t>& conn, const std::vector<std::int64_t>& off) {
        out += "      <";
        out += tag;
        out += ">\n";
        appendInts(out, "connectivity", conn);
        appendInts(out, "offsets", off);
        out += "      </";
        out += tag;
        out += ">\n";
    };
    cells("Verts", p.vertConn, p.vertOff);
    cells("Lines", p.lineConn, p.lineOff);
    cells("Strips", {}, {});
    cells("Polys", p.polyConn, p.polyOff);
    out += "    </Piece>\n  </PolyData>\n</VTKFile>\n";
    return out;
}

// The six faces of a chunk as quads (corners: near tl,tr,br,bl; far tl,tr,br,bl).
void addChunk(PolyPiece& p, const FrustumChunk& c, const glm::dmat4& worldFromViewM) {
    std::int64_t id[8];
    for (int i = 0; i < 8; ++i) id[i] = p.addPoint(glm::dvec3(worldFromViewM * glm::dvec4(c.corners[i], 1.0)));
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
        const double farD = cameraFarDepth(proj, run.lights, run.result.settings.spotTest);
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
        auto& aTile = tileFr.cellArray("tile", "Int64");
        auto& aTx = tileFr.cellArray("tile_x", "Int64");
        auto& aTy = tileFr.cellArray("tile_y", "Int64");
        auto& aCount = tileFr.cellArray("count", "Int64");
        auto& aMax = tileFr.cellArray("max_list", "Int64");
        auto& aFp = tileFr.cellArray("false_positives", "Float64");
        auto& aEff = tileFr.cellArray("efficiency", "Float64");
        for (std::uint32_t t = 0; t < tiles; ++t) {
            const auto chunk = tileFrustum(r, proj, run.lights, t);
            if (!chunk) continue;
            addChunk(tileFr, *chunk, w);
            const auto [first, count] = tileLists(r, t);
            std::uint64_t entries = 0;
            std::uint32_t longest = 0;
            for (std::uint32_t l = first; l < first + count && l < r.listCount.size(); ++l) {
                entries += r.listCount[l];
                longest = std::max(longest, r.listCount[l]);
            }
            for (int f = 0; f < 6; ++f) {
                aTile.values.push_back(t);
                aTx.values.push_back(t % r.grid.tilesX);
                aTy.values.push_back(t / r.grid.tilesX);
                aCount.values.push_back(double(entries));
                aMax.values.push_back(longest);
                aFp.values.push_back(fp[t]);
                aEff.values.push_back(eff[t]);
            }
        }
    }

    // Depth cells (2.5d cells, halfz halves, clustered froxels).
    PolyPiece cellsPiece;
    {
        std::size_t total = 0;
        for (std::uint32_t t = 0; t < tiles; ++t) {
            if (r.algorithm == Algorithm::Clustered) total += r.listsPerTile;
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
