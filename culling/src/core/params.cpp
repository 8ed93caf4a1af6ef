// The one table of culling parameters (params.hpp) and its string parser.
#include "culling/core/params.hpp"

#include "culling/core/errors.hpp"

#include <cctype>
#include <charconv>
#include <cstdio>

namespace lc {

namespace {

constexpr std::pair<Algorithm, const char*> kAlgorithms[] = {
    {Algorithm::All, "all"},          {Algorithm::Naive, "naive"},
    {Algorithm::MinMax, "minmax"},    {Algorithm::HalfZ, "halfz"},
    {Algorithm::TwoPointFiveD, "2.5d"}, {Algorithm::Clustered, "clustered"},
    {Algorithm::Fptl, "fptl"},        {Algorithm::ZBin, "zbin"},
    {Algorithm::Raster, "raster"}};
constexpr SphereTest kTests[] = {SphereTest::Planes, SphereTest::PlanesAabb, SphereTest::Exact};
constexpr Slicing kSlicings[] = {Slicing::Log, Slicing::Linear};
constexpr std::pair<OverflowPolicy, const char*> kOverflow[] = {
    {OverflowPolicy::Index, "index"}, {OverflowPolicy::Nearest, "nearest"}, {OverflowPolicy::AllLights, "all-lights"}};
constexpr std::pair<LimitKeep, const char*> kLimitKeep[] = {{LimitKeep::Index, "index"},
                                                             {LimitKeep::Nearest, "nearest"}};
constexpr SpotTest kSpotTests[] = {SpotTest::ApexSphere, SpotTest::TightSphere, SpotTest::ConeSphere,
                                   SpotTest::ConePlanes};

std::string joined(const std::vector<std::string>& v) {
    std::string s;
    for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
    return s;
}

std::vector<ParamSpec> buildTable() {
    std::vector<ParamSpec> t;
    std::vector<std::string> algos;
    for (const auto& a : kAlgorithms) algos.push_back(a.second);
    std::vector<std::string> tests;
    for (auto x : kTests) tests.push_back(toString(x));
    std::vector<std::string> slicings;
    for (auto x : kSlicings) slicings.push_back(toString(x));

    t.push_back({"algorithm", ParamType::Choice, "2.5d", algos, 0, 0,
                 "culling algorithm: all (no culling), naive (tile planes + camera near/far), "
                 "minmax (tile min/max depth), halfz (two lists split at mid depth), 2.5d "
                 "(depth-cell occupancy mask), clustered (3D froxel grid), fptl (fine-pruned tiles: "
                 "minmax, then each light tested against the tile's pixels), zbin (Z-binning: a "
                 "screen-space light mask per tile and linear view-depth bins of the depth-sorted lights), "
                 "raster (each light's proxy mesh rasterised at one pixel per tile, then its depth range "
                 "against the tile's min/max)",
                 "Algorithm", ""});
    t.push_back({"test", ParamType::Choice, "planes", tests, 0, 0,
                 "sphere-vs-volume test: planes (6 planes), planes+aabb (planes and the chunk's "
                 "bounding box), exact (Euclidean distance to the frustum chunk)",
                 "Sphere test", ""});
    t.push_back({"cells", ParamType::Int, "32", {}, 1, 32,
                 "2.5d occupancy cells per tile / clustered depth slices", "Cells", ""});
    t.push_back({"slicing", ParamType::Choice, "log", slicings, 0, 0,
                 "depth slicing of 2.5d cells and clustered slices: log or linear", "Slicing", ""});
    t.push_back({"skip-empty", ParamType::Bool, "true", {}, 0, 1,
                 "clustered: clusters holding no geometry get empty lists", "Skip empty", ""});
    std::vector<std::string> spotTests;
    for (auto x : kSpotTests) spotTests.push_back(toString(x));
    t.push_back({"spot-test", ParamType::Choice, "apex-sphere", spotTests, 0, 0,
                 "spot-light test: apex-sphere (range sphere at the apex), tight-sphere (smallest "
                 "sphere around the cone), cone-sphere (tight sphere, then cone vs the cell's "
                 "bounding sphere), cone-planes (tight sphere, then cone vs each cell plane)",
                 "Spot test", ""});
    t.push_back({"bins", ParamType::Int, "1024", {}, 1, 16384,
                 "zbin: view-depth bins, linear from the near plane to the far plane (or the farthest "
                 "light)", "Bins", ""});
    t.push_back({"proxy-level", ParamType::Int, "1", {}, 0, 4,
                 "raster: subdivisions of the icosphere a point light is drawn as (0: icosahedron, 20 "
                 "triangles; each level 4x as many)",
                 "Proxy level", ""});
    t.push_back({"proxy-segments", ParamType::Int, "8", {}, 3, 64,
                 "raster: sides of the cone a spot light is drawn as", "Cone sides", ""});
    t.push_back({"proxy-cone-angle", ParamType::Int, "60", {}, 1, 89,
                 "raster: a spot light whose outer half-angle (degrees) is above this is drawn as its "
                 "range sphere instead of a cone",
                 "Cone up to", ""});
    {
        ParamSpec overfit{"proxy-overfit", ParamType::Real, "auto", {}, 0, 0,
                          "raster: scale of each proxy (a sphere's about its centre, a cone's base about its "
                          "axis); auto: the smallest that encloses the light (docs/ALGORITHMS.md), 1: the mesh "
                          "inscribed in the light's sphere",
                          "Overfit", ""};
        overfit.realMin = 0.5;
        overfit.realMax = 4.0;
        overfit.realWord = "auto";
        t.push_back(overfit);
    }
    t.push_back({"conservative", ParamType::Bool, "true", {}, 0, 1,
                 "raster: a proxy marks every tile it overlaps (conservative rasterisation), else only "
                 "the tiles whose centre it covers",
                 "Conservative", ""});
    t.push_back({"proxy-depth", ParamType::Choice, "tile", {"tile", "slices"}, 0, 0,
                 "raster: tile (one list per tile: the proxy's depth range against the tile's min/max) or "
                 "slices (clustered lists: cells slices of slicing, each fragment's depth marking the "
                 "slices it spans, as Godot's depth bits)",
                 "Depth", ""});
    t.push_back({"tile", ParamType::Int, "16", {}, 1, 256, "tile size in pixels", "Tile", ""});
    t.push_back({"width", ParamType::Int, "1280", {}, 1, 16384, "render width in pixels", "Width", ""});
    t.push_back({"height", ParamType::Int, "720", {}, 1, 16384, "render height in pixels", "Height", ""});
    // Engine limits (docs/ALGORITHMS.md, "Caps and limits"): what a shipped
    // engine's fixed buffers do to the lists the test made.
    t.push_back({"cap", ParamType::Int, "0", {}, 0, 65536,
                 "per-list cap: a list keeps at most this many lights (the others are dropped by "
                 "--overflow-policy); 0 = no cap",
                 "Cap", "limits"});
    t.push_back({"max-lights", ParamType::Int, "0", {}, 0, 1000000,
                 "per-view light limit: only this many lights take part in culling (chosen by "
                 "--limit-keep), the others are in no list; 0 = no limit",
                 "Max lights", "limits"});
    t.push_back({"max-entries", ParamType::Int, "0", {}, 0, 100000000,
                 "record-buffer limit: all lists together keep at most this many entries, filled in list "
                 "order (what an over-full list keeps follows --overflow-policy); 0 = no limit",
                 "Max entries", "limits"});
    std::vector<std::string> overflows, keeps;
    for (const auto& x : kOverflow) overflows.push_back(x.second);
    for (const auto& x : kLimitKeep) keeps.push_back(x.second);
    t.push_back({"overflow-policy", ParamType::Choice, "index", overflows, 0, 0,
                 "what an over-full list keeps: index (the lowest light indices, as a shader appending in "
                 "index order), nearest (the lights nearest the camera, as an engine that sorts them), "
                 "all-lights (every light: the fallback some engines use)",
                 "Overflow", "limits"});
    t.push_back({"limit-keep", ParamType::Choice, "index", keeps, 0, 0,
                 "which lights --max-lights keeps: index (the lowest indices) or nearest (nearest the camera)",
                 "Keep", "limits"});
    return t;
}

} // namespace

std::string realText(double x) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", x);
    return buf;
}

