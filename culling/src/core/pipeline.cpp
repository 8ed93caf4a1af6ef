// One run of the pipeline: validate, depth pre-pass, culling pass, ground truth.
// Times are milliseconds: depth and cull as the backend measured them (its
// timingMethod says how), ground truth as CPU wall time around the call.

#include "culling/core/pipeline.hpp"

#include "culling/core/errors.hpp"
#include "culling/custom/custom_cull.hpp" // CustomCullReport: a shader's full lists
#include "culling/truth/shade.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <functional>
#include <numeric>

namespace lc {

namespace {

void throwIfCancelled(const CancelToken* cancel) {
    if (cancel && cancel->cancelled.load()) throw Cancelled();
}

// CullSettings::validate names the field first ("cells: must be in 1..32");
// the field becomes the SettingsError's field.
[[noreturn]] void throwSettings(const std::string& message) {
    const auto colon = message.find(": ");
    if (colon != std::string::npos && colon > 0 && message.find(' ') > colon)
        throw SettingsError(message.substr(0, colon), message.substr(colon + 2));
    throw SettingsError("settings", message);
}

} // namespace

namespace {

// Rows [y0, y1) of a G-buffer.
ShadeInputs rowsOf(const ShadeInputs& in, std::uint32_t y0, std::uint32_t y1) {
    ShadeInputs s;
    s.width = in.width;
    s.height = y1 - y0;
    s.perPixelLists = in.perPixelLists;
    const std::size_t a = std::size_t(in.width) * y0, b = std::size_t(in.width) * y1;
    s.position.assign(in.position.begin() + std::ptrdiff_t(3 * a),
                      in.position.begin() + std::ptrdiff_t(3 * b));
    s.normal.assign(in.normal.begin() + std::ptrdiff_t(3 * a), in.normal.begin() + std::ptrdiff_t(3 * b));
    s.list.assign(in.list.begin() + std::ptrdiff_t(a), in.list.begin() + std::ptrdiff_t(b));
    return s;
}

// One image of the shading pass: whole (sliceMs <= 0), or in row slices of
// about sliceMs wall time, checking `cancel` between slices. Slices start on
// multiples of `align` rows, where shadeCpu's own row bands start, so each
// pixel gets the arithmetic of one whole-image call. Returns RGB and the
// backend's shading time (the sum of the slices').
std::vector<float> shadeImage(CullBackend& backend, const ShadeInputs& in, const ViewLights& lights,
                              const CullResult* culled, std::uint32_t align, double sliceMs,
                              const CancelToken* cancel, double& shadeMs,
                              const std::function<void(double)>& rowsDone) {
    if (sliceMs <= 0) {
        std::vector<float> rgb = backend.shade(in, lights, culled);
        shadeMs = backend.lastShadeMs();
        return rgb;
    }
    std::vector<float> rgb(in.position.size(), 0.0f);
    shadeMs = 0;
    std::uint32_t rows = align;
    for (std::uint32_t y0 = 0; y0 < in.height;) {
        const std::uint32_t y1 = std::min(in.height, y0 + rows);
        const auto t0 = std::chrono::steady_clock::now();
        const std::vector<float> part = backend.shade(rowsOf(in, y0, y1), lights, culled);
        const double wallMs =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        shadeMs += backend.lastShadeMs() >= 0 ? backend.lastShadeMs() : wallMs;
        std::copy(part.begin(), part.end(), rgb.begin() + std::ptrdiff_t(std::size_t(in.width) * y0 * 3));
        throwIfCancelled(cancel);
        if (rowsDone) rowsDone(double(y1) / double(in.height));
        // The next slice: as many aligned rows as fit sliceMs at this rate.
        const double perRowMs = std::max(wallMs, 1e-3) / double(y1 - y0);
        rows = std::max(align, std::uint32_t(sliceMs / perRowMs) / align * align);
        y0 = y1;
    }
    return rgb;
}

// What shades a light: its position, power and cone (not its range).
using ShadingKey = std::array<double, 10>;
ShadingKey shadingKey(const ViewLights& l, std::size_t i) {
    const glm::dvec3 c = l.centers[i], p = l.power[i];
    const glm::dvec3 a = l.isSpot(i) ? l.spotAxes[i] : glm::dvec3(0.0);
    return {c.x, c.y, c.z, p.x, p.y, p.z, a.x, a.y, a.z, l.isSpot(i) ? l.spotAngles[i] : 0.0};
}

// The lights of `before` no light of `after` shades as (gone) and those of
// `after` no light of `before` does (come), matched one to one by value, so
// that a light removed or inserted before others does not change them.
// `reordered`: the matched lights are not in the same order in both (a sum
// in another order rounds differently).
struct LightsDiff {
    std::vector<std::size_t> gone, come;
    bool reordered = false;
};
LightsDiff diffShadingLights(const ViewLights& before, const ViewLights& after) {
    auto sorted = [](const ViewLights& l) {
        std::vector<std::pair<ShadingKey, std::size_t>> keys(l.size());
        for (std::size_t i = 0; i < l.size(); ++i) keys[i] = {shadingKey(l, i), i};
        std::sort(keys.begin(), keys.end());
        return keys;
    };
    const auto b = sorted(before), a = sorted(after);
    LightsDiff d;
    std::vector<std::pair<std::size_t, std::size_t>> matched; // (before, after)
    std::size_t i = 0, j = 0;
    while (i < b.size() || j < a.size()) {
        if (j == a.size() || (i < b.size() && b[i].first < a[j].first)) {
            d.gone.push_back(b[i++].second);
        } else if (i == b.size() || a[j].first < b[i].first) {
            d.come.push_back(a[j++].second);
        } else {
            matched.emplace_back(b[i++].second, a[j++].second);
        }
    }
    std::sort(matched.begin(), matched.end());
    for (std::size_t k = 1; k < matched.size() && !d.reordered; ++k)
        d.reordered = matched[k].second < matched[k - 1].second;
    std::sort(d.gone.begin(), d.gone.end());
    std::sort(d.come.begin(), d.come.end());
    return d;
}

ViewLights lightsOf(const ViewLights& l, const std::vector<std::size_t>& which) {
    ViewLights s;
    const bool spots = !l.spotAngles.empty();
    const bool ranges = !l.shadingRanges.empty();
    for (std::size_t i : which) {
        s.centers.push_back(l.centers[i]);
        s.radii.push_back(l.radii[i]);
        s.power.push_back(l.power[i]);
        if (ranges) s.shadingRanges.push_back(l.shadingRanges[i]);
        if (spots) {
            s.spotAxes.push_back(l.spotAxes[i]);
            s.spotAngles.push_back(l.spotAngles[i]);
        }
    }
    return s;
}

bool sameLights(const ViewLights& a, const ViewLights& b) {
    return a.centers == b.centers && a.power == b.power && a.spotAxes == b.spotAxes && a.spotAngles == b.spotAngles &&
           a.shadingRanges == b.shadingRanges;
}

} // namespace

void shadeAndCompare(CullBackend& backend, RunOutput& out, const Projection& proj, bool keepImages,
                     const CancelToken* cancel, double sliceMs, const Progress& progress, const RunOutput* earlier) {
    // zbin: the lists its pixels loop over, a (tile, bin) each.
    const ShadeInputs culledIn = makeShadeInputs(out.depth, proj, &out.result);
    const CullResult& r = out.result;
    // shadeCpu's row bands: a tile row (at least 4) for lists, 16 rows for all lights.
    const std::uint32_t align = std::lcm(std::max(r.grid.tileSize, 4u), 16u);
    double culledMs = 0, allMs = 0;
    // `all` with one list of every light in order shades exactly the reference.
    bool identity = r.listCount.size() == 1 && r.listCount[0] == out.lights.size();
    for (std::size_t i = 0; identity && i < out.lights.size(); ++i)
        identity = r.lightIndices[r.listOffset[0] + i] == i;
    const bool usable = !identity && earlier && earlier->shadedAll.size() == culledIn.position.size() &&
                        earlier->depth.width == out.depth.width && earlier->depth.depth == out.depth.depth;
    const bool reuse = usable && sameLights(earlier->lights, out.lights);
    LightsDiff diff;
    if (usable && !reuse) diff = diffShadingLights(earlier->lights, out.lights);
    const std::size_t changed = diff.gone.size() + diff.come.size();
    bool update = usable && !reuse && !diff.reordered && changed > 0 &&
                  2 * changed <= std::max(earlier->lights.size(), out.lights.size());
    auto part = [&progress](double base, double share) -> std::function<void(double)> {
        if (!progress) return {};
        return [&progress, base, share](double f) { progress(base + share * f); };
    };
    out.allLightsReused = reuse;
    out.allLightsUpdate.reset();
    ShadeInputs allIn;
    if (!identity && !reuse) {
        allIn = culledIn;
        allIn.perPixelLists.reset();
        for (std::uint32_t& l : allIn.list)
            if (l != ShadeInputs::kNoList) l = 0;
    }
    std::vector<float> all, carried;
    // An update: per pixel, list 0 where it is shaded again from every
    // light, kNoList elsewhere (allIn's lists, once the update stands).
    std::vector<std::uint32_t> again;
    std::uint64_t pixelsAgain = 0, lit = 0;
    double base = 0; // progress so far
    if (update) {
        // The changed lights' terms first, each set shaded alone over every
        // pixel: they decide how much is left to shade.
        auto termsOf = [&](const std::vector<std::size_t>& which, const ViewLights& from, double at) {
            if (which.empty()) return std::vector<float>(culledIn.position.size(), 0.0f);
            double ms = 0;
            std::vector<float> t = shadeImage(backend, allIn, lightsOf(from, which), nullptr, align, sliceMs,
                                              cancel, ms, part(at, 0.05));
            throwIfCancelled(cancel);
            return t;
        };
        const std::vector<float> gone = termsOf(diff.gone, earlier->lights, 0.0);
        const std::vector<float> come = termsOf(diff.come, out.lights, 0.05);
        base = 0.1;
        all = earlier->shadedAll;
        carried = earlier->shadedAllCarried;
        carried.resize(all.size(), 0.0f);
        // Each subtraction and addition rounds by at most half an ulp of its
        // result; `carried` sums the magnitudes those roundings scale with,
        // starting, where a value was shaded from every light (nothing
        // carried yet), from that sum's own rounding: about sqrt(n) ulps of
        // it over n lights. Where it outgrows the value (a light that
        // outshone the rest moved away), the pixel is shaded again from
        // every light.
        const float freshUlps = float(std::sqrt(double(earlier->lights.size())));
        again = allIn.list;
        for (std::size_t i = 0; i < again.size(); ++i) {
            if (again[i] == ShadeInputs::kNoList) continue;
            ++lit;
            bool redo = false;
            for (std::size_t k = 3 * i; k < 3 * i + 3; ++k) {
                if (gone[k] == 0.0f && come[k] == 0.0f) continue;
                if (carried[k] == 0.0f) carried[k] = freshUlps * std::fabs(all[k]);
                const float v = (all[k] - gone[k]) + come[k];
                all[k] = v;
                carried[k] += std::fabs(gone[k]) + std::fabs(come[k]) + std::fabs(v);
                redo = redo || !(carried[k] <= kCarryLimit * std::fabs(v));
            }
            if (redo) ++pixelsAgain;
            else again[i] = ShadeInputs::kNoList;
        }
        // Most pixels to shade again costs about what shading every light does.
        if (2 * pixelsAgain > lit) {
            update = false;
            all.clear();
            carried.clear();
        }
    }
    // The all-lights image costs more (every light at every pixel), but the
    // split by images is what a user can follow: half each, unless one is
    // all there is to shade; an update's pixels shaded again by their share.
    const double againShare = double(pixelsAgain) / double(std::max<std::uint64_t>(lit, 1));
    const double culledShare = (1.0 - base) * (identity || reuse ? 1.0 : update ? 1.0 / (1.0 + againShare) : 0.5);
    std::vector<float> culled =
        shadeImage(backend, culledIn, out.lights, &r, align, sliceMs, cancel, culledMs, part(base, culledShare));
    out.result.timings.shadeMs = culledMs;
    throwIfCancelled(cancel);
    const double rest = base + culledShare, restShare = 1.0 - rest;
    if (identity) {
        all = culled;
    } else if (reuse) {
        all = earlier->shadedAll;
        carried = earlier->shadedAllCarried;
    } else if (update) {
        if (pixelsAgain > 0) {
            allIn.list = std::move(again);
            double againMs = 0;
            const std::vector<float> fresh =
                shadeImage(backend, allIn, out.lights, nullptr, align, sliceMs, cancel, againMs, part(rest, restShare));
            throwIfCancelled(cancel);
            for (std::size_t i = 0; i < allIn.list.size(); ++i) {
                if (allIn.list[i] == ShadeInputs::kNoList) continue;
                for (std::size_t k = 3 * i; k < 3 * i + 3; ++k) {
                    all[k] = fresh[k];
                    carried[k] = 0.0f;
                }
            }
        }
        out.allLightsUpdate = RunOutput::AllLightsUpdate{diff.gone.size(), diff.come.size(), pixelsAgain};
    } else {
        all = shadeImage(backend, allIn, out.lights, nullptr, align, sliceMs, cancel, allMs, part(rest, restShare));
        throwIfCancelled(cancel);
    }
    const ImageError e = compareShadedImages(out.depth, culled, all);
    Metrics& m = out.truth.metrics;
    m.imageRmse = e.rmse;
    m.imageMaxError = e.maxAbs;
    m.imageErrorComputed = true;
    if (keepImages) {
        out.shadedCulled = std::move(culled);
        out.shadedAll = std::move(all);
        out.shadedAllCarried = std::move(carried);
    }
}

bool samePixels(const RunOutput& a, const Camera& ca, const RunOutput& b, const Camera& cb) {
    Camera c = cb;
    c.tileSize = ca.tileSize; // tiles shape the lists only
    const DepthImage &da = a.depth, &db = b.depth;
    return ca == c && da.width == db.width && da.height == db.height && da.clearDepth == db.clearDepth &&
           da.depth == db.depth;
}

bool sameAllLightsImage(const RunOutput& a, const Camera& ca, const RunOutput& b, const Camera& cb) {
    return samePixels(a, ca, b, cb) && sameLights(a.lights, b.lights);
}

RunOutput runPipeline(const Scene& scene, ListSource& source, CullBackend* backend, const RunOptions& options,
                      const CancelToken* cancel) {
    using Clock = std::chrono::steady_clock;
    scene.validate();
    const Projection proj(scene.camera);
    const TileGrid grid = TileGrid::make(scene.camera.width, scene.camera.height, scene.camera.tileSize);

    RunOutput out;
    out.lights = makeViewLights(scene);
    throwIfCancelled(cancel);

    DepthPass pass;
    if (options.reuseDepth) {
        out.depth = *options.reuseDepth;
        out.depthReused = true;
        if (out.depth.width != grid.width || out.depth.height != grid.height ||
            out.depth.depth.size() != std::size_t(grid.width) * grid.height)
            throw Error("the reused depth image is " + std::to_string(out.depth.width) + "x" +
                        std::to_string(out.depth.height) + " but the camera is " + std::to_string(grid.width) + "x" +
                        std::to_string(grid.height));
    } else {
        if (!backend) throw Error("a run without a backend needs a depth image");
        pass = backend->depthPass(scene, proj); // checks the image against the camera
        out.depth = std::move(pass.image);
    }
    throwIfCancelled(cancel);

    const auto t1 = Clock::now();
    out.result = source.makeLists(scene, out.depth, proj, grid, out.lights);
    const double cullWallMs = std::chrono::duration<double, std::milli>(Clock::now() - t1).count();
    out.custom = source.report();
    if (const std::string bad = out.result.validate(out.lights.size()); !bad.empty())
        throw Error("'" + (out.result.backend.empty() && backend ? backend->name() : out.result.backend) +
                    "' produced inconsistent lists: " + bad);
    // The depth pass's own figures; a source that did not time its lists
    // gets the wall time around the call (a dump's are not timed: -1 stays).
    out.result.timings.depthMs = out.depthReused ? 0.0 : pass.ms;
    if (out.result.timings.cullMs < 0 && !out.custom) out.result.timings.cullMs = cullWallMs;
    out.result.depthTriangles = pass.triangles;
    out.result.depthTrianglesDrawn = pass.trianglesDrawn;
    if (backend) {
        if (out.result.backend.empty()) out.result.backend = backend->name();
        if (out.result.device.empty()) out.result.device = backend->deviceName();
        if (out.result.timingMethod.empty()) out.result.timingMethod = backend->timingMethod();
        // Lists from elsewhere than the backend that drew the depth: name
        // the rasteriser (backends differ at a few edge pixels).
        if (!out.depthReused && out.result.backend != backend->name())
            out.depthFrom = "pre-pass on " + backend->name() + " (" + backend->deviceName() + ")";
    }
    throwIfCancelled(cancel);
    if (backend) {
        judgeRun(out, proj, *backend, options, cancel);
    } else {
        const std::unique_ptr<CullBackend> cpu = makeCpuBackend();
        judgeRun(out, proj, *cpu, options, cancel);
    }
    return out;
}

RunOutput runPipeline(const Scene& scene, const CullSettings& settings, CullBackend& backend,
                      const RunOptions& options, const CancelToken* cancel) {
    if (const std::string bad = settings.validate(); !bad.empty()) throwSettings(bad);
    BackendLists lists(backend, settings);
    return runPipeline(scene, lists, &backend, options, cancel);
}

void judgeRun(RunOutput& out, const Projection& proj, CullBackend& shadeBackend, const RunOptions& options,
              const CancelToken* cancel) {
    using Clock = std::chrono::steady_clock;
    if (options.groundTruth) {
        GroundTruthOptions truthOptions = options.truthOptions;
        truthOptions.imageError = false; // from the backend's shading pass below
        if (out.custom) truthOptions.fullLists = &out.custom->overflowedListIds;
        const auto t0 = Clock::now();
        out.truth = computeGroundTruth(out.depth, proj, out.lights, out.result, truthOptions, cancel);
        out.truthComputed = true;
        out.result.timings.groundTruthMs = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    }
    if (options.truthOptions.imageError) {
        throwIfCancelled(cancel);
        shadeAndCompare(shadeBackend, out, proj, options.keepShadedImages, cancel);
    }
}

} // namespace lc
