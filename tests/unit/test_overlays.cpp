// Overlay geometry against the culling it explains: a tile frustum's corners
// lie on the planes the culling used, cell boundaries follow the slicing
// formula, occupancy matches the depth image, the overlay volumes reproduce
// every list of a real run, the reverse look-up matches tiles.csv, and the
// per-tile heat sums to the run's metrics. Plus the overlays.vtm files as
// text (the VTK read-back is tests/ui/test_overlay_export.cpp).
#include "culling/core/errors.hpp"
#include "culling/diagnostics/explain.hpp"
#include "culling/diagnostics/export.hpp"
#include "culling/diagnostics/overlays.hpp"
#include "culling/scene/scene_io.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

using namespace lc;
namespace fs = std::filesystem;

namespace {

struct CulledScene {
    Scene scene;
    CullSettings settings;
    RunOutput out;
};

CulledScene runBuiltin(const std::string& name, Algorithm alg, ProjectionKind kind = ProjectionKind::Perspective,
               Slicing slicing = Slicing::Log, std::uint32_t w = 120, std::uint32_t h = 72) {
    CulledScene r;
    r.scene = makeBuiltinScene(name);
    r.scene.camera.width = w;
    r.scene.camera.height = h;
    r.scene.camera.tileSize = 16; // 120 x 72: partial edge tiles in both directions
    r.scene.camera.projection = kind;
    if (kind == ProjectionKind::ReversedZ) r.scene.camera.farPlane = std::numeric_limits<double>::infinity();
    r.settings.algorithm = alg;
    r.settings.cells = 8;
    r.settings.slicing = slicing;
    r.settings.test = SphereTest::Exact;
    auto backend = makeCpuBackend();
    RunOptions opt;
    opt.truthOptions.imageError = false;
    r.out = runPipeline(r.scene, r.settings, *backend, opt);
    return r;
}

std::vector<std::uint32_t> listOf(const CullResult& r, std::uint32_t l) {
    return {r.lightIndices.begin() + r.listOffset[l], r.lightIndices.begin() + r.listOffset[l] + r.listCount[l]};
}

// Tolerance for "on the plane": view coordinates of a few to a few hundred
// units, computed along two different double paths (plane equation vs
// unprojected corner).
double tol(const glm::dvec3& p) { return 1e-9 * (1.0 + glm::length(p)); }

std::string readText(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

struct TempDir {
    fs::path path;
    TempDir() {
        std::string t = (fs::temp_directory_path() / "lc_overlays_XXXXXX").string();
        path = ::mkdtemp(t.data());
    }
    ~TempDir() { fs::remove_all(path); }
};

} // namespace

// Every corner of a tile frustum lies on the two side planes through its
// pixel corner (tileSidePlanes, what the culling tests spheres against) and
// at the view depth the algorithm truncates at.
TEST(Overlays, TileFrustumCornersLieOnTheCullingPlanes) {
    for (ProjectionKind kind : {ProjectionKind::Perspective, ProjectionKind::ReversedZ, ProjectionKind::Orthographic}) {
        for (Algorithm alg : {Algorithm::Naive, Algorithm::MinMax}) {
            SCOPED_TRACE(std::string(toString(kind)) + " " + toString(alg));
            const CulledScene run = runBuiltin("atrium", alg, kind);
            const CullResult& r = run.out.result;
            const Projection proj(run.scene.camera);
            std::size_t checked = 0;
            for (std::uint32_t t = 0; t < r.grid.tileCount(); ++t) {
                const auto chunk = tileFrustum(r, proj, run.out.lights, t);
                const bool geometry = r.tileDepthMin[t] <= r.tileDepthMax[t];
                ASSERT_EQ(chunk.has_value(), alg == Algorithm::Naive || geometry);
                if (!chunk) continue;
                const auto rect = r.grid.tileRect(t % r.grid.tilesX, t / r.grid.tilesX);
                const auto side = tileSidePlanes(proj, rect);
                // Corner i (tl, tr, br, bl) lies on left/right (0/1) and top/bottom (2/3).
                const int xPlane[4] = {0, 1, 1, 0}, yPlane[4] = {2, 2, 3, 3};
                double lo = proj.nearPlane(), hi = cameraFarDepth(proj, run.out.lights);
                if (alg == Algorithm::MinMax) lo = r.tileDepthMin[t], hi = r.tileDepthMax[t];
                for (int i = 0; i < 8; ++i) {
                    const glm::dvec3& c = chunk->corners[i];
                    EXPECT_NEAR(signedDistance(side[xPlane[i % 4]], c), 0.0, tol(c));
                    EXPECT_NEAR(signedDistance(side[yPlane[i % 4]], c), 0.0, tol(c));
                    EXPECT_NEAR(-c.z, i < 4 ? lo : hi, tol(c));
                    // ...and inside (or on) the other planes.
                    for (const Plane& p : side) EXPECT_GE(signedDistance(p, c), -tol(c));
                }
                ++checked;
            }
            EXPECT_GT(checked, r.grid.tileCount() / 2);
        }
    }
    // Reversed-Z with an infinite far plane: naive's far is the farthest light reach.
    const CulledScene rz = runBuiltin("atrium", Algorithm::Naive, ProjectionKind::ReversedZ);
    double reach = 0;
    for (std::size_t l = 0; l < rz.out.lights.size(); ++l)
        reach = std::max(reach, -rz.out.lights.centers[l].z + rz.out.lights.radii[l]);
    EXPECT_EQ(cameraFarDepth(Projection(rz.scene.camera), rz.out.lights), reach);
}

// The overlays are the volumes the culling tested: re-running the sphere test
// against them (and the cell ranges against the occupancy) gives back every
// list of the run, for every algorithm with tile volumes.
TEST(Overlays, OverlayVolumesReproduceEveryList) {
    for (Algorithm alg : {Algorithm::Naive, Algorithm::MinMax, Algorithm::HalfZ, Algorithm::TwoPointFiveD,
                          Algorithm::Clustered, Algorithm::Fptl, Algorithm::ZBin}) {
        for (Slicing slicing : {Slicing::Log, Slicing::Linear}) {
            SCOPED_TRACE(std::string(toString(alg)) + " " + toString(slicing));
            const CulledScene run = runBuiltin("atrium", alg, ProjectionKind::Perspective, slicing);
            const CullResult& r = run.out.result;
            const ViewLights& L = run.out.lights;
            const Projection proj(run.scene.camera);
            std::size_t nonEmpty = 0;
            for (std::uint32_t t = 0; t < r.grid.tileCount(); ++t) {
                const auto [first, count] = r.tileLists(t);
                std::vector<std::vector<std::uint32_t>> expect(count);
                const auto frustum = tileFrustum(r, proj, L, t);
                const auto cells = tileCells(r, proj, t);
                // fptl: the frustum's lights that a pixel of the tile needs
                // (the ground truth's rule; the fine prune's slack is 1e-9).
                std::vector<char> needed(L.size(), 0);
                if (alg == Algorithm::Fptl)
                    for (const auto& [light, pixels] : pixelsNeedingLights(run.out.depth, proj, L, r.grid, t))
                        needed[light] = pixels > 0;
                for (std::uint32_t l = 0; l < L.size(); ++l) {
                    const glm::dvec3& c = L.centers[l];
                    const double rad = L.radii[l];
                    const std::uint32_t range = lightCellRange(r, t, c, rad);
                    switch (alg) {
                    case Algorithm::Naive:
                    case Algorithm::ZBin: // its masks: the screen-space frustum
                    case Algorithm::MinMax:
                        if (frustum && sphereIntersectsChunk(r.settings.test, *frustum, c, rad)) expect[0].push_back(l);
                        break;
                    case Algorithm::Fptl:
                        if (frustum && needed[l] && sphereIntersectsChunk(r.settings.test, *frustum, c, rad))
                            expect[0].push_back(l);
                        break;
                    case Algorithm::TwoPointFiveD: {
                        std::uint32_t occupied = 0;
                        for (const DepthCell& k : cells) occupied |= std::uint32_t(k.occupied) << k.cell;
                        if (frustum && (range & occupied) && sphereIntersectsChunk(r.settings.test, *frustum, c, rad))
                            expect[0].push_back(l);
                        break;
                    }
                    case Algorithm::HalfZ:
                    case Algorithm::Clustered:
                        for (const DepthCell& k : cells) {
                            if (alg == Algorithm::Clustered && (!k.occupied || !((range >> k.cell) & 1u))) continue;
                            if (sphereIntersectsChunk(r.settings.test, k.chunk, c, rad))
                                expect[k.list - first].push_back(l);
                        }
                        break;
                    default: break;
                    }
                }
                for (std::uint32_t s = 0; s < count; ++s) {
                    ASSERT_EQ(listOf(r, first + s), expect[s]) << "tile " << t << " list " << first + s;
                    nonEmpty += !expect[s].empty();
                }
            }
            EXPECT_GT(nonEmpty, 10u);
        }
    }
}

// Cell boundaries follow the slicing formula written out here independently,
// every geometry pixel's depth lies in an occupied cell of its tile, and every
// occupied cell holds at least one.
TEST(Overlays, CellBoundariesFollowTheSlicingAndOccupancyTheDepthImage) {
    for (Algorithm alg : {Algorithm::TwoPointFiveD, Algorithm::Clustered, Algorithm::HalfZ}) {
        for (Slicing slicing : {Slicing::Log, Slicing::Linear}) {
            SCOPED_TRACE(std::string(toString(alg)) + " " + toString(slicing));
            const CulledScene run = runBuiltin("atrium", alg, ProjectionKind::Perspective, slicing);
            const CullResult& r = run.out.result;
            const Projection proj(run.scene.camera);
            const std::uint32_t n = alg == Algorithm::HalfZ ? 2 : r.settings.cells;
            std::map<std::uint32_t, std::vector<DepthCell>> cellsOf;
            for (std::uint32_t t = 0; t < r.grid.tileCount(); ++t) {
                const bool geometry = r.tileDepthMin[t] <= r.tileDepthMax[t];
                auto cells = tileCells(r, proj, t);
                if (!geometry && alg != Algorithm::Clustered) {
                    EXPECT_TRUE(cells.empty());
                    continue;
                }
                ASSERT_EQ(cells.size(), n);
                double lo = r.tileDepthMin[t], hi = r.tileDepthMax[t];
                if (alg == Algorithm::Clustered) lo = r.clusterNear, hi = r.clusterFar;
                for (std::uint32_t k = 0; k < n; ++k) {
                    double b0, b1;
                    if (alg == Algorithm::HalfZ) {
                        const double mid = 0.5 * (lo + hi);
                        b0 = k == 0 ? lo : mid, b1 = k == 0 ? mid : hi;
                    } else if (slicing == Slicing::Log) {
                        b0 = lo * std::pow(hi / lo, double(k) / n), b1 = lo * std::pow(hi / lo, double(k + 1) / n);
                    } else {
                        b0 = lo + (hi - lo) * k / n, b1 = lo + (hi - lo) * (k + 1) / n;
                    }
                    EXPECT_EQ(cells[k].cell, k);
                    EXPECT_NEAR(cells[k].chunk.depthMin, b0, 1e-12 * hi);
                    EXPECT_NEAR(cells[k].chunk.depthMax, b1, 1e-12 * hi);
                    for (int i = 0; i < 8; ++i)
                        EXPECT_NEAR(-cells[k].chunk.corners[i].z, i < 4 ? b0 : b1, 1e-9 * hi);
                    if (k > 0) {
                        EXPECT_EQ(cells[k].chunk.depthMin, cells[k - 1].chunk.depthMax); // no gaps
                    }
                }
                cellsOf[t] = std::move(cells);
            }
            if (alg == Algorithm::HalfZ) continue; // halves are occupied by construction
            std::map<std::pair<std::uint32_t, std::uint32_t>, int> pixelsIn;
            const DepthImage& d = run.out.depth;
            for (std::uint32_t y = 0; y < d.height; ++y)
                for (std::uint32_t x = 0; x < d.width; ++x) {
                    if (!d.hasGeometry(x, y)) continue;
                    const double v = proj.viewDepthFromWindowDepth(d.at(x, y));
                    const std::uint32_t t = r.grid.tileOfPixel(x, y);
                    const auto& cells = cellsOf.at(t);
                    int found = -1;
                    for (const DepthCell& c : cells)
                        if (v >= c.chunk.depthMin && (v < c.chunk.depthMax || c.cell + 1 == cells.size())) found = int(c.cell);
                    ASSERT_GE(found, 0) << "pixel " << x << "," << y;
                    EXPECT_TRUE(cells[std::size_t(found)].occupied) << "pixel " << x << "," << y;
                    ++pixelsIn[{t, std::uint32_t(found)}];
                }
            for (const auto& [t, cells] : cellsOf)
                for (const DepthCell& c : cells)
                    if (c.occupied) {
                        EXPECT_GT((pixelsIn[{t, c.cell}]), 0) << "tile " << t << " cell " << c.cell;
                    }
        }
    }
}

// A light's cell range is exactly the cells whose depth interval its sphere's
// depth interval overlaps.
TEST(Overlays, LightCellRangeIsTheOverlapOfDepthIntervals) {
    for (Algorithm alg : {Algorithm::TwoPointFiveD, Algorithm::Clustered, Algorithm::HalfZ}) {
        const CulledScene run = runBuiltin("atrium", alg);
        const CullResult& r = run.out.result;
        const Projection proj(run.scene.camera);
        std::size_t partial = 0;
        for (std::uint32_t t = 0; t < r.grid.tileCount(); t += 7) {
            const auto cells = tileCells(r, proj, t);
            for (std::size_t l = 0; l < run.out.lights.size(); ++l) {
                const glm::dvec3 c = run.out.lights.centers[l];
                const double rad = run.out.lights.radii[l];
                const std::uint32_t range = lightCellRange(r, t, c, rad);
                std::uint32_t expect = 0;
                for (const DepthCell& k : cells)
                    if (-c.z + rad >= k.chunk.depthMin && -c.z - rad <= k.chunk.depthMax) expect |= 1u << k.cell;
                // Clamped boundaries: sliceRangeMask gives a cell on each side
                // of an exactly shared boundary; the interval test above does too.
                EXPECT_EQ(range, expect) << toString(alg) << " tile " << t << " light " << l;
                if (range && range != (cells.size() == 32 ? ~0u : (1u << cells.size()) - 1)) ++partial;
            }
        }
        EXPECT_GT(partial, 0u) << toString(alg); // some light spans only some cells
    }
    EXPECT_EQ(lightCellRange(runBuiltin("wall", Algorithm::MinMax).out.result, 0, {0, 0, -5}, 100), 0u);
}

// Reverse look-up against tiles.csv (the exported lists, parsed here).
TEST(Overlays, ReverseLookupMatchesTilesCsv) {
    for (Algorithm alg : {Algorithm::TwoPointFiveD, Algorithm::HalfZ, Algorithm::Clustered, Algorithm::All}) {
        const CulledScene run = runBuiltin("atrium", alg);
        const CullResult& r = run.out.result;
        std::map<std::uint32_t, std::set<std::uint32_t>> tilesOfLight, listsOfLight;
        std::istringstream csv(tilesCsv(run.out));
        std::string line;
        std::getline(csv, line); // header
        std::uint32_t row = 0;
        while (std::getline(csv, line)) {
            std::vector<std::string> f;
            std::stringstream ls(line);
            for (std::string s; std::getline(ls, s, ',');) f.push_back(s);
            if (line.back() == ',') f.push_back("");
            ASSERT_EQ(f.size(), 13u) << line;
            std::istringstream ids(f[12]);
            for (std::uint32_t id; ids >> id;) {
                listsOfLight[id].insert(row);
                if (alg != Algorithm::All) tilesOfLight[id].insert(std::stoul(f[1]) * r.grid.tilesX + std::stoul(f[0]));
            }
            ++row;
        }
        ASSERT_EQ(row, r.listCount.size());
        std::size_t held = 0;
        for (std::uint32_t l = 0; l < run.out.lights.size(); ++l) {
            const auto lists = listsHoldingLight(r, l);
            EXPECT_EQ(std::set<std::uint32_t>(lists.begin(), lists.end()), listsOfLight[l]) << "light " << l;
            const auto tiles = tilesHoldingLight(r, l);
            EXPECT_TRUE(std::is_sorted(tiles.begin(), tiles.end()));
            if (alg == Algorithm::All) {
                EXPECT_EQ(tiles.size(), r.grid.tileCount());
            } else {
                EXPECT_EQ(std::set<std::uint32_t>(tiles.begin(), tiles.end()), tilesOfLight[l]) << "light " << l;
            }
            held += !tiles.empty();
        }
        EXPECT_GT(held, 0u);
    }
}

// Per-tile heat: false positives sum to W - E of the run, list length is the
// longest list, efficiency is within [0, 1] and 1 exactly without false positives, NaN where
// there is no geometry.
TEST(Overlays, TileHeatAddsUpToTheRunsMetrics) {
    for (Algorithm alg : {Algorithm::Naive, Algorithm::MinMax, Algorithm::HalfZ, Algorithm::TwoPointFiveD,
                          Algorithm::Clustered, Algorithm::Fptl, Algorithm::ZBin}) {
        SCOPED_TRACE(toString(alg));
        const CulledScene run = runBuiltin("sky", alg); // sky: most tiles hold no geometry
        const CullResult& r = run.out.result;
        const Metrics& m = run.out.truth.metrics;
        const auto len = tileHeat(run.out, HeatMode::ListLength);
        const auto fp = tileHeat(run.out, HeatMode::FalsePositives);
        const auto eff = tileHeat(run.out, HeatMode::Efficiency);
        double fpSum = 0;
        std::size_t empty = 0;
        for (std::uint32_t t = 0; t < r.grid.tileCount(); ++t) {
            if (!(r.tileDepthMin[t] <= r.tileDepthMax[t])) {
                EXPECT_TRUE(std::isnan(len[t]) && std::isnan(fp[t]) && std::isnan(eff[t]));
                ++empty;
                continue;
            }
            const auto [first, count] = r.tileLists(t);
            std::uint32_t longest = 0;
            for (std::uint32_t l = first; l < first + count; ++l) longest = std::max(longest, r.listCount[l]);
            EXPECT_EQ(len[t], longest);
            fpSum += fp[t];
            EXPECT_GE(eff[t], 0.0); // 0: the tile's lists hold lights none of its pixels need
            EXPECT_LE(eff[t], 1.0);
            EXPECT_EQ(eff[t] == 1.0, fp[t] == 0.0) << "tile " << t;
        }
        EXPECT_GT(empty, 0u);
        EXPECT_EQ(fpSum, double(m.shadingWork - m.exactWork));
    }
    // `all`: list length everywhere there is geometry, no per-tile work.
    const CulledScene all = runBuiltin("sky", Algorithm::All);
    const auto eff = tileHeat(all.out, HeatMode::Efficiency);
    const auto len = tileHeat(all.out, HeatMode::ListLength);
    for (std::uint32_t t = 0; t < all.out.result.grid.tileCount(); ++t) {
        EXPECT_TRUE(std::isnan(eff[t]));
        if (all.out.result.tileDepthMin[t] <= all.out.result.tileDepthMax[t]) {
            EXPECT_EQ(len[t], all.out.lights.size());
        }
    }
}

// overlays.vtm as text: the four pieces, their counts, and the export folder
// holding it; a run from another camera is refused with a clear error.
TEST(Overlays, VtmFilesAreWrittenThroughTheExporter) {
    TempDir tmp;
    const CulledScene run = runBuiltin("atrium", Algorithm::TwoPointFiveD);
    const fs::path out = tmp.path / "diag";
    exportDiagnostics(run.scene, run.settings, run.out, out.string());
    const std::string vtm = readText(out / "overlays.vtm");
    for (const char* piece : {"camera_frustum", "tile_frustums", "depth_cells", "light_spheres"}) {
        EXPECT_NE(vtm.find(std::string("file=\"overlays/") + piece + ".vtp\""), std::string::npos) << piece;
        EXPECT_TRUE(fs::is_regular_file(out / "overlays" / (std::string(piece) + ".vtp"))) << piece;
    }
    const std::string spheres = readText(out / "overlays" / "light_spheres.vtp");
    EXPECT_NE(spheres.find("NumberOfVerts=\"" + std::to_string(run.out.lights.size()) + "\""), std::string::npos);
    std::size_t frusta = 0;
    for (std::uint32_t t = 0; t < run.out.result.grid.tileCount(); ++t)
        frusta += run.out.result.tileDepthMin[t] <= run.out.result.tileDepthMax[t];
    const std::string tiles = readText(out / "overlays" / "tile_frustums.vtp");
    EXPECT_NE(tiles.find("NumberOfPolys=\"" + std::to_string(6 * frusta) + "\""), std::string::npos);

    // Export again over it: the overlays folder is part of a previous export.
    exportDiagnostics(run.scene, run.settings, run.out, out.string());
    EXPECT_TRUE(fs::is_regular_file(out / "overlays.vtm"));

    Scene other = run.scene;
    other.camera.width += 16;
    try {
        writeOverlaysVtm(other, run.out, tmp.path.string());
        ADD_FAILURE() << "a run from another camera was written";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("run culling again"), std::string::npos) << e.what();
    }
    // View images: only the two known names.
    RgbImage img;
    img.width = img.height = 2;
    img.rgb.assign(12, 128);
    EXPECT_THROW(exportDiagnostics(run.scene, run.settings, run.out, out.string(), {{"../x.png", img}}), Error);
    exportDiagnostics(run.scene, run.settings, run.out, out.string(), {{"camera_view.png", img}});
    EXPECT_TRUE(fs::is_regular_file(out / "camera_view.png"));
}

