// The speed-against-error report (report.hpp): the sweep, the Pareto fronts,
// report.csv / report.md / pareto.png and their atomic folder write.

#include "culling/diagnostics/report.hpp"

#include "culling/core/backend.hpp"
#include "culling/core/content_hash.hpp"
#include "culling/core/depth.hpp"
#include "culling/core/presets.hpp"
#include "culling/core/errors.hpp"
#include "culling/core/file_io.hpp"
#include "culling/core/text.hpp"
#include "culling/truth/ground_truth.hpp"
#include "culling/truth/shade.hpp"
#include "diagnostics/font5x7.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <set>

#include <fcntl.h>
#include <stdlib.h>
#include <unistd.h>

namespace lc {

namespace fs = std::filesystem;

namespace {

bool cancelled(const CancelToken* c) { return c && c->cancelled.load(); }

double median(std::vector<double> v) {
    if (v.empty()) return -1;
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string fmt(const char* f, double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, f, v);
    return buf;
}

// Shortest text that reads back as the same double.
std::string roundTrip(double v) {
    std::array<char, 64> buf{};
    const auto r = std::to_chars(buf.data(), buf.data() + buf.size(), v);
    return std::string(buf.data(), r.ptr);
}

bool sweptByTable(const ParamSpec& p) { return p.name != "width" && p.name != "height"; }

std::vector<std::string> splitCommas(const std::string& s) {
    std::vector<std::string> out;
    std::size_t start = 0;
    for (std::size_t comma; (comma = s.find(',', start)) != std::string::npos; start = comma + 1)
        out.push_back(s.substr(start, comma - start));
    out.push_back(s.substr(start));
    return out;
}

// Values of one parameter in the sweep.
std::vector<std::string> sweepValues(const ParamSpec& p, const ReportOptions& o) {
    if (auto it = o.fixed.find(p.name); it != o.fixed.end()) return splitCommas(it->second);
    auto asText = [](const std::vector<std::uint32_t>& v) {
        std::vector<std::string> s;
        for (auto x : v) s.push_back(std::to_string(x));
        return s;
    };
    if (p.name == "tile") return asText(o.tileSizes);
    if (p.name == "cells") return asText(o.cellCounts);
    // raster: the proxy's detail, with the overfit that encloses the light
    // and conservative coverage; the settings that miss lights by design
    // (--fixed proxy-overfit=1,auto or conservative=false,true) only when
    // asked for.
    if (p.name == "proxy-level") return {"0", "1", "2"};
    if (p.name == "proxy-overfit") return {"auto"};
    if (p.name == "conservative") return {"true"};
    if (p.name == "proxy-depth") return {"tile"};
    switch (p.type) {
    case ParamType::Choice: return p.choices;
    case ParamType::Bool: return {"false", "true"};
    default: return {p.defaultValue};
    }
}

} // namespace

bool paramAppliesTo(const std::string& name, const CullSettings& s, bool sceneHasSpotLights) {
    // The engine limits apply to every algorithm; their policies only where
    // their limit is set.
    if (name == "overflow-policy") return s.cap || s.maxEntries;
    if (name == "limit-keep") return s.maxLights;
    if (name == "cap" || name == "max-lights" || name == "max-entries") return true;
    // raster's clusters are slices as clustered's, only with proxy-depth slices.
    if (s.algorithm == Algorithm::Raster && (name == "cells" || name == "slicing" || name == "skip-empty") &&
        !s.proxySlices)
        return false;
    return paramAppliesTo(name, s.algorithm, s.cells, sceneHasSpotLights);
}

bool paramAppliesTo(const std::string& name, Algorithm a, std::uint32_t cells, bool sceneHasSpotLights) {
    if (name == "algorithm") return true;
    if (name == "width" || name == "height") return false;
    if (a == Algorithm::All) return false;
    // raster draws proxies: no sphere or spot test; its proxy's settings
    // (the cone's only where a spot light is drawn as one).
    if (a == Algorithm::Raster) {
        if (name == "test" || name == "spot-test") return false;
        if (name == "proxy-segments" || name == "proxy-cone-angle") return sceneHasSpotLights;
        if (name.rfind("proxy-", 0) == 0 || name == "conservative") return true;
    } else if (name.rfind("proxy-", 0) == 0 || name == "conservative") {
        return false;
    }
    if (name.rfind("spot-", 0) == 0) return sceneHasSpotLights;
    // (raster's with proxy-depth slices: the settings' overload decides.)
    const bool slices = a == Algorithm::TwoPointFiveD || a == Algorithm::Clustered || a == Algorithm::Raster;
    if (name == "cells") return slices;
    if (name == "slicing") return slices && cells > 1;
    if (name == "skip-empty") return a == Algorithm::Clustered || a == Algorithm::Raster;
    if (name == "bins") return a == Algorithm::ZBin;
    return true; // tile, test, and parameters added later
}

std::string ReportConfig::label() const {
    if (!customLabel.empty()) return customLabel;
    if (!preset.empty()) return "preset:" + preset;
    std::string s = toString(settings.algorithm);
    for (const ParamSpec& p : cullParams()) {
        if (p.name == "algorithm") continue;
        auto it = params.find(p.name);
        // A limit that is off says nothing.
        if (p.group == "limits" && it != params.end() && it->second == "0") continue;
        if (it != params.end() && !it->second.empty()) s += " " + p.name + "=" + it->second;
    }
    return s;
}

std::vector<ReportConfig> reportConfigs(const ReportOptions& options, const std::string& backend,
                                        bool sceneHasSpotLights) {
    for (const auto& [name, value] : options.fixed) {
        const ParamSpec& p = cullParam(name); // throws for unknown names
        if (!sweptByTable(p)) throw SettingsError(name, "is part of the camera, not swept by the report");
        for (const std::string& v : splitCommas(value)) {
            CullSettings s;
            Camera c;
            setParam(s, c, name, v); // throws for bad (and empty) values
        }
    }
    std::vector<const ParamSpec*> specs;
    for (const ParamSpec& p : cullParams())
        if (sweptByTable(p)) specs.push_back(&p);

    std::vector<ReportConfig> out;
    const ParamSpec& algoSpec = cullParam("algorithm");
    for (const std::string& algoName : sweepValues(algoSpec, options)) {
        const Algorithm algo = algorithmFromString(algoName);
        // Odometer over the other parameters; a parameter that does not apply
        // keeps one (its default) value and an empty column.
        // A parameter that never applies to this algorithm (raster's proxy
        // for the others, bins outside zbin, ...) keeps one value: the
        // odometer would only repeat configurations (3^k times over: the
        // studio's estimate, worked out on every edit, spent seconds so).
        // The limits apply by their own values, whatever the algorithm.
        std::vector<std::vector<std::string>> values;
        for (const ParamSpec* p : specs) {
            std::vector<std::string> v =
                p->name == "algorithm" ? std::vector<std::string>{algoName} : sweepValues(*p, options);
            if (p->group != "limits" && !paramAppliesTo(p->name, algo, 32, sceneHasSpotLights)) v.resize(1);
            values.push_back(std::move(v));
        }
        std::vector<std::size_t> idx(specs.size(), 0);
        std::set<std::string> seen;
        for (;;) {
            ReportConfig cfg;
            cfg.backend = backend;
            Camera cam;
            // What decides where the others apply: the cells, raster's depth
            // and the limits.
            CullSettings probe;
            probe.algorithm = algo;
            for (std::size_t k = 0; k < specs.size(); ++k)
                if (const std::string& n = specs[k]->name; n == "cells" || n == "proxy-depth" || n == "cap" ||
                                                           n == "max-lights" || n == "max-entries")
                    setParam(probe, cam, n, values[k][idx[k]]);
            for (std::size_t k = 0; k < specs.size(); ++k) {
                const ParamSpec& p = *specs[k];
                const bool applies = paramAppliesTo(p.name, probe, sceneHasSpotLights);
                const std::string v = applies ? values[k][idx[k]] : std::string();
                if (applies) setParam(cfg.settings, cam, p.name, v);
                cfg.params[p.name] = v;
            }
            cfg.tileSize = cam.tileSize;
            // Non-applying parameters repeat a configuration: keep it once.
            if (seen.insert(cfg.label()).second) out.push_back(std::move(cfg));
            std::size_t k = 0;
            while (k < specs.size() && ++idx[k] == values[k].size()) idx[k++] = 0;
            if (k == specs.size()) break;
        }
    }
    return out;
}

void markPareto(std::vector<ReportRow>& rows) {
    for (ReportRow& a : rows) {
        a.paretoEfficiency = a.paretoError = a.falseNegatives == 0;
        if (a.falseNegatives) continue;
        for (const ReportRow& b : rows) {
            if (&a == &b || b.falseNegatives || b.config.backend != a.config.backend) continue;
            if (b.totalMs <= a.totalMs && b.efficiency >= a.efficiency &&
                (b.totalMs < a.totalMs || b.efficiency > a.efficiency))
                a.paretoEfficiency = false;
            if (b.totalMs <= a.totalMs && b.imageRmse <= a.imageRmse &&
                (b.totalMs < a.totalMs || b.imageRmse < a.imageRmse))
                a.paretoError = false;
        }
    }
}

namespace {

// What every row of one depth image shares: the all-lights image, each
// pixel's needed lights and the G-buffer (its lists set per row), worked out
// once per backend instead of once per configuration.
struct SweepFrame {
    std::shared_ptr<const DepthImage> depth;
    std::vector<float> allImage;
    std::shared_ptr<const PixelNeeds> needs; // null on a scene too crowded to keep them
    ShadeInputs shadeIn;
};

// (pixel, light) pairs kept for a sweep: 128 MB of light indices at most.
constexpr std::size_t kSweepNeedsEntries = std::size_t(1) << 25;

std::shared_ptr<SweepFrame> sweepFrame(DepthImage depth, const Projection& proj, const ViewLights& lights,
                                       CullBackend& shader, const CancelToken* cancel) {
    auto f = std::make_shared<SweepFrame>();
    f->depth = std::make_shared<const DepthImage>(std::move(depth));
    f->shadeIn = makeShadeInputs(*f->depth, proj, nullptr);
    f->allImage = shader.shade(f->shadeIn, lights, nullptr);
    f->needs = computePixelNeeds(*f->depth, proj, lights, kSweepNeedsEntries, cancel);
    return f;
}

// What judging a row finds: its ground truth's metrics, its shading time and
// image error.
struct Judged {
    Metrics metrics;
    double shadeMs = -1;
    ImageError error;
};

// Rows judged on one backend, by what judging reads: the lists, zbin's bins
// and order, and the list each pixel shades (ShadeInputs::list, and zbin's
// per-pixel lists). A row whose lists equal an earlier row's takes its
// judgement (minmax's lists are 2.5d's with one or two cells, for one).
using JudgedKey = std::array<std::uint64_t, 2>;
JudgedKey judgedKey(const CullResult& r, const ShadeInputs& in) {
    ContentHash h;
    h.addValue(std::uint64_t(r.algorithm == Algorithm::ZBin)).addValue(r.bytes());
    h.add(r.listOffset).add(r.listCount).add(r.lightIndices).add(r.pixelList);
    h.add(r.zbinOrder).add(r.zbinRank).add(r.zbinLo).add(r.zbinHi);
    h.add(&r.zbinNear, sizeof r.zbinNear).add(&r.zbinFar, sizeof r.zbinFar);
    h.add(in.list);
    if (const CullResult* p = in.perPixelLists.get()) h.add(p->listOffset).add(p->listCount).add(p->lightIndices);
    return h.value128();
}

// A row after its timed culls: ground truth, `repeat` timed shades of the
// culled lists on `shader`, and the image error against the all-lights image;
// or, where `judged` holds a row of the same lists, that row's.
// `fullLists`: a custom shader's lists over its layout's capacity.
void judgeRow(ReportRow& row, const std::vector<double>& cullMs, const CullResult& result, const Projection& proj,
              const ViewLights& lights, CullBackend& shader, SweepFrame& frame, const ReportOptions& options,
              const CancelToken* cancel, std::map<JudgedKey, Judged>* judged,
              const std::vector<std::uint32_t>* fullLists = nullptr) {
    const DepthImage& depth = *frame.depth;
    setShadeLists(frame.shadeIn, depth, proj, &result);
    // The limits' misses are told apart by what the cull dropped, which the
    // key does not hold: those rows are judged each.
    const bool shareable = judged && !fullLists && !result.settings.hasLimits();
    const JudgedKey key = shareable ? judgedKey(result, frame.shadeIn) : JudgedKey{};
    const Judged* known = nullptr;
    if (shareable)
        if (const auto it = judged->find(key); it != judged->end()) known = &it->second;
    Judged j;
    if (known) {
        j = *known;
    } else {
        GroundTruthOptions gto;
        gto.imageError = false;
        gto.needs = frame.needs.get();
        gto.fullLists = fullLists;
        j.metrics = computeGroundTruth(depth, proj, lights, result, gto, cancel).metrics;
        std::vector<float> image;
        std::vector<double> shadeMs;
        for (int r = 0; r < options.warmup + options.repeat; ++r) {
            image = shader.shade(frame.shadeIn, lights, &result);
            if (r >= options.warmup) shadeMs.push_back(shader.lastShadeMs());
        }
        j.shadeMs = median(shadeMs);
        j.error = compareShadedImages(depth, image, frame.allImage);
        if (shareable) judged->emplace(key, j);
    }
    row.cullMs = median(cullMs);
    row.shadeMs = j.shadeMs;
    row.totalMs = row.cullMs + row.shadeMs;
    const Metrics& m = j.metrics;
    row.efficiency = m.efficiency;
    row.optimalWork = m.optimalWork;
    row.efficiencyVsOptimal = m.efficiencyVsOptimal;
    row.falseNegatives = m.falseNegatives;
    row.falseNegativesListFull = m.falseNegativesListFull;
    row.falseNegativesLightLimit = m.falseNegativesLightLimit;
    row.overflowLists = result.limits.overflowLists.size();
    row.longestUncapped = result.settings.hasLimits() ? result.limits.longestUncapped : m.maxList;
    row.meanList = m.meanList;
    row.maxList = m.maxList;
    row.resultBytes = m.resultBytes;
    row.imageRmse = j.error.rmse;
    row.imageMaxError = j.error.maxAbs;
}

} // namespace

namespace {

// One row per preset: its settings and grid for this scene and camera.
std::vector<ReportConfig> presetConfigs(const ReportOptions& options, const std::string& backend, const Scene& scene) {
    std::vector<ReportConfig> out;
    for (const std::string& name : options.presets) {
        const EnginePreset& preset = enginePreset(name); // throws for unknown names
        ReportConfig cfg;
        cfg.backend = backend;
        cfg.preset = preset.name;
        Camera cam = scene.camera;
        applyPreset(preset, cfg.settings, cam, scene.lights.size());
        cfg.tileSize = cam.tileSize;
        for (const ParamSpec& p : cullParams())
            if (sweptByTable(p)) cfg.params[p.name] = getParam(cfg.settings, cam, p.name);
        out.push_back(std::move(cfg));
    }
    return out;
}

// The smallest value of `param` in [from, to] at which misses(value) is 0,
// by bisection (the limits only keep more lights as they grow); `to` when
// misses(to) is not 0 either.
std::uint64_t smallestLossless(std::uint64_t from, std::uint64_t to,
                               const std::function<std::uint64_t(std::uint64_t)>& misses) {
    if (from >= to) return to;
    std::uint64_t lo = from, hi = to; // misses(hi) == 0 assumed
    while (lo < hi) {
        const std::uint64_t mid = lo + (hi - lo) / 2;
        if (misses(mid) == 0) hi = mid;
        else lo = mid + 1;
    }
    return hi;
}

// A preset row's misses from its limits: the first setting change that
// removes them, each limit raised to the smallest value that loses nothing
// (the light limit first, then the record buffer, then the cap), with the
// preset's derived settings worked out again for it as the engine would; and
// where the engine does not let that limit go so far, what it does allow.
std::string findFix(const ReportRow& row, const EnginePreset& preset, const Scene& scene, CullBackend& backend,
                    const SweepFrame& frame, const Projection& proj, const ViewLights& lights,
                    const CancelToken* cancel) {
    if (row.falseNegativesListFull == 0 && row.falseNegativesLightLimit == 0)
        return row.falseNegatives ? "none: the misses are the culling test's, not a limit's" : "";
    const DepthImage& depth = *frame.depth;
    GroundTruthOptions gto;
    gto.imageError = false;
    gto.needs = frame.needs.get();
    std::vector<std::pair<std::string, std::string>> over;
    auto cullWith = [&](const std::vector<std::pair<std::string, std::string>>& o) {
        if (cancel && cancel->cancelled.load()) throw Cancelled();
        CullSettings s;
        Camera cam = scene.camera;
        applyPreset(preset, s, cam, scene.lights.size(), o);
        const TileGrid grid = TileGrid::make(cam.width, cam.height, cam.tileSize);
        return backend.cull(depth, proj, grid, lights, s);
    };
    auto metricsWith = [&](const std::vector<std::pair<std::string, std::string>>& o) {
        return computeGroundTruth(depth, proj, lights, cullWith(o), gto, cancel).metrics;
    };
    auto with = [&](const std::string& param, std::uint64_t v) {
        auto o = over;
        o.emplace_back(param, std::to_string(v));
        return o;
    };
    std::string fix;
    const auto add = [&](const std::string& param, std::uint64_t v, std::uint64_t current) {
        const EnginePreset::Room* room = preset.roomFor(param);
        std::string part = param + " " + std::to_string(v);
        if (room && room->most && v > room->most)
            part += room->most <= current
                        ? ": no setting reaches it (" + room->setting + " is fixed at " + std::to_string(room->most) +
                              "): " + (param == "max-lights" ? "keep fewer lights in view" : "keep lists shorter")
                        : ": past what the engine allows (" + room->setting + ": at most " +
                              std::to_string(room->most) + ")";
        else if (room)
            part += " (" + room->setting + ")";
        fix += (fix.empty() ? "" : ", ") + part;
        over.emplace_back(param, std::to_string(v));
    };
    CullSettings s = row.config.settings;
    if (row.falseNegativesLightLimit && s.maxLights) {
        const std::uint64_t v = smallestLossless(s.maxLights + 1, lights.size(), [&](std::uint64_t m) {
            return metricsWith(with("max-lights", m)).falseNegativesLightLimit;
        });
        add("max-lights", v, s.maxLights);
    }
    Metrics m = metricsWith(over);
    if (m.falseNegativesListFull && s.maxEntries) {
        const std::uint64_t need = std::max<std::uint64_t>(cullWith(with("max-entries", 0)).entries(), s.maxEntries + 1);
        const std::uint64_t v = smallestLossless(s.maxEntries + 1, need, [&](std::uint64_t e) {
            return metricsWith(with("max-entries", e)).falseNegativesListFull;
        });
        add("max-entries", v, s.maxEntries);
        m = metricsWith(over);
    }
    if (m.falseNegativesListFull && s.cap) {
        std::uint32_t longest = 0;
        for (std::uint32_t c : cullWith(with("cap", 0)).listCount) longest = std::max(longest, c);
        const std::uint64_t v = smallestLossless(s.cap + 1, std::max<std::uint64_t>(longest, s.cap + 1), [&](std::uint64_t c) {
            return metricsWith(with("cap", c)).falseNegativesListFull;
        });
        add("cap", v, s.cap);
        m = metricsWith(over);
    }
    if (m.falseNegativesListFull || m.falseNegativesLightLimit) fix += " (still " + std::to_string(m.falseNegatives) + " misses)";
    return fix;
}

} // namespace

Report runReport(const Scene& sceneIn, const ReportOptions& options, const ReportProgress& progress,
                 const CancelToken* cancel) {
    sceneIn.validate();
    if (options.repeat < 1 || options.repeat > 1000) throw SettingsError("repeat", "must be in 1..1000");
    if (options.warmup < 0 || options.warmup > 1000) throw SettingsError("warmup", "must be in 0..1000");
    std::vector<std::string> backends;
    // A backend named twice is swept once (twice would double every row and
    // split the Pareto front between the copies).
    for (const std::string& b : options.backends.empty() ? availableBackends() : options.backends)
        if (std::find(backends.begin(), backends.end(), b) == backends.end()) backends.push_back(b);

    Report rep;
    rep.sceneName = sceneIn.name;
    rep.width = sceneIn.camera.width;
    rep.height = sceneIn.camera.height;
    rep.lights = sceneIn.lights.size();
    rep.repeat = options.repeat;
    rep.warmup = options.warmup;
    for (const ParamSpec& p : cullParams())
        if (sweptByTable(p)) rep.paramNames.push_back(p.name);

    const bool hasSpots = sceneIn.hasSpotLights();
    // Open every backend first: the total is known before the first run.
    struct Swept {
        std::unique_ptr<CullBackend> owned; // opened for the sweep (no backendFor)
        CullBackend* backend;
        std::vector<ReportConfig> cfgs;
    };
    std::vector<Swept> work;
    std::size_t total = 0;
    for (const std::string& name : backends) {
        std::unique_ptr<CullBackend> owned;
        CullBackend* b = nullptr;
        try {
            if (options.backendFor) {
                b = &options.backendFor(name);
            } else {
                owned = makeBackend(name, options.device);
                b = owned.get();
            }
        } catch (const Error& e) {
            if (backends.size() == 1) throw;
            rep.notes.push_back(name + ": not run (" + e.what() + ")");
            continue;
        }
        std::vector<ReportConfig> cfgs = options.presets.empty() ? reportConfigs(options, b->name(), hasSpots)
                                                                 : presetConfigs(options, b->name(), sceneIn);
        total += cfgs.size();
        work.push_back({std::move(owned), b, std::move(cfgs)});
    }

    // The custom shaders' tile sizes: each one `--tile` names (the shader
    // gets TILE_SIZE), else the scene camera's.
    std::vector<std::uint32_t> shaderTiles{sceneIn.camera.tileSize};
    if (const auto it = options.fixed.find("tile"); it != options.fixed.end()) {
        shaderTiles.clear();
        for (const std::string& t : splitCommas(it->second))
            if (const std::uint32_t v = std::uint32_t(std::stoul(t));
                std::find(shaderTiles.begin(), shaderTiles.end(), v) == shaderTiles.end())
                shaderTiles.push_back(v);
    }
    total += options.shaders.size() * shaderTiles.size();
    rep.queued = total;
    const ViewLights lights = makeViewLights(sceneIn);
    const Projection proj(sceneIn.camera);
    // Each custom shader runs once first, on the CPU rasteriser's depth: one
    // that does not compile, or fails on its device, fails the report before
    // the sweep rather than after every built-in configuration.
    if (!options.shaders.empty()) {
        const DepthImage probe = rasterizeDepthCpu(sceneIn, proj, cancel);
        const TileGrid grid = TileGrid::make(sceneIn.camera.width, sceneIn.camera.height, sceneIn.camera.tileSize);
        for (const CustomShaderOptions& so : options.shaders) {
            CustomCullReport crep;
            runCustomShader(so, probe, proj, grid, lights, crep);
        }
    }
    std::size_t done = 0;
    // For the custom shaders: the depth, shading backend and all-lights image
    // of the vulkan backend (else the first that ran).
    std::shared_ptr<SweepFrame> shaderFrame;
    CullBackend* shaderShade = nullptr;
    try {
        for (auto& [owned, backend, cfgs] : work) {
            if (cancelled(cancel)) throw Cancelled();
            rep.backendDevices.emplace_back(backend->name(), backend->deviceName());
            rep.backendTiming.emplace_back(backend->name(), backend->timingMethod());
            // Depth does not depend on any swept parameter: one pre-pass, one
            // all-lights image and one G-buffer per backend.
            const std::shared_ptr<SweepFrame> frame =
                sweepFrame(backend->renderDepth(sceneIn, proj), proj, lights, *backend, cancel);
            const DepthImage& depth = *frame->depth;
            std::map<JudgedKey, Judged> judged; // this backend's rows, by their lists
            if (!shaderFrame || backend->name() == "vulkan") {
                shaderFrame = frame;
                shaderShade = backend;
            }
            for (const ReportConfig& cfg : cfgs) {
                if (cancelled(cancel)) throw Cancelled();
                const TileGrid grid =
                    TileGrid::make(sceneIn.camera.width, sceneIn.camera.height, cfg.tileSize);
                ReportRow row;
                row.config = cfg;
                row.device = backend->deviceName();
                std::vector<double> cullMs;
                CullResult result;
                for (int r = 0; r < options.warmup + options.repeat; ++r) {
                    result = backend->cull(depth, proj, grid, lights, cfg.settings);
                    if (r >= options.warmup) cullMs.push_back(result.timings.cullMs);
                }
                if (const std::string bad = result.validate(lights.size()); !bad.empty())
                    throw Error("backend '" + backend->name() + "' produced an inconsistent result for " +
                                cfg.label() + ": " + bad);
                judgeRow(row, cullMs, result, proj, lights, *backend, *frame, options, cancel, &judged);
                if (!cfg.preset.empty())
                    row.fix = findFix(row, enginePreset(cfg.preset), sceneIn, *backend, *frame, proj, lights, cancel);
                rep.rows.push_back(std::move(row));
                ++done;
                if (progress) progress(done, total, cfg.backend + " " + cfg.label());
            }
        }
        for (const CustomShaderOptions& so : options.shaders)
        for (const std::uint32_t tile : shaderTiles) {
            if (cancelled(cancel)) throw Cancelled();
            if (!shaderFrame) throw Error("custom shaders need a backend for the depth pre-pass");
            const TileGrid grid = TileGrid::make(sceneIn.camera.width, sceneIn.camera.height, tile);
            ReportRow row;
            row.config.backend = "vulkan"; // it runs on a Vulkan device: judged beside the vulkan rows
            row.config.tileSize = grid.tileSize;
            // The file's name, or the path as given where two shaders share a name.
            std::string file = std::filesystem::path(so.path).filename().string();
            if (std::count_if(options.shaders.begin(), options.shaders.end(), [&](const CustomShaderOptions& other) {
                    return std::filesystem::path(other.path).filename() == std::filesystem::path(so.path).filename();
                }) > 1)
                file = so.path;
            row.config.params["algorithm"] = "custom:" + file;
            row.config.params["tile"] = std::to_string(grid.tileSize);
            row.config.customLabel = "custom:" + file + " " + toString(so.layout) + " " + toString(so.lists);
            if (shaderTiles.size() > 1) row.config.customLabel += " tile=" + std::to_string(tile);
            std::vector<double> cullMs;
            CullResult result;
            CustomCullReport crep;
            for (int r = 0; r < options.warmup + options.repeat; ++r) {
                crep = CustomCullReport{};
                result = runCustomShader(so, *shaderFrame->depth, proj, grid, lights, crep);
                if (r >= options.warmup) cullMs.push_back(crep.passMs);
            }
            row.device = crep.device;
            judgeRow(row, cullMs, result, proj, lights, *shaderShade, *shaderFrame, options, cancel, nullptr,
                     &crep.overflowedListIds);
            row.overflowLists = crep.overflowLists;
            // What `run` fails a shader for beside its misses, and the
            // layer's first word on it (a binding of the wrong type says why).
            if (crep.overflowLists || crep.invalidIndices || crep.duplicateIndices ||
                !crep.validationMessages.empty()) {
                std::string note = row.config.customLabel + ": " +
                                   countOf(crep.overflowLists, "overflowed list", "overflowed lists") + ", " +
                                   countOf(crep.invalidIndices, "invalid index", "invalid indices") + ", " +
                                   countOf(crep.duplicateIndices, "duplicate index", "duplicate indices") + ", " +
                                   countOf(crep.validationMessages.size(), "validation message", "validation messages");
                if (!crep.validationMessages.empty())
                    note += " (the first: " + validationGist(crep.validationMessages.front()) + ")";
                rep.notes.push_back(note);
            }
            const std::string label = row.config.customLabel;
            rep.rows.push_back(std::move(row));
            ++done;
            if (progress) progress(done, total, label);
        }
    } catch (const Cancelled&) {
        if (!options.partialOnCancel) throw;
        rep.cancelled = true; // the rows finished so far are the report
    }
    // Custom shaders run on a Vulkan device of their own: where no vulkan
    // backend was swept, the header still says which device and clock.
    const auto shaderRow = std::find_if(rep.rows.begin(), rep.rows.end(),
                                        [](const ReportRow& r) { return !r.config.customLabel.empty(); });
    if (shaderRow != rep.rows.end() &&
        std::none_of(rep.backendDevices.begin(), rep.backendDevices.end(), [](const auto& d) { return d.first == "vulkan"; })) {
        rep.backendDevices.emplace_back("vulkan", shaderRow->device + " (the custom shaders)");
        rep.backendTiming.emplace_back("vulkan", "cpu-wall-clock around the shader's dispatch (submit and wait)");
    }
    markPareto(rep.rows);
    return rep;
}

// ---- report.csv ----------------------------------------------------------------

std::string reportCsv(const Report& rep) {
    std::string out = "backend,device";
    for (const std::string& p : rep.paramNames) {
        std::string col = p;
        std::replace(col.begin(), col.end(), '-', '_');
        out += "," + col;
    }
    out += ",cull_ms,shade_ms,total_ms,efficiency,false_negatives,mean_list,max_list,result_bytes,"
           "image_rmse,image_max_error,pareto_efficiency,pareto_error,optimal_work,efficiency_vs_optimal,"
           "fn_list_full,fn_light_limit,overflow_lists,longest_list_uncapped,preset,fix\n";
    auto quoted = [](const std::string& s) {
        if (s.find_first_of(",\"\n") == std::string::npos) return s;
        std::string q = "\"";
        for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
        return q + "\"";
    };
    for (const ReportRow& r : rep.rows) {
        out += r.config.backend + "," + quoted(r.device);
        for (const std::string& p : rep.paramNames) {
            auto it = r.config.params.find(p);
            out += "," + (it == r.config.params.end() ? std::string() : it->second);
        }
        out += "," + roundTrip(r.cullMs) + "," + roundTrip(r.shadeMs) + "," + roundTrip(r.totalMs) + "," +
               roundTrip(r.efficiency) + "," + std::to_string(r.falseNegatives) + "," + roundTrip(r.meanList) + "," +
               std::to_string(r.maxList) + "," + std::to_string(r.resultBytes) + "," + roundTrip(r.imageRmse) + "," +
               roundTrip(r.imageMaxError) + "," + (r.paretoEfficiency ? "1" : "0") + "," +
               (r.paretoError ? "1" : "0") + "," + std::to_string(r.optimalWork) + "," +
               roundTrip(r.efficiencyVsOptimal) + "," + std::to_string(r.falseNegativesListFull) + "," +
               std::to_string(r.falseNegativesLightLimit) + "," + std::to_string(r.overflowLists) + "," +
               std::to_string(r.longestUncapped) + "," + quoted(r.config.preset) + "," + quoted(r.fix) + "\n";
    }
    return out;
}

// ---- report.md -----------------------------------------------------------------

namespace {

std::string describe(const ReportRow& r) {
    return "`" + r.config.label() + "` (" + r.config.backend + ": cull " + fmt("%.3f", r.cullMs) + " ms + shade " +
           fmt("%.3f", r.shadeMs) + " ms = " + fmt("%.3f", r.totalMs) + " ms, efficiency " +
           fmt("%.3f", r.efficiency) + ", image RMSE " + fmt("%.3g", r.imageRmse) + ")";
}

// Per configuration swept over caps: the smallest cap that loses no light
// and what it costs, beside the longest list (the cap that never overflows).
std::string capsSection(const Report& rep) {
    std::map<std::string, std::vector<const ReportRow*>> groups;
    bool anyCap = false;
    for (const ReportRow& r : rep.rows) {
        // A custom shader has no cap to sweep; a preset's cap is the engine's
        // (its row's fix says how far to raise it).
        if (!r.config.customLabel.empty() || !r.config.preset.empty()) continue;
        anyCap = anyCap || r.config.settings.cap > 0;
        ReportConfig uncapped = r.config;
        uncapped.params["cap"] = "0";
        uncapped.params.erase("overflow-policy");
        if (r.config.settings.cap)
            uncapped.params["overflow-policy"] = toString(r.config.settings.overflow);
        groups[r.config.backend + " `" + uncapped.label() + "`"].push_back(&r);
    }
    if (!anyCap) return {};
    std::string md = "\n## Caps\n\nPer configuration, the smallest swept per-list cap that loses no light "
                     "(no false negative from a full list), the bytes an engine allocates for it (a count and `cap` "
                     "indices per list), and the longest list the test made (a cap that never overflows).\n\n";
    for (auto& [key, rows] : groups) {
        std::sort(rows.begin(), rows.end(),
                  [](auto* a, auto* b) { return a->config.settings.cap < b->config.settings.cap; });
        const ReportRow* lossless = nullptr;
        std::uint32_t longest = 0;
        for (const ReportRow* r : rows) {
            longest = std::max(longest, r->longestUncapped);
            if (!lossless && r->config.settings.cap > 0 && r->falseNegativesListFull == 0) lossless = r;
        }
        md += "- " + key + ": ";
        md += lossless ? "cap " + std::to_string(lossless->config.settings.cap) + " loses nothing (" +
                             std::to_string(lossless->resultBytes) + " bytes, " +
                             std::to_string(lossless->overflowLists) + " over-full lists)"
                       : std::string("every swept cap loses lights");
        for (const ReportRow* r : rows)
            if (r->config.settings.cap > 0 && r->falseNegativesListFull > 0)
                md += "; cap " + std::to_string(r->config.settings.cap) + " misses " +
                      std::to_string(r->falseNegativesListFull) + " light-pixels in " +
                      std::to_string(r->overflowLists) + " over-full lists";
        md += "; the longest list is " + std::to_string(longest) + ".\n";
    }
    return md;
}

// The engine presets side by side: misses by cause, what they cost, and the
// first setting change that keeps every light.
std::string presetsSection(const Report& rep) {
    std::string md;
    for (const ReportRow& r : rep.rows) {
        if (r.config.preset.empty()) continue;
        if (md.empty())
            md = "\n## Engine presets\n\nEach preset culls as the engine does (docs/ENGINES.md: the source of "
                 "every number and what the model leaves out). FN = false negatives (light-pixels missed): by the "
                 "culling test, by a full list (cap or record buffer), by the light limit.\n\n"
                 "| backend | preset | engine | settings | FN test / list full / light limit | over-full lists | "
                 "efficiency | bytes | cull ms | to lose nothing |\n|---|---|---|---|---|---:|---:|---:|---:|---|\n";
        const CullSettings& s = r.config.settings;
        std::string set = std::string(toString(s.algorithm)) + " tile " + std::to_string(r.config.tileSize);
        if (s.clusterLists() || s.algorithm == Algorithm::TwoPointFiveD)
            set += " cells " + std::to_string(s.cells) + " " + toString(s.slicing);
        if (s.algorithm == Algorithm::ZBin) set += " bins " + std::to_string(s.bins);
        if (s.cap) set += " cap " + std::to_string(s.cap);
        if (s.maxEntries) set += " max-entries " + std::to_string(s.maxEntries);
        if (s.cap || s.maxEntries) set += " overflow-policy " + std::string(toString(s.overflow));
        if (s.maxLights) set += " max-lights " + std::to_string(s.maxLights) + " keep " + toString(s.limitKeep);
        md += "| " + r.config.backend + " | " + r.config.preset + " | " + enginePreset(r.config.preset).engine + " | " +
              set + " | " + std::to_string(r.falseNegatives - r.falseNegativesListFull - r.falseNegativesLightLimit) +
              " / " + std::to_string(r.falseNegativesListFull) + " / " + std::to_string(r.falseNegativesLightLimit) +
              " | " + std::to_string(r.overflowLists) + " | " +
              (r.falseNegatives ? fmt("(%.4f: not a score with misses)", r.efficiency) : fmt("%.4f", r.efficiency)) +
              " | " +
              std::to_string(r.resultBytes) + " | " + fmt("%.3f", r.cullMs) + " | " +
              (r.fix.empty() ? std::string("loses nothing") : r.fix) + " |\n";
    }
    return md;
}

} // namespace

std::string reportMarkdown(const Report& rep) {
    const auto configurations = [](std::size_t n) { return countOf(n, "configuration", "configurations"); };
    std::string md = "# Culling report: " + rep.sceneName + "\n\n";
    md += std::to_string(rep.width) + "x" + std::to_string(rep.height) + ", " + countOf(rep.lights, "light", "lights") +
          ", " + configurations(rep.rows.size()) + "; times are " +
          (rep.repeat == 1 ? std::string("of 1 run") : "medians of " + std::to_string(rep.repeat) + " runs") +
          " after " + std::to_string(rep.warmup) +
          " untimed. Total = culling pass + shading pass (the depth pre-pass, the "
          "same for every configuration, is not included).\n\n";
    if (rep.cancelled)
        md += "**Partial: cancelled after " + std::to_string(rep.rows.size()) + " of " + configurations(rep.queued) +
              ".**\n\n";
    for (std::size_t i = 0; i < rep.backendDevices.size(); ++i)
        md += "- backend `" + rep.backendDevices[i].first + "`: " + rep.backendDevices[i].second + "; timing: " +
              rep.backendTiming[i].second + "\n";
    for (const std::string& n : rep.notes) md += "- " + n + "\n";
    md += "\n## Reading\n\n";
    if (rep.rows.empty()) {
        md += "No configuration ran.\n";
    } else {
        std::uint64_t fnRows = 0;
        std::string fnNames;
        for (const ReportRow& r : rep.rows)
            if (r.falseNegatives > 0 && fnRows++ < 5)
                fnNames += std::string(fnNames.empty() ? "" : ", ") + "`" + r.config.label() + "` (" + r.config.backend +
                           ", " + std::to_string(r.falseNegatives) + ")";
        md += fnRows == 0 ? "- Every configuration has zero false negatives.\n"
                          : "- **" + std::to_string(fnRows) +
                                (fnRows == 1 ? " configuration has" : " configurations have") +
                                " false negatives** (lights missing where they matter): " +
                                fnNames + (fnRows > 5 ? " and " + std::to_string(fnRows - 5) + " more" : "") +
                                "; they are left off the Pareto fronts and are not ranked below.\n";
        for (const auto& [backend, device] : rep.backendDevices) {
            // Only configurations without false negatives are ranked: one that
            // misses lights is wrong, however fast or tight it looks.
            std::vector<const ReportRow*> rows;
            for (const ReportRow& r : rep.rows)
                if (r.config.backend == backend && r.falseNegatives == 0) rows.push_back(&r);
            if (rows.empty()) {
                md += "- On " + backend + ", no configuration is free of false negatives: none is ranked.\n";
                continue;
            }
            const ReportRow* fastest = *std::min_element(rows.begin(), rows.end(), [](auto* a, auto* b) {
                return a->totalMs < b->totalMs;
            });
            const ReportRow* tightest = *std::max_element(rows.begin(), rows.end(), [](auto* a, auto* b) {
                return a->efficiency < b->efficiency || (a->efficiency == b->efficiency && a->totalMs > b->totalMs);
            });
            const ReportRow* slowest = *std::max_element(rows.begin(), rows.end(), [](auto* a, auto* b) {
                return a->totalMs < b->totalMs;
            });
            md += "- On " + backend + ", the fastest configuration without false negatives is " + describe(*fastest) + "; the slowest takes " +
                  fmt("%.1f", fastest->totalMs > 0 ? slowest->totalMs / fastest->totalMs : 0.0) +
                  "x as long. The most efficient is " + describe(*tightest) + ", at " +
                  fmt("%.1f", 100.0 * tightest->efficiencyVsOptimal) +
                  "% of the best lists its own tiles, cells or froxels allow (efficiency_vs_optimal).\n";
            std::vector<const ReportRow*> front;
            for (const ReportRow* r : rows)
                if (r->paretoEfficiency) front.push_back(r);
            std::sort(front.begin(), front.end(), [](auto* a, auto* b) { return a->totalMs < b->totalMs; });
            md += "- " + backend + " Pareto front, time against efficiency (" + configurations(front.size()) +
                  ", fastest first):";
            for (std::size_t i = 0; i < front.size(); ++i) {
                md += (i ? "; " : " ") + std::string("`") + front[i]->config.label() + "` " +
                      fmt("%.3f", front[i]->totalMs) + " ms / " + fmt("%.3f", front[i]->efficiency);
                if (i)
                    md += " (+" + fmt("%.3f", front[i]->totalMs - front[i - 1]->totalMs) + " ms buys +" +
                          fmt("%.3f", front[i]->efficiency - front[i - 1]->efficiency) + " efficiency)";
            }
            md += ".\n";
            std::size_t errFront = 0;
            for (const ReportRow* r : rows) errFront += r->paretoError;
            md += "- " + backend + " Pareto front, time against image error: " + configurations(errFront) + ".";
            // Shading against culling: where the time goes at the two ends.
            md += " At the fastest configuration culling is " +
                  fmt("%.0f", fastest->totalMs > 0 ? 100.0 * fastest->cullMs / fastest->totalMs : 0.0) +
                  "% of the total; at the most efficient " +
                  fmt("%.0f", tightest->totalMs > 0 ? 100.0 * tightest->cullMs / tightest->totalMs : 0.0) + "%.\n";
            // Best per algorithm.
            md += "- Best total per algorithm on " + backend + ":";
            bool first = true;
            for (const std::string& a : cullParam("algorithm").choices) {
                const ReportRow* best = nullptr;
                for (const ReportRow* r : rows)
                    if (r->config.customLabel.empty() && toString(r->config.settings.algorithm) == a &&
                        (!best || r->totalMs < best->totalMs))
                        best = r;
                if (!best) continue;
                md += (first ? " " : "; ") + a + " " + fmt("%.3f", best->totalMs) + " ms (efficiency " +
                      fmt("%.3f", best->efficiency) + ")";
                first = false;
            }
            // A custom shader is its own row, never one of the built-in algorithms.
            for (const ReportRow* r : rows)
                if (!r->config.customLabel.empty()) {
                    md += (first ? " " : "; ") + std::string("`") + r->config.customLabel + "` " +
                          fmt("%.3f", r->totalMs) + " ms (efficiency " + fmt("%.3f", r->efficiency) + ")";
                    first = false;
                }
            md += ".\n";
        }
    }
    md += capsSection(rep);
    md += presetsSection(rep);
    md += "\n## Table\n\n| backend | configuration | cull ms | shade ms | total ms | efficiency | of optimum | FN | "
          "mean list | max list | bytes | image RMSE | image max | Pareto |\n|---|---|---:|---:|---:|---:|---:|---:|---:|"
          "---:|---:|---:|---:|---|\n";
    for (const ReportRow& r : rep.rows) {
        std::string pareto = r.paretoEfficiency ? "E" : "";
        if (r.paretoError) pareto += pareto.empty() ? "I" : " I";
        md += "| " + r.config.backend + " | " + r.config.label() + " | " + fmt("%.3f", r.cullMs) + " | " +
              fmt("%.3f", r.shadeMs) + " | " + fmt("%.3f", r.totalMs) + " | " + fmt("%.4f", r.efficiency) + " | " +
              fmt("%.3f", r.efficiencyVsOptimal) + " | " + std::to_string(r.falseNegatives) + " | " + fmt("%.2f", r.meanList) + " | " + std::to_string(r.maxList) +
              " | " + std::to_string(r.resultBytes) + " | " + fmt("%.4g", r.imageRmse) + " | " +
              fmt("%.4g", r.imageMaxError) + " | " + pareto + " |\n";
    }
    md += "\nPareto: E = on the time/efficiency front, I = on the time/image-error front (per backend).\n";
    return md;
}

// ---- pareto.png ------------------------------------------------------------------

namespace {

struct Plot {
    RgbImage& img;
    void set(int x, int y, glm::dvec3 c) {
        if (x < 0 || y < 0 || x >= int(img.width) || y >= int(img.height)) return;
        std::uint8_t* p = &img.rgb[(std::size_t(y) * img.width + x) * 3];
        for (int i = 0; i < 3; ++i) p[i] = std::uint8_t(std::lround(std::clamp(c[i], 0.0, 1.0) * 255.0));
    }
    void fill(int x0, int y0, int x1, int y1, glm::dvec3 c) {
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) set(x, y, c);
    }
    void line(int x0, int y0, int x1, int y1, glm::dvec3 c, int w = 1) {
        const int n = std::max(std::abs(x1 - x0), std::abs(y1 - y0));
        for (int i = 0; i <= n; ++i) {
            const double t = n ? double(i) / n : 0.0;
            const int x = int(std::lround(x0 + t * (x1 - x0))), y = int(std::lround(y0 + t * (y1 - y0)));
            fill(x - w / 2, y - w / 2, x - w / 2 + w, y - w / 2 + w, c);
        }
    }
    static int textWidth(const std::string& s, int scale) {
        return s.empty() ? 0 : int(s.size()) * detail::kGlyphAdvance * scale - scale;
    }
    void text(int x, int y, const std::string& s, int scale, glm::dvec3 c) {
        for (char ch : s) {
            const auto& g = detail::glyph5x7(ch);
            for (int r = 0; r < detail::kGlyphHeight; ++r)
                for (int b = 0; b < 5; ++b)
                    if (g.rows[r] & (0x10 >> b))
                        fill(x + b * scale, y + r * scale, x + (b + 1) * scale, y + (r + 1) * scale, c);
            x += detail::kGlyphAdvance * scale;
        }
    }
};

// One scatter panel: x = total ms (log scale when it spans more than 10x),
// y = `yOf`; the Pareto front of each backend joined by a line.
void drawPanel(Plot& p, int x0, int y0, int w, int h, const Report& rep, const std::string& title,
               const std::string& yLabel, double (*yOf)(const ReportRow&), bool (*onFront)(const ReportRow&)) {
    const glm::dvec3 ink(0.1), grid(0.88);
    const int left = x0 + 70, right = x0 + w - 15, top = y0 + 30, bottom = y0 + h - 45;
    p.text(x0 + (w - Plot::textWidth(title, 2)) / 2, y0 + 6, title, 2, ink);
    double xmin = 1e300, xmax = -1e300, ymin = 0, ymax = -1e300;
    for (const ReportRow& r : rep.rows) {
        if (!(r.totalMs > 0) || !std::isfinite(yOf(r))) continue;
        xmin = std::min(xmin, r.totalMs), xmax = std::max(xmax, r.totalMs);
        ymin = std::min(ymin, yOf(r)), ymax = std::max(ymax, yOf(r));
    }
    if (!(xmin <= xmax)) xmin = 0.1, xmax = 1;
    if (!(ymax > ymin)) ymax = ymin + 1;
    const bool logX = xmax > 10 * xmin;
    const AxisTicks xa = axisTicks(logX ? xmin : 0.0, xmax, logX), ya = axisTicks(ymin, ymax, false);
    const double lx0 = logX ? std::log10(xa.lo) : xa.lo, lx1 = logX ? std::log10(xa.hi) : xa.hi;
    auto px = [&](double ms) {
        const double t = logX ? (std::log10(ms) - lx0) / (lx1 - lx0) : (ms - lx0) / (lx1 - lx0);
        return left + int(std::lround(t * (right - left)));
    };
    auto py = [&](double v) { return bottom - int(std::lround((v - ya.lo) / (ya.hi - ya.lo) * (bottom - top))); };
    // Grid and ticks, each at its own value.
    for (double v : ya.ticks) {
        const int y = py(v);
        p.line(left, y, right, y, grid);
        const std::string t = tickText(v);
        p.text(left - 6 - Plot::textWidth(t, 1), y - 3, t, 1, ink);
    }
    for (double v : xa.ticks) {
        const int x = px(v);
        p.line(x, top, x, bottom, grid);
        const std::string t = tickText(v);
        p.text(x - Plot::textWidth(t, 1) / 2, bottom + 6, t, 1, ink);
    }
    p.line(left, top, left, bottom, ink);
    p.line(left, bottom, right, bottom, ink);
    const std::string xl = std::string("TOTAL MS = CULL + SHADE") + (logX ? " (LOG SCALE)" : "");
    p.text(left + (right - left - Plot::textWidth(xl, 1)) / 2, bottom + 20, xl, 1, ink);
    p.text(x0 + 4, top - 14, yLabel, 1, ink);
    // Fronts first (under the points), per backend.
    for (const auto& [backend, device] : rep.backendDevices) {
        std::vector<const ReportRow*> front;
        for (const ReportRow& r : rep.rows)
            if (r.config.backend == backend && onFront(r) && r.totalMs > 0) front.push_back(&r);
        std::sort(front.begin(), front.end(), [](auto* a, auto* b) { return a->totalMs < b->totalMs; });
        for (std::size_t i = 1; i < front.size(); ++i)
            p.line(px(front[i - 1]->totalMs), py(yOf(*front[i - 1])), px(front[i]->totalMs), py(yOf(*front[i])),
                   glm::dvec3(0.85, 0.1, 0.1), 2);
    }
    std::size_t customDrawn = 0;
    for (const ReportRow& r : rep.rows) {
        if (!(r.totalMs > 0) || !std::isfinite(yOf(r))) continue;
        const int x = px(r.totalMs), y = py(yOf(r));
        if (!r.config.customLabel.empty()) {
            // A custom shader: a cross in its own colour, named beside it
            // (and its false negatives, which keep it off the front).
            const glm::dvec3 c(0.55, 0.0, 0.6);
            if (onFront(r)) p.fill(x - 6, y - 6, x + 7, y + 7, glm::dvec3(0.85, 0.1, 0.1));
            p.line(x - 5, y - 5, x + 5, y + 5, c, 2);
            p.line(x - 5, y + 5, x + 5, y - 5, c, 2);
            std::string name = r.config.params.count("algorithm") ? r.config.params.at("algorithm").substr(7) : "custom";
            if (r.falseNegatives) name += " FN " + std::to_string(r.falseNegatives);
            // Labels of nearby shaders would overlap: each one its own line.
            const int line = int(customDrawn++ % 3) - 1;
            p.line(x + 5, y, x + 8, y - 3 + 11 * line + 3, c, 1);
            p.text(x + 9, y - 3 + 11 * line, name, 1, c);
            continue;
        }
        const glm::dvec3 c = algorithmColour(r.config.settings.algorithm);
        const bool second = !rep.backendDevices.empty() && r.config.backend != rep.backendDevices.front().first;
        if (onFront(r)) p.fill(x - 5, y - 5, x + 6, y + 6, glm::dvec3(0.85, 0.1, 0.1));
        if (r.falseNegatives) {
            // Misses lights: a cross, not a square (its efficiency is no
            // score, and it never joins the front).
            p.line(x - 4, y - 4, x + 4, y + 4, c, second ? 1 : 2);
            p.line(x - 4, y + 4, x + 4, y - 4, c, second ? 1 : 2);
            continue;
        }
        if (second) { // hollow square: the second backend
            p.fill(x - 3, y - 3, x + 4, y + 4, c);
            p.fill(x - 1, y - 1, x + 2, y + 2, glm::dvec3(1.0));
        } else {
            p.fill(x - 3, y - 3, x + 4, y + 4, c);
        }
    }
}

} // namespace

