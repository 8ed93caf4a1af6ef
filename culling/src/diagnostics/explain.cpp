// One light in one list, explained: the CPU reference's tests (cpu_backend.cpp's
// per-chunk test, step by step, with the same chunk, sphere and slack) and the
// ground truth of the list's pixels.
#include "culling/diagnostics/explain.hpp"

#include "culling/capture/capture_frame.hpp"
#include "culling/core/errors.hpp"
#include "culling/cpu/fine_prune.hpp"
#include "culling/custom/custom_cull.hpp"
#include "culling/math/light_proxy.hpp"
#include "culling/math/spot_tests.hpp"
#include "culling/math/tile_math.hpp"
#include "truth/light_grid.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <limits>

namespace lc {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

std::string num(double v) {
    char b[48];
    std::snprintf(b, sizeof b, "%.4g", v);
    return b;
}

bool tileEmpty(const CullResult& r, std::uint32_t t) { return !(r.tileDepthMin[t] <= r.tileDepthMax[t]); }

} // namespace

const char* chunkPlaneName(int plane) {
    static const char* kPlane[6] = {"side plane left", "side plane right", "side plane top",
                                    "side plane bottom", "depth min (chunk's near plane)",
                                    "depth max (chunk's far plane)"};
    return plane >= 0 && plane < 6 ? kPlane[plane] : "";
}

std::array<glm::dvec3, 4> chunkFace(const std::array<glm::dvec3, 8>& c, int plane) {
    // Corners: near tl, tr, br, bl (0..3), far tl, tr, br, bl (4..7).
    static const int kFace[6][4] = {{0, 3, 7, 4}, {1, 2, 6, 5}, {0, 1, 5, 4},
                                    {3, 2, 6, 7}, {0, 1, 2, 3}, {4, 5, 6, 7}};
    const int p = std::clamp(plane, 0, 5);
    return {c[std::size_t(kFace[p][0])], c[std::size_t(kFace[p][1])], c[std::size_t(kFace[p][2])],
            c[std::size_t(kFace[p][3])]};
}