// The inspector's rows against the ground truth: per list, the pixels needing
// the listed and missing lights add up to the list's exact work, FN = 0 means
// no Missing row, and a light taken out of a list shows up as Missing with
// the pixels that need it.
TEST(Overlays, TileLightRowsAddUpToTheGroundTruth) {
    for (Algorithm alg : {Algorithm::MinMax, Algorithm::HalfZ, Algorithm::TwoPointFiveD, Algorithm::Clustered}) {
        SCOPED_TRACE(toString(alg));
        CulledScene run = runBuiltin("atrium", alg);
        const CullResult& r = run.out.result;
        const Projection proj(run.scene.camera);
        ASSERT_EQ(run.out.truth.metrics.falseNegatives, 0u);
        std::size_t falsePositives = 0;
        for (std::uint32_t t = 0; t < r.grid.tileCount(); t += 3) {
            const auto rows = tileLightRows(run.out, proj, t);
            const auto [first, count] = r.tileLists(t);
            std::vector<std::uint64_t> exact(count, 0), listed(count, 0);
            for (const TileLightRow& row : rows) {
                ASSERT_GE(row.list, first);
                ASSERT_LT(row.list, first + count);
                EXPECT_NE(row.verdict, Verdict::Missing) << "tile " << t << " light " << row.light;
                EXPECT_EQ(row.verdict == Verdict::Needed, row.pixelsNeeding > 0);
                exact[row.list - first] += row.pixelsNeeding;
                listed[row.list - first] += row.verdict != Verdict::Missing;
                falsePositives += row.verdict == Verdict::FalsePositive;
            }
            for (std::uint32_t s = 0; s < count; ++s) {
                EXPECT_EQ(exact[s], run.out.truth.listExactWork[first + s]) << "list " << first + s;
                EXPECT_EQ(listed[s], r.listCount[first + s]);
            }
            // Cells partition the pixels: per-cell rows add up to the whole tile's.
            if (alg == Algorithm::TwoPointFiveD && r.tileDepthMin[t] <= r.tileDepthMax[t]) {
                std::map<std::uint32_t, std::uint32_t> whole, byCell;
                for (const auto& row : rows) whole[row.light] += row.pixelsNeeding;
                for (std::uint32_t c = 0; c < r.settings.cells; ++c)
                    for (const auto& row : tileLightRows(run.out, proj, t, int(c))) byCell[row.light] += row.pixelsNeeding;
                EXPECT_EQ(whole, byCell) << "tile " << t;
            }
        }
        EXPECT_GT(falsePositives, 0u);
    }

    // `all`: the one list's pixels are the whole image, whichever tile is
    // asked, and each row agrees with Explain's count for that light.
    {
        CulledScene all = runBuiltin("atrium", Algorithm::All);
        const Projection proj(all.scene.camera);
        const std::uint32_t tiles = all.out.result.grid.tileCount();
        const auto rows = tileLightRows(all.out, proj, tiles / 2);
        ASSERT_EQ(rows.size(), all.out.result.listCount[0]);
        std::uint64_t exact = 0;
        std::size_t needed = 0;
        for (const TileLightRow& row : rows) {
            exact += row.pixelsNeeding;
            needed += row.verdict == Verdict::Needed;
            EXPECT_EQ(row.verdict == Verdict::Needed, row.pixelsNeeding > 0);
            if (row.light % 16 == 0) {
                EXPECT_EQ(explainLight(all.out, proj, 0, row.light).pixelsNeeding, row.pixelsNeeding) << row.light;
            }
        }
        EXPECT_EQ(exact, all.out.truth.listExactWork[0]);
        EXPECT_GT(needed, 0u);
        const auto corner = tileLightRows(all.out, proj, 0);
        ASSERT_EQ(corner.size(), rows.size());
        for (std::size_t i = 0; i < rows.size(); ++i) EXPECT_EQ(corner[i].pixelsNeeding, rows[i].pixelsNeeding);
    }

    // Remove a needed light from one list: it becomes Missing with its pixels.
    CulledScene run = runBuiltin("atrium", Algorithm::MinMax);
    CullResult& r = run.out.result;
    const Projection proj(run.scene.camera);
    for (std::uint32_t t = 0; t < r.grid.tileCount(); ++t) {
        const auto rows = tileLightRows(run.out, proj, t);
        auto needed = std::find_if(rows.begin(), rows.end(), [](const TileLightRow& x) { return x.verdict == Verdict::Needed; });
        if (needed == rows.end()) continue;
        const TileLightRow victim = *needed;
        auto begin = r.lightIndices.begin() + r.listOffset[t];
        auto it = std::find(begin, begin + r.listCount[t], victim.light);
        ASSERT_NE(it, begin + r.listCount[t]);
        std::rotate(it, it + 1, begin + r.listCount[t]); // move it to the end of the list...
        --r.listCount[t];                              // ...and drop it
        const auto after = tileLightRows(run.out, proj, t);
        const auto missing = std::find_if(after.begin(), after.end(), [&](const TileLightRow& x) { return x.light == victim.light; });
        ASSERT_NE(missing, after.end());
        EXPECT_EQ(missing->verdict, Verdict::Missing);
        EXPECT_EQ(missing->pixelsNeeding, victim.pixelsNeeding);
        return;
    }
    FAIL() << "no tile with a needed light";
}