namespace {

long long parseInt(const ParamSpec& p, const std::string& v) {
    long long x = 0;
    const char* b = v.data();
    const char* e = v.data() + v.size();
    auto [ptr, ec] = std::from_chars(b, e, x);
    if (v.empty() || ec != std::errc() || ptr != e || x < p.minValue || x > p.maxValue)
        throw SettingsError(p.name, "must be an integer in " + std::to_string(p.minValue) + ".." +
                                        std::to_string(p.maxValue) + ", got '" + v + "'");
    return x;
}

bool parseBool(const ParamSpec& p, const std::string& value) {
    // Any case: TRUE as well as true (as 1, yes and on are accepted).
    std::string v = value;
    for (char& c : v) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (v == "true" || v == "1" || v == "yes" || v == "on") return true;
    if (v == "false" || v == "0" || v == "no" || v == "off") return false;
    throw SettingsError(p.name, "must be true or false, got '" + value + "'");
}

double parseReal(const ParamSpec& p, const std::string& v) {
    if (!p.realWord.empty() && v == p.realWord) return 0.0;
    double x = 0;
    const char* b = v.data();
    const char* e = v.data() + v.size();
    auto [ptr, ec] = std::from_chars(b, e, x);
    if (v.empty() || ec != std::errc() || ptr != e || !(x >= p.realMin && x <= p.realMax))
        throw SettingsError(p.name, "must be a number in " + realText(p.realMin) + ".." + realText(p.realMax) +
                                        (p.realWord.empty() ? "" : " or " + p.realWord) + ", got '" + v + "'");
    return x;
}

std::size_t parseChoice(const ParamSpec& p, const std::string& v) {
    for (std::size_t i = 0; i < p.choices.size(); ++i)
        if (p.choices[i] == v) return i;
    throw SettingsError(p.name, "must be one of " + joined(p.choices) + ", got '" + v + "'");
}

} // namespace

