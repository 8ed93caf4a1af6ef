#pragma once
// The culling parameters, declared once. This one table feeds CullSettings,
// the CLI's flags and the studio's toolbar controls: add a parameter here and
// it appears in all three.

#include "culling/math/spot_tests.hpp"
#include "culling/math/tile_math.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace lc {

enum class Algorithm { All, Naive, MinMax, HalfZ, TwoPointFiveD, Clustered, Fptl, ZBin };
// "all", "naive", "minmax", "halfz", "2.5d", "clustered", "fptl", "zbin"
const char* toString(Algorithm a);
Algorithm algorithmFromString(const std::string& s); // throws SettingsError("algorithm", ...)

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

    // Empty when valid, else names the field.
    std::string validate() const;
};

enum class ParamType { Choice, Int, Bool };

// One parameter: its name (CLI flag --name, JSON key, UI label source), type,
// default, range and help. Values are exchanged as strings so that the CLI,
// the studio and JSON share one parser.
struct ParamSpec {
    std::string name;
    ParamType type;
    std::string defaultValue;
    std::vector<std::string> choices; // Choice only
    long long minValue = 0, maxValue = 0; // Int only
    std::string help;
    std::string label;               // short UI label
};

// Every culling parameter, in display order: algorithm, test, cells, slicing,
// skip-empty, spot-test, bins, tile, width, height.
const std::vector<ParamSpec>& cullParams();
const ParamSpec& cullParam(const std::string& name); // throws SettingsError

// Reads/writes a parameter by name. Throws SettingsError naming the parameter
// and the bad value. Camera-owned ones (tile, width, height) go to `camera`.
void setParam(CullSettings& s, Camera& camera, const std::string& name, const std::string& value);
std::string getParam(const CullSettings& s, const Camera& camera, const std::string& name);

} // namespace lc