namespace {

// The algorithm's tests of the light against the list's volume, as steps
// with their numbers; whether all passed.
// raster: the proxy as the reference draws it, which of its triangles
// cover the tile (or, where none does, how near the nearest came), then its
// depth range against the tile's.
bool explainRaster(const RunOutput& run, const Projection& proj, Explanation& e) {
    const CullResult& r = run.result;
    const ViewLights& lights = run.lights;
    const CullSettings& s = r.settings;
    const std::uint32_t light = e.light, t = e.tile;
    const std::uint32_t tx = t % r.grid.tilesX, ty = t / r.grid.tilesX;
    const LightProxy p = makeLightProxy(lights, light, s);
    std::vector<std::uint32_t> covering;
    // Where no triangle covers the tile: the one that comes nearest (its
    // separation from the tile's square, in tiles: how much the proxy falls
    // short, the measure for an overfit), for the step's numbers; under
    // centre sampling also a triangle that overlaps the tile without
    // covering its centre.
    std::uint32_t nearestTri = 0;
    double nearestGap = std::numeric_limits<double>::infinity();
    std::int64_t grazing = -1;
    for (std::uint32_t i = 0; i < p.mesh->triangles.size(); ++i) {
        const auto& tri = p.mesh->triangles[i];
        const std::array<glm::dvec3, 3> v = {p.vertex(tri[0]), p.vertex(tri[1]), p.vertex(tri[2])};
        bool hit = false;
        proxyTriangleTiles(proj, r.grid, v, s.conservative,
                           [&](std::uint32_t x, std::uint32_t y) { hit = hit || (x == tx && y == ty); });
        if (hit) covering.push_back(i);
        if (const double gap = proxyTriangleTileGap(proj, r.grid, v, tx, ty); !hit && gap < nearestGap)
            nearestGap = gap, nearestTri = i;
        if (!hit && !s.conservative && grazing < 0)
            proxyTriangleTiles(proj, r.grid, v, true, [&](std::uint32_t x, std::uint32_t y) {
                if (x == tx && y == ty) grazing = i;
            });
    }
    const std::string mesh =
        (p.cone ? "cone of " + std::to_string(s.proxySegments) + " sides"
                : "icosphere level " + std::to_string(s.proxyLevel)) +
        " (" + std::to_string(p.mesh->triangles.size()) + " triangles), overfit " + num(p.overfit) +
        (s.proxyOverfit > 0 ? "" : " (auto: encloses the light)");
    const std::string rule = s.conservative ? "overlaps" : "covers the centre of";
    std::string numbers;
    if (!covering.empty()) {
        numbers = "triangle " + std::to_string(covering[0]) +
                  (covering.size() > 1 ? " (and " + std::to_string(covering.size() - 1) + " more)" : std::string()) +
                  " " + rule + " tile " + std::to_string(tx) + "," + std::to_string(ty);
    } else if (grazing >= 0) {
        numbers = "no triangle covers the centre of tile " + std::to_string(tx) + "," + std::to_string(ty) +
                  "; triangle " + std::to_string(grazing) +
                  " overlaps it (centre sampling: a tile a proxy only grazes is not covered; --conservative true "
                  "covers it)";
    } else if (!std::isfinite(nearestGap)) {
        numbers = "no triangle " + rule + " tile " + std::to_string(tx) + "," + std::to_string(ty) +
                  " (the proxy lies before the near plane)";
    } else {
        char gap[96];
        std::snprintf(gap, sizeof gap, "%.3g tiles (%.3g pixels)", nearestGap, nearestGap * r.grid.tileSize);
        numbers = "no triangle " + rule + " tile " + std::to_string(tx) + "," + std::to_string(ty) +
                  "; the nearest, triangle " + std::to_string(nearestTri) + ", falls " + gap + " short of it" +
                  (s.conservative ? "" : " (centre sampling: a tile it only grazes is not covered)");
    }
    bool ok = e.steps.emplace_back(ExplainStep{"proxy coverage: " + mesh, numbers, !covering.empty()}).passed;
    if (s.proxySlices) {
        // The depths the covering triangles span over the tile -> slices.
        double lo = std::numeric_limits<double>::infinity(), hi = -lo;
        for (std::uint32_t i : covering) {
            const auto& tri = p.mesh->triangles[i];
            const auto [a, b] = proxyTriangleTileDepth(proj, r.grid, {p.vertex(tri[0]), p.vertex(tri[1]), p.vertex(tri[2])},
                                                       s.conservative, tx, ty);
            lo = std::min(lo, a), hi = std::max(hi, b);
        }
        if (covering.empty()) return false;
        const std::uint32_t all = p.sliceMask(
            SliceLocator(s.slicing, r.clusterNear, r.clusterFar, std::min<std::uint32_t>(s.cells, 32)), s.skipEmpty, lo,
            hi, ~0u);
        const std::uint32_t k = std::uint32_t(std::max(e.sub, 0));
        const bool inRange = (all >> k) & 1u;
        std::string rule;
        if (p.depthMin - p.slack() <= r.clusterNear) rule += "; the proxy reaches the near plane: from slice 0";
        if (p.depthMax + p.slack() >= r.clusterFar) rule += "; it reaches the far plane: to the last slice";
        auto range = [](std::uint32_t m) {
            if (!m) return std::string("no slice");
            const int a = std::countr_zero(m), b = 31 - std::countl_zero(m);
            return a == b ? "slice " + std::to_string(a) : "slices " + std::to_string(a) + ".." + std::to_string(b);
        };
        ok = e.steps.emplace_back(ExplainStep{"proxy depth slices (" + std::to_string(s.cells) + " " +
                                                  toString(s.slicing) + " of " + num(r.clusterNear) + ".." +
                                                  num(r.clusterFar) + ")",
                                              "the covering triangles span depths " + num(lo) + ".." + num(hi) +
                                                  " over the tile" + rule + ": " + range(all) +
                                                  (inRange ? ", slice " : ", not slice ") + std::to_string(k),
                                              inRange})
                 .passed &&
             ok;
        if (s.skipEmpty) {
            const bool occ = (r.cellMask[t] >> k) & 1u;
            ok = e.steps.emplace_back(ExplainStep{"slice holds geometry (skip-empty)", occ ? "occupied" : "empty: skipped",
                                                  occ})
                     .passed &&
                 ok;
        }
        return ok;
    }
    const double tmin = r.tileDepthMin[t], tmax = r.tileDepthMax[t];
    const bool reaches = p.depthReaches(tmin, tmax);
    ok = e.steps.emplace_back(ExplainStep{"proxy depth range",
                                          "the proxy's depth " + num(p.depthMin) + ".." + num(p.depthMax) +
                                              (reaches ? " reaches" : " misses") + " the tile's " + num(tmin) +
                                              ".." + num(tmax),
                                          reaches})
             .passed &&
         ok;
    return ok;
}

bool explainTests(const RunOutput& run, const Projection& proj, const BoundingSphere& sphere, Explanation& e) {
    const CullResult& r = run.result;
    const ViewLights& lights = run.lights;
    const CullSettings& s = r.settings;
    const std::uint32_t light = e.light, per = std::max(r.listsPerTile, 1u);
    const double rr = sphere.radius + sphereTestSlack(sphere.center, sphere.radius);
    auto step = [&](std::string test, std::string numbers, bool passed) {
        e.steps.push_back({std::move(test), std::move(numbers), passed});
        return passed;
    };
    const std::uint32_t t = e.tile;
    const TileGrid::Rect rect = r.grid.tileRect(t % r.grid.tilesX, t / r.grid.tilesX);
    const double tmin = r.tileDepthMin[t], tmax = r.tileDepthMax[t];
    const double cd = -sphere.center.z;
    const bool empty = tileEmpty(r, t);
    bool ok = true;
    double lo = 0, hi = 0;
    const bool emptyListed = r.algorithm == Algorithm::Naive || r.algorithm == Algorithm::ZBin ||
                             (r.layout() == Algorithm::Clustered && !s.skipEmpty);
    if (empty && !emptyListed) {
        ok = step("tile holds geometry", "no geometry pixel: the tile gets an empty list", false);
    } else {
        switch (r.layout()) {
        case Algorithm::ZBin: // the tile's mask: naive's screen-space volume
        case Algorithm::Naive: {
            // The range the pass culled over: the camera's near and far,
            // an infinite far replaced by the farthest reach of a light.
            lo = r.cameraNear;
            hi = r.cameraFar;
            break;
        }
        case Algorithm::Raster:
        case Algorithm::Fptl:
        case Algorithm::MinMax: lo = tmin, hi = tmax; break;
        case Algorithm::TwoPointFiveD:
            if (r.cellLists && e.sub >= 0) {
                lo = sliceBoundary(s.slicing, tmin, tmax, per, std::uint32_t(e.sub));
                hi = sliceBoundary(s.slicing, tmin, tmax, per, std::uint32_t(e.sub) + 1);
            } else {
                lo = tmin, hi = tmax;
            }
            break;
        case Algorithm::HalfZ:
            lo = e.sub == 1 ? r.halfzSplit[t] : tmin;
            hi = e.sub == 1 ? tmax : r.halfzSplit[t];
            break;
        case Algorithm::Clustered:
            lo = sliceBoundary(s.slicing, r.clusterNear, r.clusterFar, per, std::uint32_t(e.sub));
            hi = sliceBoundary(s.slicing, r.clusterNear, r.clusterFar, per, std::uint32_t(e.sub) + 1);
            break;
        default: break;
        }
        e.chunkDepthMin = lo;
        e.chunkDepthMax = hi;
        if (r.algorithm == Algorithm::TwoPointFiveD && !r.cellLists) {
            const std::uint32_t m = sliceRangeMask(s.slicing, tmin, tmax, s.cells, cd - sphere.radius, cd + sphere.radius);
            char bits[80];
            std::snprintf(bits, sizeof bits, "light's cells 0x%08x & tile's occupied cells 0x%08x", m, r.cellMask[t]);
            ok = step("cell mask (" + std::to_string(s.cells) + " " + toString(s.slicing) + " cells of " + num(tmin) +
                          ".." + num(tmax) + ")",
                      bits, (m & r.cellMask[t]) != 0) && ok;
        }
        if (r.algorithm == Algorithm::Clustered) {
            const std::uint32_t m = sliceRangeMask(s.slicing, r.clusterNear, r.clusterFar, per, cd - sphere.radius,
                                                   cd + sphere.radius);
            const bool inRange = (m >> e.sub) & 1u;
            ok = step("slice range", "the light's depth " + num(cd - sphere.radius) + ".." + num(cd + sphere.radius) +
                                         (inRange ? " reaches" : " misses") + " slice " + std::to_string(e.sub),
                      inRange) && ok;
            if (s.skipEmpty) {
                const bool occ = (r.cellMask[t] >> e.sub) & 1u;
                ok = step("slice holds geometry (skip-empty)", occ ? "occupied" : "empty: skipped", occ) && ok;
            }
        }
        const FrustumChunk chunk = makeFrustumChunk(proj, rect, lo, hi);
        e.hasChunk = true;
        e.chunkCorners = chunk.corners;
        if (r.algorithm == Algorithm::Raster) return explainRaster(run, proj, e) && ok;
        for (int k = 0; k < 6; ++k) {
            const double d = signedDistance(chunk.planes[std::size_t(k)], sphere.center);
            ok = step(chunkPlaneName(k), "signed distance " + num(d) + (d >= -rr ? " >= " : " < ") + "-r = " + num(-rr),
                      d >= -rr) && ok;
            if (e.decisivePlane < 0 || d + rr < e.decisiveMargin) e.decisivePlane = k, e.decisiveMargin = d + rr;
        }
        if (s.test != SphereTest::Planes) {
            glm::dvec3 blo = chunk.corners[0], bhi = chunk.corners[0];
            for (const auto& c : chunk.corners) blo = glm::min(blo, c), bhi = glm::max(bhi, c);
            const double d = glm::length(sphere.center - glm::clamp(sphere.center, blo, bhi));
            ok = step("box around the chunk (planes+aabb)", "distance " + num(d) + (d <= rr ? " <= " : " > ") + "r = " + num(rr),
                      d <= rr) && ok;
        }
        if (s.test == SphereTest::Exact) {
            const double d = distanceToChunk(chunk, sphere.center);
            ok = step("exact distance to the chunk", "distance " + num(d) + (d <= rr ? " <= " : " > ") + "r = " + num(rr),
                      d <= rr) && ok;
        }
        const bool coneRefines = s.spotTest == SpotTest::ConeSphere || s.spotTest == SpotTest::ConePlanes;
        if (coneRefines && lights.isSpot(light)) {
            const bool pass = spotIntersectsChunk(s.spotTest, s.test, lights.spotCone(light), chunk);
            ok = step(std::string("spot cone (") + toString(s.spotTest) + ")",
                      pass ? "the cone meets the chunk" : "the cone misses the chunk", pass) && ok;
        }
        const std::size_t binned = lights.size() - r.limits.lightsOverLimit; // zbin sorts the kept lights
        if (r.algorithm == Algorithm::ZBin && r.limits.isOverLimit(light)) {
            // The kept lights alone were sorted and binned: this one has no
            // place among them (reported, as below, not a test of the list).
            step("Z-bins (per pixel, after the mask)",
                 "not binned: past the light limit (max-lights " + std::to_string(s.maxLights) + "), only the " +
                     std::to_string(binned) + " lights kept are sorted into the bins",
                 false);
        } else if (r.algorithm == Algorithm::ZBin && light < r.zbinRank.size()) {
            // After the mask, each pixel's bin: the light is looped over
            // where its rank lies in the bin's range. Reported, not a test
            // of the list (the mask is the list).
            const std::uint32_t k = r.zbinRank[light];
            std::uint32_t inRange = 0, pixels = 0;
            for (std::uint32_t y = rect.y0; y < rect.y1; ++y)
                for (std::uint32_t x = rect.x0; x < rect.x1; ++x) {
                    if (!run.depth.hasGeometry(x, y)) continue;
                    ++pixels;
                    const std::uint32_t b = r.zbinOf(proj.viewDepthFromWindowDepth(run.depth.at(x, y)));
                    inRange += r.zbinLo[b] <= k && k <= r.zbinHi[b];
                }
            step("Z-bins (per pixel, after the mask)",
                 "sorted position " + std::to_string(k) + " of " + std::to_string(binned) + "; bins " +
                     std::to_string(r.zbinOf(cd - sphere.radius)) + ".." + std::to_string(r.zbinOf(cd + sphere.radius)) +
                     " of " + std::to_string(r.zbinLo.size()) + "; the pixels of " + std::to_string(inRange) + " of the tile's " +
                     std::to_string(pixels) + " geometry pixels loop over it",
                 inRange > 0);
        }
        if (r.algorithm == Algorithm::Fptl) {
            // The fine prune, as the reference runs it (fine_prune.hpp):
            // the tile's geometry pixels inside the light's volume.
            std::uint32_t inside = 0, pixels = 0;
            for (std::uint32_t y = rect.y0; y < rect.y1; ++y)
                for (std::uint32_t x = rect.x0; x < rect.x1; ++x) {
                    if (!run.depth.hasGeometry(x, y)) continue;
                    ++pixels;
                    inside += fptlPixelKeeps(lights, light, proj.viewPositionFromDepth(x, y, run.depth.at(x, y)));
                }
            ok = step("fine prune (the tile's pixels)",
                      std::to_string(inside) + " of the tile's " + std::to_string(pixels) +
                          " geometry pixels lie inside the light's volume (+slack)",
                      inside > 0) && ok;
        }
    }
    return ok;
}

// Ground truth over the list's pixels: how many use the list, how many need
// the light, the needed pixel nearest its centre or, where none does, the
// pixel nearest its range.
void explainPixels(const RunOutput& run, const Projection& proj, Explanation& e) {
    const CullResult& r = run.result;
    const ViewLights& lights = run.lights;
    const std::uint32_t list = e.list, light = e.light;
    e.nearestDistance = kInf;
    double neededToCentre = kInf;
    std::uint32_t x0 = 0, y0 = 0, x1 = r.grid.width, y1 = r.grid.height;
    if (r.algorithm != Algorithm::All) {
        const TileGrid::Rect rect = r.grid.tileRect(e.tile % r.grid.tilesX, e.tile / r.grid.tilesX);
        x0 = rect.x0, y0 = rect.y0, x1 = rect.x1, y1 = rect.y1;
    }
    for (std::uint32_t y = y0; y < y1; ++y)
        for (std::uint32_t x = x0; x < x1; ++x) {
            if (!run.depth.hasGeometry(x, y)) continue;
            const glm::dvec3 p = proj.viewPositionFromDepth(x, y, run.depth.at(x, y));
            if (r.listOfPixel(x, y, -p.z) != list) continue;
            ++e.listPixels;
            if (detail::lightNeeds(lights, light, p)) {
                ++e.pixelsNeeding;
                const double toCentre = glm::length(p - lights.centers[light]);
                if (!e.hasNeededPixel || toCentre < neededToCentre) {
                    e.hasNeededPixel = true;
                    e.neededPosition = p;
                    neededToCentre = toCentre;
                }
                continue;
            }
            const double d = std::max(0.0, glm::length(p - lights.centers[light]) - lights.radii[light]);
            if (d < e.nearestDistance) {
                e.nearestDistance = d;
                e.nearestPosition = p;
                e.nearestX = x, e.nearestY = y;
            }
        }
    if (e.pixelsNeeding > 0 || e.listPixels == 0) e.nearestDistance = -1;

}

// The verdict: needed, a false positive, missing (and why) or rightly left out.
std::string verdictOf(const RunOutput& run, Explanation& e) {
    const CullResult& r = run.result;
    const ViewLights& lights = run.lights;
    const std::uint32_t list = e.list, light = e.light;
    std::string failed;
    for (const ExplainStep& st : e.steps)
        if (!st.passed && failed.empty()) failed = st.test;
    if (e.listed && e.pixelsNeeding > 0) {
        e.verdict = "needed: listed, and " + std::to_string(e.pixelsNeeding) + " of the list's " +
                    std::to_string(e.listPixels) + (e.listPixels == 1 ? " pixel needs it" : " pixels need it");
    } else if (e.listed && r.settings.overflow == OverflowPolicy::AllLights && r.limits.overflowIndex(list) >= 0) {
        e.verdict = "listed by the all-lights fallback: the list was over-full (cap " + std::to_string(r.settings.cap) +
                    ") and lists every light instead" +
                    (e.pixelsNeeding > 0 ? "; " + std::to_string(e.pixelsNeeding) + " of its pixels need it"
                                         : std::string("; none of its pixels needs it"));
    } else if (e.listed) {
        e.verdict = e.listPixels == 0 ? "listed, but no pixel uses this list"
                                      : "false positive: listed, but none of the list's " + std::to_string(e.listPixels) +
                                            " pixels is inside its volume; the nearest is " +
                                            // A spot's pixel within its range is outside its cone.
                                            (e.nearestDistance == 0.0 && lights.isSpot(light)
                                                 ? std::string("within its range but outside its cone")
                                                 : num(e.nearestDistance) + " beyond its range") +
                                            " (pixel " + std::to_string(e.nearestX) + "," +
                                            std::to_string(e.nearestY) + ")" +
                                            (e.testsPass ? ": the tests are conservative here (the sphere meets the "
                                                           "chunk, not the pixels' surfaces)"
                                                         : "");
    } else if (e.pixelsNeeding > 0) {
        // A custom culling's list that overflowed or held an invalid index:
        // that, not the test, is the likely cause (MissCause).
        const CustomCullReport* c = run.custom.get();
        const auto among = [&](const std::vector<std::uint32_t>& ids) {
            return std::binary_search(ids.begin(), ids.end(), list);
        };
        std::string cause;
        const ListLimits& limits = run.result.limits;
        const CullSettings& set = run.result.settings;
        if (limits.isOverLimit(light))
            cause = " (dropped: past the light limit, max-lights " + std::to_string(set.maxLights) + " keeping " +
                    toString(set.limitKeep) + "; the culling never saw it)";
        else if (limits.dropped(list, light))
            cause = " (dropped: list full (" +
                    (set.cap ? "cap " + std::to_string(set.cap) : std::string()) +
                    (set.cap && set.maxEntries ? ", " : "") +
                    (set.maxEntries ? "record buffer of " + std::to_string(set.maxEntries) + " entries" : std::string()) +
                    "); the test kept it, overflow-policy " + toString(set.overflow) + " dropped it)";
        else if (c && among(c->overflowedListIds))
            cause = " (dropped: list full, layout " + c->layout + "; the shader wrote more entries than fit)";
        else if (c && among(c->invalidIndexListIds))
            cause = " (the list held an index past the light count: an invalid index, perhaps where this light's "
                    "belonged)";
        else if (failed.empty())
            cause = " (the reference's tests keep it: this pass dropped it)";
        else
            cause = " (the first test to reject it: '" + failed + "')";
        e.verdict = "MISSING: not listed, but " + std::to_string(e.pixelsNeeding) + (e.pixelsNeeding == 1 ? " of the list's pixels needs it" : " of the list's pixels need it") +
                    cause;
    } else {
        // A light the limits took out loses nothing here, but the list would
        // have held it: say so, so that a limit's reach is visible.
        const ListLimits& limits = run.result.limits;
        std::string limit;
        if (limits.isOverLimit(light))
            limit = "; past the light limit too (max-lights " + std::to_string(r.settings.maxLights) + ")";
        else if (limits.dropped(list, light))
            limit = "; the list was full too: the test kept it and the limits dropped it";
        e.verdict = "not listed, rightly: no pixel of the list needs it" +
                    (failed.empty() ? std::string() : " (the first test to reject it: '" + failed + "')") + limit;
    }
    return e.verdict;
}

} // namespace