const char* toString(OverflowPolicy p) {
    for (const auto& x : kOverflow)
        if (x.first == p) return x.second;
    return "?";
}

const char* toString(LimitKeep k) {
    for (const auto& x : kLimitKeep)
        if (x.first == k) return x.second;
    return "?";
}

const char* toString(Algorithm a) {
    for (const auto& x : kAlgorithms)
        if (x.first == a) return x.second;
    return "?";
}

Algorithm algorithmFromString(const std::string& s) {
    for (const auto& x : kAlgorithms)
        if (s == x.second) return x.first;
    return kAlgorithms[parseChoice(cullParam("algorithm"), s)].first; // throws
}

std::string CullSettings::validate() const {
    if (cells < 1 || cells > 32)
        return "cells: must be an integer in 1..32, got " + std::to_string(cells);
    if (bins < 1 || bins > 16384) return "bins: must be an integer in 1..16384, got " + std::to_string(bins);
    bool knownAlgo = false;
    for (const auto& x : kAlgorithms) knownAlgo |= x.first == algorithm;
    if (!knownAlgo) return "algorithm: unknown value";
    if (test != SphereTest::Planes && test != SphereTest::PlanesAabb && test != SphereTest::Exact)
        return "test: unknown value";
    if (slicing != Slicing::Log && slicing != Slicing::Linear) return "slicing: unknown value";
    bool knownSpot = false;
    for (auto x : kSpotTests) knownSpot |= x == spotTest;
    if (!knownSpot) return "spot-test: unknown value";
    if (proxyLevel > 4) return "proxy-level: must be an integer in 0..4, got " + std::to_string(proxyLevel);
    if (proxySegments < 3 || proxySegments > 64)
        return "proxy-segments: must be an integer in 3..64, got " + std::to_string(proxySegments);
    if (proxyConeAngle < 1 || proxyConeAngle > 89)
        return "proxy-cone-angle: must be an integer in 1..89, got " + std::to_string(proxyConeAngle);
    if (!(proxyOverfit == 0.0 || (proxyOverfit >= 0.5 && proxyOverfit <= 4.0)))
        return "proxy-overfit: must be a number in 0.5..4 or auto, got " + realText(proxyOverfit);
    if (cap > 65536) return "cap: must be an integer in 0..65536, got " + std::to_string(cap);
    if (maxLights > 1000000) return "max-lights: must be an integer in 0..1000000, got " + std::to_string(maxLights);
    if (maxEntries > 100000000)
        return "max-entries: must be an integer in 0..100000000, got " + std::to_string(maxEntries);
    bool knownOverflow = false, knownKeep = false;
    for (const auto& x : kOverflow) knownOverflow |= x.first == overflow;
    for (const auto& x : kLimitKeep) knownKeep |= x.first == limitKeep;
    if (!knownOverflow) return "overflow-policy: unknown value";
    if (!knownKeep) return "limit-keep: unknown value";
    return {};
}

