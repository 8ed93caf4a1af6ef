#pragma once
// The culling parameters, declared once. This one table feeds CullSettings,
// the CLI's flags and the studio's toolbar controls: add a parameter here and
// it appears in all three.

#include "culling/math/spot_tests.hpp"
#include "culling/math/tile_math.hpp"

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace lc {

enum class Algorithm { All, Naive, MinMax, HalfZ, TwoPointFiveD, Clustered, Fptl, ZBin, Raster };
// "all", "naive", "minmax", "halfz", "2.5d", "clustered", "fptl", "zbin", "raster"
const char* toString(Algorithm a);
Algorithm algorithmFromString(const std::string& s); // throws SettingsError("algorithm", ...)

// Engine limits (docs/ALGORITHMS.md, "Caps and limits"). Which lights an
// over-full list keeps: the lowest indices (a shader appending lights in
// index order), the ones nearest the camera (an engine that sorts its lights
// first), or every light (the fallback of an engine whose over-full record
// means "shade with all lights").
enum class OverflowPolicy { Index, Nearest, AllLights };
const char* toString(OverflowPolicy p); // "index", "nearest", "all-lights"
// Which lights a per-view light limit keeps: the lowest indices, or the ones
// nearest the camera.
enum class LimitKeep { Index, Nearest };
const char* toString(LimitKeep k); // "index", "nearest"

// Settings of one culling run. Resolution and tile size live on the Camera
// (they are part of what the culling camera sees) but are also parameters.
struct CullSettings {
    Algorithm algorithm = Algorithm::TwoPointFiveD;
    SphereTest test = SphereTest::Planes;
    std::uint32_t cells = 32;        // 2.5d occupancy cells, clustered depth slices (1..32)
    Slicing slicing = Slicing::Log;
    bool skipEmpty = true;           // clustered: empty clusters (no geometry) get empty lists
    SpotTest spotTest = SpotTest::ApexSphere; // how spot lights are culled (point lights ignore it)
    std::uint32_t bins = 1024;       // zbin: linear view-depth bins (1..16384)
    // raster: each light's proxy mesh rasterised at one pixel per tile
    // (culling/math/light_proxy.hpp, docs/ALGORITHMS.md).
    std::uint32_t proxyLevel = 1;     // icosphere subdivisions of a point light's proxy (0..4)
    std::uint32_t proxySegments = 8;  // sides of a spot light's cone proxy (3..64)
    std::uint32_t proxyConeAngle = 60; // spots wider than this half-angle (degrees) get the sphere proxy
    double proxyOverfit = 0;          // scale of the proxy; 0 = auto (the factor that encloses the light)
    bool conservative = true;         // coverage: any overlap of a tile (else the tile's centre)
    // raster's depth: false = one list per tile, the proxy's depth range
    // against the tile's min/max; true = clustered lists (`cells` slices of
    // `slicing` over the camera's range, as `clustered`), each fragment's
    // depth marking the slices (Godot's depth bits).
    bool proxySlices = false;
    // Engine limits, applied to the lists the culling test made (both
    // backends, one rule: applyListLimits in core/limits.hpp); 0 = none.
    std::uint32_t cap = 0;           // entries one list keeps at most
    std::uint32_t maxLights = 0;     // lights the view culls at most (the others are in no list)
    std::uint32_t maxEntries = 0;    // entries all lists together keep at most (a record buffer)
    OverflowPolicy overflow = OverflowPolicy::Index; // what an over-full list or buffer keeps
    LimitKeep limitKeep = LimitKeep::Index;          // which lights maxLights keeps
    bool hasLimits() const { return cap || maxLights || maxEntries; }
    // Lists per cluster: `cells` depth slices of `slicing` over the frame's
    // cluster range per tile (clustered, and raster with proxySlices).
    bool clusterLists() const {
        return algorithm == Algorithm::Clustered || (algorithm == Algorithm::Raster && proxySlices);
    }

    // Empty when valid, else names the field.
    std::string validate() const;
};

enum class ParamType { Choice, Int, Bool, Real };

// One parameter: its name (CLI flag --name, JSON key, UI label source), type,
// default, range and help. Values are exchanged as strings so that the CLI,
// the studio and JSON share one parser.
struct ParamSpec {
    ParamSpec(std::string name_, ParamType type_, std::string defaultValue_, std::vector<std::string> choices_,
              long long minValue_, long long maxValue_, std::string help_, std::string label_,
              std::string group_ = {})
        : name(std::move(name_)), type(type_), defaultValue(std::move(defaultValue_)), choices(std::move(choices_)),
          minValue(minValue_), maxValue(maxValue_), help(std::move(help_)), label(std::move(label_)),
          group(std::move(group_)) {}
    std::string name;
    ParamType type;
    std::string defaultValue;
    std::vector<std::string> choices; // Choice only
    long long minValue = 0, maxValue = 0; // Int only
    std::string help;
    std::string label;               // short UI label
    // "limits" for the engine limits (the studio shows them on their own
    // toolbar row, beside the engine preset); empty for the culling proper.
    std::string group;
    // Real only: the range, and a word the value may be instead of a number
    // (proxy-overfit's "auto"; it reads as 0).
    double realMin = 0, realMax = 0;
    std::string realWord;
};

// Every culling parameter, in display order: algorithm, test, cells, slicing,
// skip-empty, spot-test, bins, the raster proxy's (proxy-level, proxy-segments,
// proxy-cone-angle, proxy-overfit, conservative, proxy-depth), tile, width, height, then the limits: cap,
// max-lights, max-entries, overflow, limit-keep.
const std::vector<ParamSpec>& cullParams();
const ParamSpec& cullParam(const std::string& name); // throws SettingsError

// Reads/writes a parameter by name. Throws SettingsError naming the parameter
// and the bad value. Camera-owned ones (tile, width, height) go to `camera`.
void setParam(CullSettings& s, Camera& camera, const std::string& name, const std::string& value);
std::string getParam(const CullSettings& s, const Camera& camera, const std::string& name);
// A Real parameter's value as text: the shortest form that reads back ("1.25").
std::string realText(double x);

} // namespace lc