Explanation explainLight(const RunOutput& run, const Projection& proj, std::uint32_t list, std::uint32_t light) {
    const CullResult& r = run.result;
    const ViewLights& lights = run.lights;
    if (list >= r.listCount.size())
        throw SettingsError("list", std::to_string(list) + " is outside 0.." + std::to_string(r.listCount.size() - 1));
    if (light >= lights.size())
        throw SettingsError("light", std::to_string(light) + " is outside 0.." + std::to_string(lights.size() - 1));
    const CullSettings& s = r.settings;
    Explanation e;
    e.list = list;
    e.light = light;
    // A shader's, dump's or capture's lists: whose, and which rule they
    // follow (the skeleton's algorithm is only how their tiles are laid out).
    if (run.custom)
        e.algorithm = std::string(captureDepth(run) ? "capture" : "custom") + " (" +
                      (r.algorithm == Algorithm::ZBin ? std::string("zbin") : run.custom->lists) + " lists)";
    else
        e.algorithm = toString(r.algorithm);
    const std::uint32_t per = std::max(r.listsPerTile, 1u);
    e.tile = r.tileOfList(list);
    e.tileX = e.tile % std::max(r.grid.tilesX, 1u);
    e.tileY = e.tile / std::max(r.grid.tilesX, 1u);
    e.sub = per > 1 ? int(list % per) : -1;
    const auto first = r.lightIndices.begin() + r.listOffset[list];
    e.listed = std::binary_search(first, first + r.listCount[list], light);

    const BoundingSphere sphere = lights.cullSphere(light, s.spotTest);
    e.sphereCenter = sphere.center;
    e.sphereRadius = sphere.radius;
    if (r.algorithm == Algorithm::All)
        e.steps.push_back({"all", "one list holds every light: nothing is tested", true});
    e.testsPass = r.algorithm == Algorithm::All || explainTests(run, proj, sphere, e);
    explainPixels(run, proj, e);
    verdictOf(run, e);
    if (e.listed && !e.testsPass) {
        if (run.custom)
            e.listedAnyway = "the shader's own test kept it; the tests above are the built-in ones of its lists";
        else if (r.algorithm == Algorithm::Raster && r.backend == "vulkan")
            e.listedAnyway = "the rasteriser's coverage of its proxy reached the tile (" +
                             (r.coverage.empty() ? std::string("conservative") : r.coverage) +
                             "), wider than the exact overlap the tests above work out";
        else if (r.backend == "vulkan")
            e.listedAnyway = "the Vulkan passes widen every float comparison (by about 2e-5 relative, docs/VULKAN.md) "
                             "so that rounding never drops a light; the tests above, in double precision, reject it "
                             "by less than that";
        else
            e.listedAnyway = "the backend's own test kept it though the reference's rejects it: report it as a defect";
    }
    return e;
}