const std::vector<ParamSpec>& cullParams() {
    static const std::vector<ParamSpec> table = buildTable();
    return table;
}

const ParamSpec& cullParam(const std::string& name) {
    for (const auto& p : cullParams())
        if (p.name == name) return p;
    std::vector<std::string> names;
    for (const auto& p : cullParams()) names.push_back(p.name);
    throw SettingsError(name, "unknown parameter (known: " + joined(names) + ")");
}

void setParam(CullSettings& s, Camera& camera, const std::string& name, const std::string& value) {
    const ParamSpec& p = cullParam(name);
    if (name == "algorithm") s.algorithm = kAlgorithms[parseChoice(p, value)].first;
    else if (name == "test") s.test = kTests[parseChoice(p, value)];
    else if (name == "cells") s.cells = std::uint32_t(parseInt(p, value));
    else if (name == "slicing") s.slicing = kSlicings[parseChoice(p, value)];
    else if (name == "skip-empty") s.skipEmpty = parseBool(p, value);
    else if (name == "spot-test") s.spotTest = kSpotTests[parseChoice(p, value)];
    else if (name == "bins") s.bins = std::uint32_t(parseInt(p, value));
    else if (name == "proxy-level") s.proxyLevel = std::uint32_t(parseInt(p, value));
    else if (name == "proxy-segments") s.proxySegments = std::uint32_t(parseInt(p, value));
    else if (name == "proxy-cone-angle") s.proxyConeAngle = std::uint32_t(parseInt(p, value));
    else if (name == "proxy-overfit") s.proxyOverfit = parseReal(p, value);
    else if (name == "conservative") s.conservative = parseBool(p, value);
    else if (name == "proxy-depth") s.proxySlices = parseChoice(p, value) == 1;
    else if (name == "tile") camera.tileSize = std::uint32_t(parseInt(p, value));
    else if (name == "width") camera.width = std::uint32_t(parseInt(p, value));
    else if (name == "height") camera.height = std::uint32_t(parseInt(p, value));
    else if (name == "cap") s.cap = std::uint32_t(parseInt(p, value));
    else if (name == "max-lights") s.maxLights = std::uint32_t(parseInt(p, value));
    else if (name == "max-entries") s.maxEntries = std::uint32_t(parseInt(p, value));
    else if (name == "overflow-policy") s.overflow = kOverflow[parseChoice(p, value)].first;
    else if (name == "limit-keep") s.limitKeep = kLimitKeep[parseChoice(p, value)].first;
}

std::string getParam(const CullSettings& s, const Camera& camera, const std::string& name) {
    cullParam(name); // throws for unknown names
    if (name == "algorithm") return toString(s.algorithm);
    if (name == "test") return toString(s.test);
    if (name == "cells") return std::to_string(s.cells);
    if (name == "slicing") return toString(s.slicing);
    if (name == "skip-empty") return s.skipEmpty ? "true" : "false";
    if (name == "spot-test") return toString(s.spotTest);
    if (name == "bins") return std::to_string(s.bins);
    if (name == "proxy-level") return std::to_string(s.proxyLevel);
    if (name == "proxy-segments") return std::to_string(s.proxySegments);
    if (name == "proxy-cone-angle") return std::to_string(s.proxyConeAngle);
    if (name == "proxy-overfit") return s.proxyOverfit == 0.0 ? "auto" : realText(s.proxyOverfit);
    if (name == "conservative") return s.conservative ? "true" : "false";
    if (name == "proxy-depth") return s.proxySlices ? "slices" : "tile";
    if (name == "tile") return std::to_string(camera.tileSize);
    if (name == "width") return std::to_string(camera.width);
    if (name == "height") return std::to_string(camera.height);
    if (name == "cap") return std::to_string(s.cap);
    if (name == "max-lights") return std::to_string(s.maxLights);
    if (name == "max-entries") return std::to_string(s.maxEntries);
    if (name == "overflow-policy") return toString(s.overflow);
    return toString(s.limitKeep);
}

} // namespace lc