std::string tickText(double v) {
    if (v == 0) return "0";
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

AxisTicks axisTicks(double lo, double hi, bool log, int target) {
    AxisTicks a;
    if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi)) hi = lo + 1;
    if (log && lo > 0) {
        const int d0 = int(std::floor(std::log10(lo) + 1e-9)), d1 = int(std::ceil(std::log10(hi) - 1e-9));
        a.lo = std::pow(10.0, d0), a.hi = std::pow(10.0, std::max(d1, d0 + 1));
        const bool onlyDecades = d1 - d0 > 3;
        for (int d = d0; d <= std::max(d1, d0 + 1); ++d)
            for (double m : {1.0, 2.0, 5.0}) {
                if (onlyDecades && m != 1.0) continue;
                const double v = m * std::pow(10.0, d);
                if (v <= a.hi * (1 + 1e-9)) a.ticks.push_back(v);
            }
        return a;
    }
    const double raw = (hi - lo) / std::max(target, 1);
    const double mag = std::pow(10.0, std::floor(std::log10(raw)));
    // The round step nearest the raw one (in ratio).
    double step = mag;
    for (double m : {2.0, 5.0, 10.0})
        if (std::abs(std::log(m * mag / raw)) < std::abs(std::log(step / raw))) step = m * mag;
    const long k0 = long(std::floor(lo / step + 1e-9)), k1 = long(std::ceil(hi / step - 1e-9));
    a.lo = double(k0) * step, a.hi = double(std::max(k1, k0 + 1)) * step;
    for (long k = k0; k <= std::max(k1, k0 + 1); ++k) {
        // Rounded to the step's decimals, so that 3 * 0.1 is 0.3.
        const double scale = std::pow(10.0, std::max(0.0, -std::floor(std::log10(step))));
        a.ticks.push_back(std::round(double(k) * step * scale) / scale);
    }
    return a;
}