std::string Explanation::text(const std::string& lightName) const {
    std::string out = "light " + std::to_string(light) + (lightName.empty() ? "" : " '" + lightName + "'") + " in list " +
                      std::to_string(list) + " (tile " + std::to_string(tileX) + "," + std::to_string(tileY) + (sub >= 0 ? ", sub-list " + std::to_string(sub) : "") +
                      "), " + algorithm + "\n";
    out += "  culling sphere: centre (" + num(sphereCenter.x) + ", " + num(sphereCenter.y) + ", " + num(sphereCenter.z) +
           ") view space, radius " + num(sphereRadius) + "; its view depth " + num(-sphereCenter.z - sphereRadius) +
           ".." + num(-sphereCenter.z + sphereRadius) + "\n";
    if (chunkDepthMax > 0) out += "  tested chunk: view depth " + num(chunkDepthMin) + ".." + num(chunkDepthMax) + "\n";
    for (const ExplainStep& s : steps) out += std::string("  ") + (s.passed ? "pass  " : "FAIL  ") + s.test + ": " + s.numbers + "\n";
    if (decisivePlane >= 0)
        out += std::string("  ") +
               (decisiveMargin < 0 ? "of the six planes, farthest outside: the " : "of the six planes, closest to rejecting it: the ") +
               chunkPlaneName(decisivePlane) + " (signed distance + r = " + num(decisiveMargin) + ")\n";
    out += "  tests: " + std::string(testsPass ? "keep it" : "reject it") + "; the list " +
           (listed ? "holds it" : "does not hold it") + "\n";
    if (!listedAnyway.empty()) out += "  why listed: " + listedAnyway + "\n";
    out += "  verdict: " + verdict + "\n";
    return out;
}

} // namespace lc
