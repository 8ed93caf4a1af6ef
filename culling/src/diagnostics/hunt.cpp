// The hunt: random small trials judged by ground truth, and the shrinking of
// the first failing one (culling/diagnostics/hunt.hpp).
#include "culling/diagnostics/hunt.hpp"

#include "culling/core/errors.hpp"
#include "culling/core/file_io.hpp"
#include "culling/diagnostics/export.hpp"
#include "culling/math/projection.hpp"
#include "culling/scene/gltf_io.hpp"
#include "culling/scene/scene_io.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>
#include <sstream>

namespace fs = std::filesystem;

namespace lc {

namespace {

constexpr double kPi = 3.14159265358979323846;

// splitmix64: a trial's numbers depend only on (seed, index), the same on
// every machine (no std distributions).
struct Rng {
    std::uint64_t s;
    std::uint64_t next() {
        std::uint64_t z = (s += 0x9e3779b97f4a7c15ull);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return z ^ (z >> 31);
    }
    double uniform() { return double(next() >> 11) * 0x1.0p-53; }          // [0, 1)
    double uniform(double a, double b) { return a + (b - a) * uniform(); }
    double logUniform(double a, double b) { return a * std::pow(b / a, uniform()); }
    std::uint32_t below(std::uint32_t n) { return std::uint32_t(next() % n); } // [0, n)
    bool chance(double p) { return uniform() < p; }
    glm::dvec3 unitVector() {
        const double z = uniform(-1, 1), a = uniform(0, 2 * kPi), r = std::sqrt(std::max(0.0, 1 - z * z));
        return {r * std::cos(a), r * std::sin(a), z};
    }
};

std::uint64_t mix(std::uint64_t a, std::uint64_t b) {
    Rng r{a ^ (b * 0xd1b54a32d192ed03ull)};
    r.next();
    return r.next();
}

void addBox(Mesh& m, glm::dvec3 lo, glm::dvec3 hi) {
    const auto base = std::uint32_t(m.vertexCount());
    for (int i = 0; i < 8; ++i) {
        m.positions.push_back(float(i & 1 ? hi.x : lo.x));
        m.positions.push_back(float(i & 2 ? hi.y : lo.y));
        m.positions.push_back(float(i & 4 ? hi.z : lo.z));
    }
    // Corner index = x + 2y + 4z; each quad counter-clockwise seen from outside.
    static const std::uint32_t quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                              {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    for (const auto& q : quads)
        for (std::uint32_t t : {q[0], q[1], q[2], q[0], q[2], q[3]}) m.indices.push_back(base + t);
}

void addGround(Mesh& m, double half) {
    const auto base = std::uint32_t(m.vertexCount());
    for (int i = 0; i < 4; ++i) {
        m.positions.push_back(float(i & 1 ? half : -half));
        m.positions.push_back(0.0f);
        m.positions.push_back(float(i & 2 ? half : -half));
    }
    for (std::uint32_t t : {0u, 2u, 3u, 0u, 3u, 1u}) m.indices.push_back(base + t); // facing +y
}

// A UV sphere: `rings` bands of `segments` quads, poles as fans; outward
// counter-clockwise faces (a closed solid).
void addSphere(Mesh& m, glm::dvec3 c, double radius, std::uint32_t rings, std::uint32_t segments) {
    const auto base = std::uint32_t(m.vertexCount());
    auto push = [&](glm::dvec3 p) {
        for (int k = 0; k < 3; ++k) m.positions.push_back(float(p[k]));
    };
    push(c + glm::dvec3(0, radius, 0)); // north pole: vertex 0
    for (std::uint32_t i = 1; i < rings; ++i) {
        const double th = kPi * double(i) / double(rings);
        for (std::uint32_t j = 0; j < segments; ++j) {
            const double ph = 2 * kPi * double(j) / double(segments);
            push(c + radius * glm::dvec3(std::sin(th) * std::cos(ph), std::cos(th), -std::sin(th) * std::sin(ph)));
        }
    }
    push(c - glm::dvec3(0, radius, 0)); // south pole
    const std::uint32_t south = base + 1 + (rings - 1) * segments;
    auto ring = [&](std::uint32_t i, std::uint32_t j) { return base + 1 + (i - 1) * segments + j % segments; };
    for (std::uint32_t j = 0; j < segments; ++j) {
        for (std::uint32_t t : {base, ring(1, j), ring(1, j + 1)}) m.indices.push_back(t);
        for (std::uint32_t i = 1; i + 1 < rings; ++i)
            for (std::uint32_t t : {ring(i, j), ring(i + 1, j), ring(i + 1, j + 1), ring(i, j), ring(i + 1, j + 1),
                                    ring(i, j + 1)})
                m.indices.push_back(t);
        for (std::uint32_t t : {ring(rings - 1, j), south, ring(rings - 1, j + 1)}) m.indices.push_back(t);
    }
}

// A sliver: a long triangle a thousandth as wide, both faces (a thin pole
// or wire that covers a tile in a few pixels, or none at its centre).
void addSliver(Mesh& m, glm::dvec3 a, glm::dvec3 b, glm::dvec3 across) {
    const auto base = std::uint32_t(m.vertexCount());
    for (const glm::dvec3& p : {a, b, a + across})
        for (int k = 0; k < 3; ++k) m.positions.push_back(float(p[k]));
    for (std::uint32_t t : {0u, 1u, 2u, 0u, 2u, 1u}) m.indices.push_back(base + t);
}

double diagonalOf(const Scene& s) {
    const auto [lo, hi] = s.bounds();
    return std::max(glm::length(hi - lo), 1e-3);
}

glm::dvec3 pointIn(Rng& r, glm::dvec3 lo, glm::dvec3 hi) {
    return {r.uniform(lo.x, hi.x), r.uniform(lo.y, hi.y), r.uniform(lo.z, hi.z)};
}

PointLight randomLight(Rng& r, const Scene& s, const std::vector<PointLight>& earlier, bool spots, double diag) {
    const auto [lo, hi] = s.bounds();
    const glm::dvec3 centre = 0.5 * (lo + hi);
    const Camera& c = s.camera;
    const glm::dvec3 eye = c.position, dir = glm::normalize(c.target - c.position);
    PointLight l;
    l.explicitRadius = r.logUniform(diag * 2e-3, diag * 1.5);
    const double where = r.uniform();
    if (where < 0.35) {
        l.position = pointIn(r, lo - 0.05 * diag, hi + 0.05 * diag);
    } else if (where < 0.6) { // in view, at some depth
        l.position = eye + dir * r.logUniform(1e-3 * diag, 2 * diag) + r.unitVector() * r.uniform(0, 0.3 * diag);
    } else if (where < 0.72) { // behind the camera
        l.position = eye - dir * r.logUniform(1e-3 * diag, diag) + r.unitVector() * r.uniform(0, 0.2 * diag);
    } else if (where < 0.84) { // around the near plane: its sphere crosses it
        const double d = c.nearPlane * r.uniform(0.2, 3.0);
        l.position = eye + dir * d + r.unitVector() * r.uniform(0, 0.05 * diag);
        l.explicitRadius = std::max(l.explicitRadius, c.nearPlane * r.uniform(0.5, 4.0));
    } else if (where < 0.92 && !earlier.empty()) { // coincident with another light
        l.position = earlier[r.below(std::uint32_t(earlier.size()))].position;
    } else { // far away
        l.position = centre + r.unitVector() * diag * r.uniform(1.0, 5.0);
    }
    l.intensity = r.uniform(1, 10);
    l.color = {r.uniform(0.2, 1), r.uniform(0.2, 1), r.uniform(0.2, 1)};
    if (spots && r.chance(0.35)) {
        l.kind = LightKind::Spot;
        const double a = r.uniform();
        l.outerAngleDeg = a < 0.2 ? 90.0 : a < 0.35 ? r.uniform(80, 90) : r.uniform(1, 90);
        l.innerAngleDeg = r.chance(0.2) ? l.outerAngleDeg : r.uniform(0, l.outerAngleDeg);
        const double d = r.uniform();
        l.direction = d < 0.15 ? dir : d < 0.25 ? -dir : r.unitVector();
    }
    return l;
}

} // namespace

unsigned parseHuntDims(const std::string& text) {
    static const std::pair<const char*, unsigned> names[] = {
        {"camera", HuntCamera}, {"projection", HuntProjection}, {"screen", HuntScreen},
        {"lights", HuntLights}, {"spots", HuntSpots},           {"scene", HuntSceneDim},
        {"all", HuntAll}};
    unsigned dims = 0;
    std::stringstream in(text);
    for (std::string word; std::getline(in, word, ',');) {
        bool known = false;
        for (const auto& [name, bit] : names)
            if (word == name) dims |= bit, known = true;
        if (!known)
            throw SettingsError("vary", "unknown dimension '" + word +
                                            "' (camera, projection, screen, lights, spots, scene, all)");
    }
    return dims;
}

std::string huntDimsToString(unsigned dims) {
    static const std::pair<const char*, unsigned> names[] = {
        {"camera", HuntCamera}, {"projection", HuntProjection}, {"screen", HuntScreen},
        {"lights", HuntLights}, {"spots", HuntSpots},           {"scene", HuntSceneDim}};
    std::string s;
    for (const auto& [name, bit] : names)
        if (dims & bit) s += (s.empty() ? "" : ",") + std::string(name);
    return s.empty() ? "nothing" : s;
}

std::string HuntCoverage::text() const {
    std::ostringstream o;
    o << orthographic << " orthographic, " << reversedZ << " reversed-Z (" << infiniteFar << " infinite far), "
      << glDepth << " GL depth, " << nonMultipleScreens << " non-multiple screens (" << tinyScreens << " tiny), "
      << cameraInsideBounds << " camera inside the scene, " << spotTrials << " with spots (" << wideSpots
      << " with a cone wider than 90 degrees), " << crowds << " crowds of 33+ lights, " << lightsBehindCamera << " lights behind the camera, " << lightsCrossingNear
      << " crossing the near plane, " << lightsLargerThanScene << " larger than the scene, " << generatedScenes
      << " generated scenes, " << emptyViews << " seeing no geometry";
    if (overCapacity) o << ", " << overCapacity << " over capacity (not failures)";
    return o.str();
}

Scene makeHuntScene(std::uint64_t seed) {
    Rng r{mix(seed, 0x5ce4e)};
    Scene s;
    s.name = "hunt-" + std::to_string(seed);
    Mesh m;
    m.name = "generated";
    addGround(m, 12.0);
    const std::uint32_t boxes = 1 + r.below(6);
    for (std::uint32_t i = 0; i < boxes; ++i) {
        const glm::dvec3 c{r.uniform(-9, 9), 0, r.uniform(-9, 9)};
        const glm::dvec3 half{r.logUniform(0.15, 2.0), r.logUniform(0.1, 2.5), r.logUniform(0.15, 2.0)};
        const double lift = r.chance(0.25) ? r.uniform(0.5, 3.0) : 0.0; // some float above the ground
        addBox(m, {c.x - half.x, lift, c.z - half.z}, {c.x + half.x, lift + 2 * half.y, c.z + half.z});
    }
    // Spheres and slivers from numbers of their own: the boxes and lights of
    // a seed stay what they were.
    Rng g{mix(seed, 0x5b4e7e)};
    for (std::uint32_t i = g.below(3); i > 0; --i) {
        const double radius = g.logUniform(0.2, 2.0);
        addSphere(m, {g.uniform(-9, 9), radius + (g.chance(0.3) ? g.uniform(0.2, 2) : 0.0), g.uniform(-9, 9)}, radius,
                  4 + g.below(8), 6 + g.below(12));
    }
    for (std::uint32_t i = g.below(4); i > 0; --i) {
        const glm::dvec3 a{g.uniform(-10, 10), g.uniform(0, 4), g.uniform(-10, 10)};
        const glm::dvec3 along = g.unitVector() * g.uniform(2, 12);
        glm::dvec3 side = glm::cross(along, g.unitVector());
        if (!(glm::length(side) > 1e-6 * glm::length(along))) side = glm::cross(along, glm::dvec3(0, 1, 0));
        if (!(glm::length(side) > 1e-6 * glm::length(along))) side = glm::cross(along, glm::dvec3(1, 0, 0));
        addSliver(m, a, a + along, glm::normalize(side) * (1e-3 * glm::length(along)));
    }
    s.meshes.push_back(std::move(m));
    s.camera.position = {0, 6, 16};
    s.camera.target = {0, 0.5, 0};
    s.camera.width = 160;
    s.camera.height = 96;
    s.camera.tileSize = 16;
    s.camera.nearPlane = 0.1;
    s.camera.farPlane = 100;
    for (int i = 0; i < 8; ++i) s.lights.push_back(randomLight(r, s, s.lights, false, diagonalOf(s)));
    return s;
}

Scene makeHuntTrial(const Scene* base, std::uint64_t seed, std::uint64_t index, unsigned vary) {
    Rng r{mix(seed, index + 1)};
    Scene s = base ? *base : makeHuntScene((vary & HuntSceneDim) ? mix(seed, ~index) : seed);
    s.origin = {};
    s.name = (base ? base->name : std::string("hunt")) + "-trial-" + std::to_string(index);
    const auto [lo, hi] = s.bounds();
    const glm::dvec3 centre = 0.5 * (lo + hi);
    const double diag = diagonalOf(s);
    Camera& c = s.camera;

    if (vary & HuntCamera) {
        if (r.chance(0.25)) {
            c.position = pointIn(r, lo, hi) + glm::dvec3(0, r.uniform(0.05, 0.3) * diag * 0.2, 0);
        } else {
            glm::dvec3 d = r.unitVector();
            if (r.chance(0.8)) d.y = std::abs(d.y); // mostly from above the ground
            c.position = centre + d * diag * r.uniform(0.3, 2.0);
        }
        const double t = r.uniform();
        if (t < 0.4 || s.lights.empty())
            c.target = centre + r.unitVector() * r.uniform(0, 0.1 * diag);
        else if (t < 0.55)
            c.target = s.lights[r.below(std::uint32_t(s.lights.size()))].position;
        else if (t < 0.8) // a corner of the bounds: geometry edges
            c.target = {r.chance(0.5) ? lo.x : hi.x, r.chance(0.5) ? lo.y : hi.y, r.chance(0.5) ? lo.z : hi.z};
        else
            c.target = pointIn(r, lo, hi);
        if (glm::length(c.target - c.position) < 1e-6 * diag) c.target = c.position + glm::dvec3(0, 0, -1);
        c.up = {0, 1, 0};
        const glm::dvec3 view = glm::normalize(c.target - c.position);
        if (glm::length(glm::cross(view, c.up)) < 1e-3) c.up = {1, 0, 0};
    }
    if (vary & HuntProjection) {
        const std::uint32_t k = r.below(8); // perspective kinds twice as often as orthographic
        static const ProjectionKind kinds[8] = {
            ProjectionKind::Perspective, ProjectionKind::Perspective,   ProjectionKind::PerspectiveGL,
            ProjectionKind::ReversedZ,   ProjectionKind::ReversedZ,     ProjectionKind::PerspectiveGL,
            ProjectionKind::Orthographic, ProjectionKind::OrthographicGL};
        c.projection = kinds[k];
        const double f = r.uniform();
        c.fovYDeg = f < 0.1 ? r.uniform(0.5, 5) : f < 0.2 ? r.uniform(140, 175) : r.uniform(20, 120);
        c.orthoHeight = r.logUniform(0.05 * diag, 1.5 * diag);
        const double dist = glm::length(centre - c.position);
        c.nearPlane = r.logUniform(1e-4 * diag, 0.3 * std::max(dist, 0.1 * diag));
        const double far = r.uniform();
        if (c.projection == ProjectionKind::ReversedZ && far < 0.5)
            c.farPlane = std::numeric_limits<double>::infinity();
        else if (far < 0.2) // a far plane that cuts the scene
            c.farPlane = c.nearPlane + r.uniform(0.1, 1.0) * (dist + 0.5 * diag);
        else
            c.farPlane = c.nearPlane + (dist + diag) * r.uniform(1.0, 50.0);
    }
    if (vary & HuntScreen) {
        static const std::uint32_t tiles[4] = {8, 16, 16, 32};
        c.tileSize = tiles[r.below(4)];
        auto side = [&](std::uint32_t maxSide) -> std::uint32_t {
            const double u = r.uniform();
            if (u < 0.12) return 1 + r.below(24);                                           // tiny
            if (u < 0.45) return c.tileSize * (1 + r.below(std::max(1u, maxSide / c.tileSize))); // whole tiles
            return 1 + r.below(maxSide);
        };
        c.width = side(400);
        c.height = side(300);
    }
    // One trial in ten is a crowd (its own numbers, so the other trials stay
    // as they were): 33..300 lights around the camera's target, wide enough
    // to reach the geometry there together, so that lists need more lights
    // than a limit a shader keeps below its declared capacity.
    Rng crowd{mix(seed ^ 0xc40dull, index + 1)};
    if ((vary & HuntLights) && crowd.chance(0.1)) {
        s.lights.clear();
        const auto n = std::uint32_t(crowd.logUniform(33, 301));
        const glm::dvec3 at = c.target;
        for (std::uint32_t i = 0; i < n; ++i) {
            PointLight l = randomLight(crowd, s, s.lights, vary & HuntSpots, diag);
            l.position = at + crowd.unitVector() * crowd.uniform(0, 0.05 * diag);
            l.explicitRadius = crowd.logUniform(0.2, 0.6) * diag;
            s.lights.push_back(l);
        }
    } else if (vary & HuntLights) {
        s.lights.clear();
        const std::uint32_t n = r.chance(0.3) ? 1 + r.below(4) : 1 + r.below(32);
        for (std::uint32_t i = 0; i < n; ++i) s.lights.push_back(randomLight(r, s, s.lights, vary & HuntSpots, diag));
    } else if (vary & HuntSpots) {
        for (PointLight& l : s.lights) {
            if (!r.chance(0.35)) continue;
            l.kind = LightKind::Spot;
            l.outerAngleDeg = r.chance(0.3) ? 90.0 : r.uniform(1, 90);
            l.innerAngleDeg = r.uniform(0, l.outerAngleDeg);
            l.direction = r.unitVector();
        }
    }
    // Generated lights are named by index; a given scene's keep their names
    // (the verdict then names the user's light, even after shrinking).
    if (!base || (vary & HuntLights))
        for (std::size_t i = 0; i < s.lights.size(); ++i) s.lights[i].name = "L" + std::to_string(i);
    if (const std::string bad = c.validate(); !bad.empty()) throw Error("hunt: generated an invalid camera: " + bad);
    return s;
}

CullSettings huntSettings(const HuntOptions& options, Scene& scene) {
    if (!options.preset) return options.settings;
    CullSettings s;
    applyPreset(*options.preset, s, scene.camera, scene.lights.size(), options.presetOverrides);
    return s;
}

HuntVerdict judgeHuntTrial(const Scene& sceneIn, const HuntOptions& options, CullBackend& backend, RunOutput* runOut) {
    sceneIn.validate();
    // With a preset, the trial's own settings and tile size (a copy: the
    // trial's scene stays the searched one).
    std::optional<Scene> derived;
    if (options.preset && !options.shader) derived = sceneIn;
    const Scene& scene = derived ? *derived : sceneIn;
    const CullSettings settings = derived ? huntSettings(options, *derived) : options.settings;
    HuntVerdict v;
    RunOptions ro;
    ro.truthOptions.imageError = false;
    RunOutput run;
    try {
        if (options.shader) {
            CustomCullReport report;
            run = runCustomPipeline(scene, *options.shader, backend, ro, report);
        } else {
            run = runPipeline(scene, settings, backend, ro);
        }
    } catch (const SettingsError&) {
        throw;
    } catch (const InputError&) {
        throw; // the user's file (a shader that does not compile): no trial can pass, nothing to shrink
    } catch (const Error& e) {
        v.fails = true;
        v.property = std::string("error: ") + e.what();
        return v;
    }
    v.falseNegatives = run.truthComputed ? run.truth.metrics.falseNegatives : 0;
    v.geometryPixels = run.truthComputed ? run.truth.metrics.geometryPixels : 0;
    v.invalidIndices = run.custom ? run.custom->invalidIndices : 0;
    // A custom shader's lists past its layout's capacity, or a built-in
    // algorithm's engine limits (--cap, --max-entries, --max-lights): their
    // drops are what the limits model, counted apart unless --overflow.
    v.overflowLists = run.custom ? run.custom->overflowLists : run.result.limits.overflowLists.size();
    v.overCapacity = v.overflowLists > 0 || (!run.custom && run.result.limits.lightsOverLimit > 0);
    std::vector<MissedLight> missed;
    if (v.falseNegatives) missed = locateFalseNegatives(run, Projection(scene.camera));
    const bool testMiss = !missed.empty() && missed.front().cause == MissCause::CullingTest;
    v.duplicateIndices = run.custom ? run.custom->duplicateIndices : 0;
    v.validationMessages = run.custom ? run.custom->validationMessages.size() : 0;
    if (v.invalidIndices) {
        v.fails = true;
        v.property = "invalid indices";
    } else if (v.validationMessages) {
        v.fails = true;
        v.property = "validation messages: " + run.custom->validationMessages.front();
    } else if (v.duplicateIndices) {
        v.fails = true;
        v.property = "duplicate indices";
    } else if (testMiss || (v.falseNegatives && !v.overCapacity)) {
        v.fails = true;
        v.property = "false negatives";
    } else if (v.overCapacity && options.overflowIsFailure) {
        v.fails = true;
        v.property = "overflow";
    }
    if (!missed.empty()) v.miss = missed.front();
    // A built-in algorithm off the CPU: its lists must hold the CPU
    // reference's over the same depth (a superset: float rounding may add).
    if (!options.shader && backend.name() != "cpu" && !v.fails) {
        const Projection proj(scene.camera);
        const TileGrid grid = TileGrid::make(scene.camera.width, scene.camera.height, scene.camera.tileSize);
        // Under engine limits the backends' rounding may fill a list's last
        // slots differently: the test's own lists, before the limits, are
        // compared (the limits are one host rule, tested on their own).
        CullSettings open = settings;
        open.cap = open.maxLights = open.maxEntries = 0;
        const CullResult ref = makeCpuBackend()->cull(run.depth, proj, grid, run.lights, open);
        CullResult unlimited;
        if (settings.hasLimits()) unlimited = backend.cull(run.depth, proj, grid, run.lights, open);
        const CullResult& got = settings.hasLimits() ? unlimited : run.result;
        if (ref.listCount.size() != got.listCount.size()) {
            v.fails = true;
            v.property = "lists differ from the CPU reference (" + std::to_string(got.listCount.size()) +
                         " lists, the reference " + std::to_string(ref.listCount.size()) + ")";
        } else {
            for (std::size_t l = 0; l < ref.listCount.size(); ++l) {
                const auto rb = ref.lightIndices.begin() + ref.listOffset[l], re = rb + ref.listCount[l];
                const auto gb = got.lightIndices.begin() + got.listOffset[l], ge = gb + got.listCount[l];
                std::vector<std::uint32_t> lost;
                std::set_difference(rb, re, gb, ge, std::back_inserter(lost));
                if (!lost.empty() && !v.missingReferenceEntries) {
                    v.referenceList = std::uint32_t(l);
                    v.referenceLight = lost.front();
                }
                v.missingReferenceEntries += lost.size();
            }
            if (v.missingReferenceEntries) {
                v.fails = true;
                v.property = "lists lack the CPU reference's entries";
            }
        }
    }
    if (runOut) *runOut = std::move(run);
    return v;
}

namespace {

// Rounds x to `digits` significant decimal digits (0: leaves it).
double roundSig(double x, int digits) {
    if (x == 0 || !std::isfinite(x)) return x;
    const double scale = std::pow(10.0, digits - 1 - std::floor(std::log10(std::abs(x))));
    return std::round(x * scale) / scale;
}
// Rounds to a multiple of `step`; a step below 1 divides by its inverse, so
// that 0.1 steps print as 12.7, not 12.700000000000001.
glm::dvec3 roundTo(glm::dvec3 v, double step) {
    if (step < 1) {
        const double inv = std::round(1.0 / step);
        return glm::round(v * inv) / inv;
    }
    return glm::round(v / step) * step;
}

} // namespace

namespace {

// A mesh without the vertices its triangles no longer use, to be written
// inline (no longer its source file).
void keepUsedVertices(Mesh& m) {
    std::vector<std::uint32_t> remap(m.vertexCount(), ~0u);
    std::vector<float> positions;
    for (std::uint32_t& v : m.indices) {
        if (remap[v] == ~0u) {
            remap[v] = std::uint32_t(positions.size() / 3);
            positions.insert(positions.end(), m.positions.begin() + 3 * v, m.positions.begin() + 3 * v + 3);
        }
        v = remap[v];
    }
    m.positions = std::move(positions);
    m.sourcePath.clear();
    m.resolvedPath.clear();
}

} // namespace

Scene shrinkHuntFailure(const Scene& failing, const HuntOptions& options, CullBackend& backend, std::size_t* runs) {
    std::size_t count = 0;
    const HuntVerdict first = judgeHuntTrial(failing, options, backend);
    ++count;
    Scene best = failing;
    auto stillFails = [&](const Scene& s) {
        if (options.cancel && options.cancel->cancelled) return false; // keep what was shrunk so far
        if (!s.camera.validate().empty()) return false;
        ++count;
        try {
            return judgeHuntTrial(s, options, backend).fails;
        } catch (const Error&) {
            return false; // a shrink step made a scene the tool refuses: not a smaller repro
        }
    };
    // Lights: the missed one alone, else drop the others one at a time.
    if (first.miss && best.lights.size() > 1) {
        Scene alone = best;
        alone.lights = {best.lights[first.miss->light]};
        if (stillFails(alone)) best = alone;
    }
    // Drops runs of items from `best` (halves of what is left, then quarters,
    // ... single ones) while it still fails, never all of them, until the
    // runs since `since` reach `maxRuns`. `size` counts a scene's items,
    // `drop(scene, begin, end)` removes [begin, end). True when any went.
    auto dropRuns = [&](auto size, auto drop, std::size_t since, std::size_t maxRuns) {
        bool dropped = false;
        for (std::size_t chunk = std::max<std::size_t>(1, size(best) / 2); chunk >= 1 && count - since < maxRuns;
             chunk /= 2)
            for (std::size_t start = 0; start < size(best) && size(best) > 1 && count - since < maxRuns;) {
                const std::size_t end = std::min(size(best), start + chunk);
                if (end - start == size(best)) break; // never all of them
                Scene fewer = best;
                drop(fewer, start, end);
                if (stillFails(fewer)) {
                    best = std::move(fewer); // the next run starts where this one was
                    dropped = true;
                } else {
                    start = end;
                }
            }
        return dropped;
    };
    // Then runs of lights: a crowd of 300 shrinks in few runs.
    dropRuns([](const Scene& sc) { return sc.lights.size(); },
             [](Scene& sc, std::size_t b, std::size_t e) {
                 sc.lights.erase(sc.lights.begin() + std::ptrdiff_t(b), sc.lights.begin() + std::ptrdiff_t(e));
             },
             count, 200);
    // Triangles: whole meshes, then runs of each mesh's triangles, within
    // one bound, so a level of 100k triangles shrinks as far as the runs
    // allow.
    for (std::size_t i = best.meshes.size(); i-- > 0 && best.meshes.size() > 1;) {
        Scene fewer = best;
        fewer.meshes.erase(fewer.meshes.begin() + std::ptrdiff_t(i));
        if (stillFails(fewer)) best = fewer;
    }
    const std::size_t triangleRunsSince = count;
    for (std::size_t mi = 0; mi < best.meshes.size(); ++mi) {
        const bool trimmed = dropRuns([mi](const Scene& sc) { return sc.meshes[mi].triangleCount(); },
                                      [mi](Scene& sc, std::size_t b, std::size_t e) {
                                          std::vector<std::uint32_t>& idx = sc.meshes[mi].indices;
                                          idx.erase(idx.begin() + std::ptrdiff_t(3 * b),
                                                    idx.begin() + std::ptrdiff_t(3 * e));
                                      },
                                      triangleRunsSince, 160);
        if (!trimmed) continue;
        // A mesh that lost triangles is written inline, without the vertices
        // nothing uses any more (not as its source file's path).
        keepUsedVertices(best.meshes[mi]);
    }
    // Screen: halve each side while it still fails.
    for (int axis = 0; axis < 2; ++axis)
        for (;;) {
            Scene smaller = best;
            std::uint32_t& side = axis == 0 ? smaller.camera.width : smaller.camera.height;
            if (side <= 1) break;
            side = (side + 1) / 2;
            if (!stillFails(smaller)) break;
            best = smaller;
        }
    // Then whole tiles off each side (keeping a partial edge tile partial),
    // in steps halved when a step loses the failure.
    for (int axis = 0; axis < 2; ++axis) {
        const std::uint32_t tile = best.camera.tileSize;
        std::uint32_t side = axis == 0 ? best.camera.width : best.camera.height;
        for (std::uint32_t step = side / tile / 2; step >= 1 && side > tile;) {
            if (step * tile >= side) {
                step /= 2;
                continue;
            }
            Scene smaller = best;
            (axis == 0 ? smaller.camera.width : smaller.camera.height) = side - step * tile;
            if (stillFails(smaller)) {
                best = smaller;
                side -= step * tile;
            } else {
                step /= 2;
            }
        }
    }
    // Camera values: the roundest that still fails, coarsest first.
    const double diag = diagonalOf(best);
    for (double step : {1.0, 0.1, 0.01}) {
        Scene round = best;
        Camera& c = round.camera;
        c.position = roundTo(c.position, step * std::max(1.0, std::floor(diag / 10)));
        c.target = roundTo(c.target, step * std::max(1.0, std::floor(diag / 10)));
        if (stillFails(round)) {
            best = round;
            break;
        }
    }
    for (int digits : {1, 2, 3}) {
        Scene round = best;
        Camera& c = round.camera;
        c.fovYDeg = roundSig(c.fovYDeg, digits + 1);
        c.orthoHeight = roundSig(c.orthoHeight, digits);
        c.nearPlane = roundSig(c.nearPlane, digits);
        c.farPlane = roundSig(c.farPlane, digits);
        if (stillFails(round)) {
            best = round;
            break;
        }
    }
    // The lights' numbers too, where that keeps the miss.
    for (int digits : {2, 3, 4}) {
        Scene round = best;
        for (PointLight& l : round.lights) {
            for (int k = 0; k < 3; ++k) l.position[k] = roundSig(l.position[k], digits);
            l.explicitRadius = roundSig(l.explicitRadius, digits);
            l.intensity = roundSig(l.intensity, 2);
            l.color = roundTo(l.color, 0.01);
            l.outerAngleDeg = std::min(90.0, roundSig(l.outerAngleDeg, digits));
            l.innerAngleDeg = std::min(l.outerAngleDeg, roundSig(l.innerAngleDeg, digits));
            for (int k = 0; k < 3; ++k) l.direction[k] = roundSig(l.direction[k], digits);
        }
        bool valid = true;
        for (const PointLight& l : round.lights) valid = valid && l.validate().empty();
        if (valid && stillFails(round)) {
            best = round;
            break;
        }
    }
    for (std::size_t i = 0; i < best.lights.size(); ++i) best.lights[i].name = "L" + std::to_string(i);
    if (runs) *runs = count;
    return best;
}

HuntResult hunt(const HuntOptions& options, CullBackend& backend) {
    if (options.maxTrials == 0 && !(options.maxSeconds > 0))
        throw SettingsError("trials", "give a trial count or a time budget");
    HuntResult result;
    HuntCoverage& cov = result.coverage;
    const auto t0 = std::chrono::steady_clock::now();
    auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
    double lastReport = 0;
    for (std::uint64_t i = 0;; ++i) {
        if (options.maxTrials && i >= options.maxTrials) break;
        if (options.maxSeconds > 0 && elapsed() >= options.maxSeconds) break;
        if (options.cancel && options.cancel->cancelled) {
            result.cancelled = true;
            break;
        }
        const Scene s = makeHuntTrial(options.baseScene, options.seed, i, options.vary);
        // Coverage of what this trial is.
        const Camera& c = s.camera;
        ++cov.trials;
        cov.orthographic += isOrthographic(c.projection);
        cov.reversedZ += c.projection == ProjectionKind::ReversedZ;
        cov.infiniteFar += std::isinf(c.farPlane);
        cov.glDepth += c.projection == ProjectionKind::PerspectiveGL || c.projection == ProjectionKind::OrthographicGL;
        cov.nonMultipleScreens += c.width % c.tileSize != 0 || c.height % c.tileSize != 0;
        cov.tinyScreens += c.width <= 24 || c.height <= 24;
        cov.generatedScenes += !options.baseScene;
        const auto [lo, hi] = s.bounds();
        cov.cameraInsideBounds += glm::all(glm::greaterThanEqual(c.position, lo)) &&
                                  glm::all(glm::lessThanEqual(c.position, hi));
        const glm::dmat4 view = c.viewFromWorld();
        const double diag = diagonalOf(s);
        bool spot = false, wide = false;
        for (const PointLight& l : s.lights) {
            spot = spot || l.isSpot();
            wide = wide || (l.isSpot() && l.outerAngleDeg > 45.0);
            const glm::dvec3 v = glm::dvec3(view * glm::dvec4(l.position, 1.0));
            const double r = l.radius();
            cov.lightsBehindCamera += v.z > 0;
            cov.lightsCrossingNear += std::abs(-v.z - c.nearPlane) < r;
            cov.lightsLargerThanScene += r > diag;
        }
        cov.spotTrials += spot;
        cov.crowds += s.lights.size() > 32;
        cov.wideSpots += wide;

        const HuntVerdict v = judgeHuntTrial(s, options, backend);
        cov.emptyViews += v.geometryPixels == 0 && !v.fails;
        if (v.overCapacity && !v.fails) {
            ++cov.overCapacity;
            if (!result.firstOverCapacityTrial) result.firstOverCapacityTrial = i;
        }
        if (v.fails) {
            HuntFailure f;
            f.trial = i;
            f.original = s;
            f.varied = huntDimsToString(options.vary);
            f.shrunk = shrinkHuntFailure(s, options, backend, &f.shrinkRuns);
            f.verdict = judgeHuntTrial(f.shrunk, options, backend);
            if (!f.verdict.fails) { // shrinking never keeps a passing scene; belt and braces
                f.shrunk = s;
                f.verdict = v;
            }
            result.failure = std::move(f);
            break;
        }
        if (options.progress && elapsed() - lastReport >= 1.0) {
            lastReport = elapsed();
            options.progress(cov, lastReport);
        }
    }
    result.seconds = elapsed();
    if (options.progress) options.progress(cov, result.seconds);
    return result;
}

std::string huntVerdictText(const HuntFailure& f, const HuntOptions& options) {
    Scene s = f.shrunk;
    const CullSettings settings = huntSettings(options, s); // with a preset, its tile size for this scene
    const Camera& c = s.camera;
    const HuntVerdict& v = f.verdict;
    auto g = [](double x) {
        char b[32];
        std::snprintf(b, sizeof b, "%g", x);
        return std::string(b);
    };
    std::ostringstream o;
    o << "The culling under test ("
      << (options.shader ? "custom shader " + options.shader->path + ", layout " + toString(options.shader->layout) +
                               ", lists " + toString(options.shader->lists)
                         : options.preset ? "engine preset " + options.preset->name + ": " + toString(settings.algorithm)
                                          : std::string("built-in ") + toString(settings.algorithm))
      << ") fails the hunt's property (" << v.property << ")";
    if (!f.pathFrame.empty())
        o << " at " << f.pathFrame << ".";
    else
        o << " at trial " << f.trial << " of seed " << options.seed << " (varying " << f.varied << ").";
    if (v.miss) {
        const TileGrid grid = TileGrid::make(c.width, c.height, c.tileSize);
        const std::uint32_t tx = v.miss->tile % grid.tilesX, ty = v.miss->tile / grid.tilesX;
        const PointLight& l = s.lights.at(v.miss->light);
        char pos[160];
        std::snprintf(pos, sizeof pos, "(%g, %g, %g), radius %g", l.position.x, l.position.y, l.position.z,
                      l.radius());
        o << " Light " << v.miss->light << " ('" << l.name << "', a " << toString(l.kind) << " light at " << pos
          << (l.isSpot() ? ", outer angle " + g(l.outerAngleDeg) + " degrees" : std::string()) << ")"
          << " is missing from the list of tile " << tx << "," << ty << " (list " << v.miss->list << ", cause "
          << toString(v.miss->cause) << ") where " << v.miss->pixels << (v.miss->pixels == 1 ? " geometry pixel needs it; " : " geometry pixels need it; ")
          << v.falseNegatives << (v.falseNegatives == 1 ? " false negative in all" : " false negatives in all");
        if (v.overflowLists || v.invalidIndices)
            o << ", " << v.overflowLists << " lists over the layout's capacity, " << v.invalidIndices
              << " invalid indices";
        o << ".";
    } else if (v.missingReferenceEntries) {
        o << " Its lists lack " << v.missingReferenceEntries
          << " entries the CPU reference lists over the same depth image; the first: light " << v.referenceLight
          << " in list " << v.referenceList
          << " (no false negative: the reference lists more than the pixels need; compare `lightcull run "
             "--backend cpu` with the repro's run).";
    } else {
        o << " " << v.falseNegatives << " false negatives, " << v.invalidIndices << " invalid indices, "
          << v.duplicateIndices << " duplicate indices, " << v.validationMessages << " validation messages, "
          << v.overflowLists << " overflowed lists.";
    }
    o << " Shrunk from " << f.original.lights.size() << (f.original.lights.size() == 1 ? " light at " : " lights at ")
      << f.original.camera.width << "x"
      << f.original.camera.height << " to " << s.lights.size() << " light" << (s.lights.size() == 1 ? "" : "s")
      << " at " << c.width << "x" << c.height << " (tile " << c.tileSize << ", " << toString(c.projection)
      << (isOrthographic(c.projection) ? ", height " + g(c.orthoHeight)
                                       : ", fov " + g(c.fovYDeg) + " degrees")
      << ", near " << c.nearPlane << ", far " << c.farPlane << ") in " << f.shrinkRuns << " runs.\n";
    return o.str();
}

namespace {

std::string oneLine(std::string s) {
    for (char& c : s)
        if (c == '\n' || c == '\r') c = ' ';
    return s;
}

// What a repro folder holds; a folder holding anything else is refused.
const std::set<std::string> kReproFiles = {"scene.json", "scene.glb", "repro.sh", "studio.sh", "verdict.txt",
                                           "summary.json", "run", "path.csv", "path.svg"};

// Written first into every repro folder: the folder is a hunt's to replace.
constexpr const char* kReproMarker = ".lightcull-hunt";

} // namespace

std::string huntOutputProblem(const std::string& dir) {
    const fs::path p(dir);
    const fs::path parent = p.has_parent_path() ? p.parent_path() : fs::path(".");
    if (dir.empty()) return "no folder given";
    // Missing parent folders are made (fs::create_directories); the nearest
    // one that exists must be a folder.
    std::error_code ec;
    for (fs::path q = parent; !fs::is_directory(q, ec); q = q.parent_path()) {
        if (fs::exists(fs::symlink_status(q, ec))) return dir + ": " + q.string() + " is not a folder";
        if (!q.has_parent_path() || q.parent_path() == q) break;
    }
    if (!fs::exists(p)) return {};
    if (!fs::is_directory(p)) return dir + ": is a file, not a folder";
    // A folder is reused only when a hunt wrote it (its marker file) and it
    // holds nothing but a hunt's outputs: a user's own scene.json or run/
    // in a folder of theirs is never replaced.
    bool empty = true;
    for (const auto& e : fs::directory_iterator(p)) {
        empty = false;
        const std::string name = e.path().filename().string();
        if (name != kReproMarker && !kReproFiles.count(name))
            return dir + ": holds " + name + ", which is not an earlier hunt's output";
    }
    if (!empty && !fs::exists(p / kReproMarker))
        return dir + ": holds files of the names a hunt writes, but no hunt wrote them (no " +
               std::string(kReproMarker) + "); give a new or empty folder";
    return {};
}

std::string huntNoMissText(const HuntResult& result, const HuntOptions& options) {
    const std::string head = std::string(result.cancelled ? "cancelled: " : "") + "no miss in " +
                             std::to_string(result.coverage.trials);
    if (!result.path.empty()) return head + " frames of " + result.path + "\n";
    return head + " trials of seed " + std::to_string(options.seed) + " (coverage: " + result.coverage.text() + ")\n";
}

namespace {

// The program `name` beside the one running (the CLI and the studio are
// installed side by side), or empty.
std::string besideMe(const std::string& name) {
    std::error_code ec;
    const fs::path self = fs::read_symlink("/proc/self/exe", ec);
    if (ec) return {};
    const fs::path p = self.parent_path() / name;
    return fs::exists(p, ec) ? p.string() : std::string();
}

// What a repro script runs when its variable is unset: `name` from PATH,
// else the one beside the program that wrote the script.
std::string fallback(const std::string& name) {
    const std::string mine = besideMe(name);
    if (mine.empty()) return name;
    return "$(command -v " + name + " || echo " + shellQuote(mine) + ")";
}

} // namespace

std::string writeHuntRepro(const HuntResult& result, const HuntOptions& options, CullBackend& backend,
                           const std::string& dir, const std::string& device) {
    if (const std::string why = huntOutputProblem(dir); !why.empty()) throw SettingsError("out", why);
    const fs::path out(dir);
    fs::create_directories(out);
    writeFileSynced((out / kReproMarker).string(), "a lightcull hunt wrote this folder and may replace it\n");
    for (const std::string& name : kReproFiles) fs::remove_all(out / name);
    if (!result.failure) {
        writeFileSynced((out / "verdict.txt").string(), huntNoMissText(result, options));
        return {};
    }
    // The `lightcull run` that shows the miss, run from the folder. With a
    // preset, its settings for the shrunk scene, each named (and the scene's
    // tile size the preset's): the repro runs as the trial did.
    const HuntFailure& f = *result.failure;
    Scene scene = f.shrunk;
    const CullSettings settings = huntSettings(options, scene);
    std::string command = "lightcull run --scene scene.json --backend " + backend.name();
    // The same culling in the studio, its first miss selected and explained.
    std::string studio = "lightcull-studio --scene scene.json --backend " + backend.name();
    if (!device.empty()) command += " --device " + shellQuote(device);
    if (options.shader) {
        const std::string shader = shellQuote(fs::absolute(options.shader->path).string());
        command += " --shader " + shader + " --layout " + toString(options.shader->layout) + " --lists " +
                   toString(options.shader->lists);
        if (!options.shader->validation) command += " --no-validation";
        // The hunt's time limit, where it is not run's default: a slow shader
        // fails the repro as it failed the trial.
        if (options.shader->timeoutMs != CustomShaderOptions{}.timeoutMs) {
            std::ostringstream ms;
            ms << options.shader->timeoutMs;
            command += " --timeout-ms " + ms.str();
        }
        studio += " --shader " + shader;
    } else {
        Camera scratch;
        for (const ParamSpec& p : cullParams())
            if (p.name != "tile" && p.name != "width" && p.name != "height") {
                command += " --" + p.name + " " + shellQuote(getParam(settings, scratch, p.name));
                studio += " --param " + shellQuote(p.name + "=" + getParam(settings, scratch, p.name));
            }
    }
    command += " --no-image-error --out run";
    studio += " --first-miss";

    saveSceneFile(scene, (out / "scene.json").string());
    saveGltfScene(scene, (out / "scene.glb").string()); // for the user's engine and glTF viewers
    scene.origin.file = fs::absolute(out / "scene.json").string();
    scene.origin.command = command;
    RunOutput run;
    const HuntVerdict again = judgeHuntTrial(scene, options, backend, &run);
    // A run that failed (a hang, a device error) has no lists to export:
    // the repro is the scene and the command that fails the same way.
    const bool runFailed = again.property.rfind("error: ", 0) == 0;
    if (!runFailed) {
        exportDiagnostics(scene, settings, run, (out / "run").string());
        fs::copy_file(out / "run" / "summary.json", out / "summary.json", fs::copy_options::overwrite_existing);
    }
    // A failure that did not come back when the repro ran (a shader near its
    // time limit on a loaded machine): said in the verdict and the script.
    const std::string notAgain =
        again.fails ? std::string()
                    : "It did not fail when the shrunk repro ran again (a time limit depends on the machine's "
                      "load): the repro may pass.";
    std::string verdict = huntVerdictText(f, options);
    if (!notAgain.empty()) {
        while (!verdict.empty() && verdict.back() == '\n') verdict.pop_back();
        verdict += " " + notAgain + "\n";
    }
    writeFileSynced((out / "verdict.txt").string(), verdict);
    writeFileSynced((out / "repro.sh").string(),
                    "#!/bin/sh\n# lightcull hunt, seed " + std::to_string(options.seed) + ", trial " +
                        std::to_string(f.trial) + ": " + oneLine(f.verdict.property) + " (verdict.txt). " +
                        (!notAgain.empty() ? notAgain + "\n"
                         : runFailed       ? "Fails (exit 1) while the error is there.\n"
                                           : "Exits 3 while the miss is there.\n") +
                        "# Set LIGHTCULL to the binary when lightcull is not on PATH" +
                        (besideMe("lightcull").empty() ? std::string()
                                                       : " (else the one that wrote this runs)") +
                        ".\ncd \"$(dirname \"$0\")\" || exit 1\n# " + command + "\nexec \"${LIGHTCULL:-" +
                        fallback("lightcull") + "}\"" + command.substr(9) + "\n");
    // The studio reads a shader's layout and lists from its first line only.
    std::string studioNote;
    if (options.shader) {
        std::string headerLayout, headerLists;
        try {
            const CustomShaderOptions h = shaderOptionsFromFile(options.shader->path);
            headerLayout = toString(h.layout);
            headerLists = toString(h.lists);
        } catch (const Error&) {
        }
        const std::string used = toString(options.shader->layout), usedLists = toString(options.shader->lists);
        studioNote = headerLayout == used && headerLists == usedLists
                         ? "# The shader's layout and lists come from its first line, as in the hunt.\n"
                         : "# NOTE: the studio takes the shader's layout and lists from its first line (" +
                               (headerLayout.empty() ? std::string("none") : headerLayout + ", " + headerLists) +
                               "); this hunt used --layout " + used + " --lists " + usedLists +
                               ": put `// lightcull: --layout " + used + " --lists " + usedLists +
                               "` first in the shader to see the same lists there.\n";
    }
    writeFileSynced((out / "studio.sh").string(),
                    "#!/bin/sh\n# The repro in LightCull Studio: the scene opens, culls and selects the miss "
                    "(Explain shows why).\n# Set LIGHTCULL_STUDIO to the binary when lightcull-studio is not on "
                    "PATH.\n" +
                        studioNote +
                        "cd \"$(dirname \"$0\")\" || exit 1\nexec \"${LIGHTCULL_STUDIO:-" +
                        fallback("lightcull-studio") + "}\"" +
                        studio.substr(16) + " \"$@\"\n");
    for (const char* script : {"repro.sh", "studio.sh"})
        fs::permissions(out / script, fs::perms::owner_exec | fs::perms::group_exec | fs::perms::others_exec,
                        fs::perm_options::add);
    return command;
}

} // namespace lc