RgbImage paretoImage(const Report& rep) {
    const int panelW = 560, panelH = 420, legendH = 60;
    RgbImage img;
    img.width = 2 * panelW;
    img.height = panelH + legendH;
    img.rgb.assign(std::size_t(img.width) * img.height * 3, 255);
    Plot p{img};
    drawPanel(p, 0, 0, panelW, panelH, rep, "TIME VS EFFICIENCY", "EFFICIENCY E/W",
              [](const ReportRow& r) { return r.efficiency; }, [](const ReportRow& r) { return r.paretoEfficiency; });
    drawPanel(p, panelW, 0, panelW, panelH, rep, "TIME VS IMAGE ERROR", "IMAGE RMSE",
              [](const ReportRow& r) { return r.imageRmse; }, [](const ReportRow& r) { return r.paretoError; });
    // Legend: algorithms, backends, the front.
    const glm::dvec3 ink(0.1);
    int x = 20, y = panelH + 10;
    for (const std::string& a : cullParam("algorithm").choices) {
        p.fill(x, y, x + 9, y + 9, algorithmColour(algorithmFromString(a)));
        p.text(x + 14, y + 1, a, 1, ink);
        x += 14 + Plot::textWidth(a, 1) + 24;
    }
    if (std::any_of(rep.rows.begin(), rep.rows.end(), [](const ReportRow& r) { return !r.config.customLabel.empty(); })) {
        p.line(x, y, x + 9, y + 9, glm::dvec3(0.55, 0.0, 0.6), 2);
        p.line(x, y + 9, x + 9, y, glm::dvec3(0.55, 0.0, 0.6), 2);
        p.text(x + 14, y + 1, "CUSTOM SHADER", 1, ink);
        x += 14 + Plot::textWidth("CUSTOM SHADER", 1) + 24;
    }
    p.fill(x, y - 1, x + 11, y + 10, glm::dvec3(0.85, 0.1, 0.1));
    p.fill(x + 2, y + 1, x + 9, y + 8, glm::dvec3(0.3));
    p.text(x + 16, y + 1, "PARETO FRONT (LINE JOINS IT)", 1, ink);
    x = 20, y += 22;
    if (std::any_of(rep.rows.begin(), rep.rows.end(),
                    [](const ReportRow& r) { return r.falseNegatives && r.config.customLabel.empty(); })) {
        p.line(x, y, x + 9, y + 9, glm::dvec3(0.3), 2);
        p.line(x, y + 9, x + 9, y, glm::dvec3(0.3), 2);
        p.text(x + 14, y + 1, "MISSES LIGHTS (FALSE NEGATIVES)", 1, ink);
        x += 14 + Plot::textWidth("MISSES LIGHTS (FALSE NEGATIVES)", 1) + 24;
    }
    for (std::size_t i = 0; i < rep.backendDevices.size(); ++i) {
        p.fill(x, y, x + 9, y + 9, glm::dvec3(0.3));
        if (i > 0) p.fill(x + 2, y + 2, x + 7, y + 7, glm::dvec3(1.0));
        const std::string t = rep.backendDevices[i].first + (i ? " (HOLLOW)" : " (FILLED)");
        p.text(x + 14, y + 1, t, 1, ink);
        x += 14 + Plot::textWidth(t, 1) + 24;
    }
    const std::string info = rep.sceneName + " " + std::to_string(rep.width) + "X" + std::to_string(rep.height) +
                             " " + std::to_string(rep.lights) + " LIGHTS";
    p.text(int(img.width) - 20 - Plot::textWidth(info, 1), y + 1, info, 1, ink);
    return img;
}

// ---- the folder ------------------------------------------------------------------


namespace {
// What a report folder holds: an older report is replaced, anything else refused.
const std::set<std::string> kReportOutputs = {"report.csv", "report.md", "pareto.png"};
} // namespace

void checkReportFolder(const std::string& dir) {
    checkFolderTarget(dir, kReportOutputs, "write the report", "report output");
}

void writeReport(const Report& rep, const std::string& dir) {
    writeFolderAtomic(dir, kReportOutputs, "write the report", "report output",
                      [&](const std::string& out) {
                          const fs::path tmp = out;
                          writeFileSynced((tmp / "report.csv").string(), reportCsv(rep));
                          writeFileSynced((tmp / "report.md").string(), reportMarkdown(rep));
                          writePng(paretoImage(rep), (tmp / "pareto.png").string());
                      });
}

glm::dvec3 algorithmColour(Algorithm a) {
    // Okabe-Ito's colours, then its vermillion, a grey and a brown: nine
    // algorithms, nine colours, none of them the Pareto front's red.
    static const glm::dvec3 k[] = {{0.0, 0.0, 0.0},    {0.90, 0.62, 0.0},  {0.34, 0.71, 0.91},
                                   {0.0, 0.62, 0.45},  {0.80, 0.47, 0.65}, {0.0, 0.45, 0.70},
                                   {0.84, 0.37, 0.0},  {0.55, 0.55, 0.55}, {0.55, 0.35, 0.17}};
    static_assert(sizeof k / sizeof k[0] == std::size_t(Algorithm::Raster) + 1, "a colour per algorithm");
    return k[std::min<std::size_t>(std::size_t(a), std::size(k) - 1)];
}

} // namespace lc
