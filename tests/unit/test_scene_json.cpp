// The scene JSON format: lossless round trip and every error path, each
// checked for the file name, the field path and the line of the field.
#include "culling/core/errors.hpp"
#include "culling/scene/scene_io.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

using namespace lc;
namespace fs = std::filesystem;

namespace {

void expectSceneEq(const Scene& a, const Scene& b) {
    EXPECT_EQ(a.name, b.name);
    const Camera &c = a.camera, &d = b.camera;
    EXPECT_EQ(c.position, d.position);
    EXPECT_EQ(c.target, d.target);
    EXPECT_EQ(c.up, d.up);
    EXPECT_EQ(c.projection, d.projection);
    EXPECT_EQ(c.fovYDeg, d.fovYDeg);
    EXPECT_EQ(c.orthoHeight, d.orthoHeight);
    EXPECT_EQ(c.nearPlane, d.nearPlane);
    EXPECT_EQ(c.farPlane, d.farPlane);
    EXPECT_EQ(c.width, d.width);
    EXPECT_EQ(c.height, d.height);
    EXPECT_EQ(c.tileSize, d.tileSize);
    ASSERT_EQ(a.lights.size(), b.lights.size());
    for (std::size_t i = 0; i < a.lights.size(); ++i) {
        const PointLight &l = a.lights[i], &m = b.lights[i];
        EXPECT_EQ(l.name, m.name);
        EXPECT_EQ(l.position, m.position);
        EXPECT_EQ(l.color, m.color);
        EXPECT_EQ(l.intensity, m.intensity);
        EXPECT_EQ(l.minIntensity, m.minIntensity);
        EXPECT_EQ(l.explicitRadius, m.explicitRadius);
    }
    ASSERT_EQ(a.meshes.size(), b.meshes.size());
    for (std::size_t i = 0; i < a.meshes.size(); ++i) {
        EXPECT_EQ(a.meshes[i].name, b.meshes[i].name);
        EXPECT_EQ(a.meshes[i].sourcePath, b.meshes[i].sourcePath);
        EXPECT_EQ(a.meshes[i].positions, b.meshes[i].positions);  // bitwise float equality
        EXPECT_EQ(a.meshes[i].indices, b.meshes[i].indices);
        EXPECT_EQ(a.meshes[i].transform, b.meshes[i].transform);
    }
}

std::string tempDir() {
    const fs::path d = fs::temp_directory_path() / ("lc_scene_json_" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d.string();
}

// A valid scene; each error case replaces one line of it. Line numbers are
// those of this text (line 1 is the opening brace).
const char* kBase = R"({
  "format": "lightcull-scene",
  "version": 1,
  "name": "t",
  "camera": {
    "position": [0, 1, 5],
    "target": [0, 0, 0],
    "projection": "perspective",
    "fov_y_deg": 60,
    "near": 0.1,
    "far": 100,
    "width": 320,
    "height": 200,
    "tile_size": 16
  },
  "meshes": [
    {
      "name": "tri",
      "positions": [0, 0, 0, 1, 0, 0, 0, 1, 0],
      "indices": [0, 1, 2],
      "transform": {"translate": [1, 2, 3], "rotate_deg": [0, 90, 0], "scale": 2}
    }
  ],
  "lights": [
    {"name": "a", "position": [0, 1, 0], "color": [1, 1, 1], "intensity": 2, "min_intensity": 0.5},
    {
      "name": "b",
      "position": [1, 1, 0],
      "intensity": 3,
      "radius": 4
    }
  ]
}
)";

std::string replaceLine(const std::string& text, int line, const std::string& with) {
    std::string out;
    std::size_t pos = 0;
    for (int l = 1; pos <= text.size(); ++l) {
        std::size_t nl = text.find('\n', pos);
        if (nl == std::string::npos) nl = text.size();
        out += (l == line ? with : text.substr(pos, nl - pos));
        if (nl < text.size()) out += '\n';
        pos = nl + 1;
    }
    return out;
}

struct ErrorCase {
    int line;             // line of kBase to replace (0: none)
    std::string with;     // replacement text
    std::string field;    // expected field path
    int expectLine;       // expected line in the error
    std::string message;  // fragment of the message
};

} // namespace

TEST(SceneJson, BaseSceneParsesAsWritten) {
    const Scene s = parseScene(kBase, "/nowhere/base.json");
    EXPECT_EQ(s.name, "t");
    EXPECT_EQ(s.camera.width, 320u);
    EXPECT_EQ(s.camera.up, glm::dvec3(0, 1, 0));  // default
    ASSERT_EQ(s.lights.size(), 2u);
    EXPECT_DOUBLE_EQ(s.lights[0].radius(), 2.0);  // sqrt(2*1/0.5)
    EXPECT_DOUBLE_EQ(s.lights[1].radius(), 4.0);  // explicit
    EXPECT_EQ(s.lights[1].color, glm::dvec3(1));  // default colour
    ASSERT_EQ(s.meshes.size(), 1u);
    // transform = T(1,2,3) * Ry(90) * S(2): model (1,0,0) -> scaled (2,0,0)
    // -> rotated about +Y by 90 deg: (0,0,-2) -> translated (1,2,1).
    const glm::dvec4 p = s.meshes[0].transform * glm::dvec4(1, 0, 0, 1);
    EXPECT_NEAR(p.x, 1, 1e-12);
    EXPECT_NEAR(p.y, 2, 1e-12);
    EXPECT_NEAR(p.z, 1, 1e-12);
    // Whole numbers written as floats (Python's json.dump writes 640.0) read
    // as the whole numbers they are.
    std::string floats = kBase;
    floats.replace(floats.find("\"version\": 1"), 12, "\"version\": 1.0");
    floats.replace(floats.find("\"width\": 320"), 12, "\"width\": 320.0");
    EXPECT_EQ(parseScene(floats, "/nowhere/floats.json").camera.width, 320u);
}

TEST(SceneJson, RoundTripIsLossless) {
    Scene s = parseScene(kBase, "/nowhere/base.json");
    // Values without short decimal forms, and an infinite far plane.
    s.lights[0].position = {0.1, 1.0 / 3.0, -2.718281828459045e-7};
    s.lights[0].intensity = 9.999999999999999e23; // near the largest valid (kMaxLightPower)
    s.camera.projection = ProjectionKind::ReversedZ;
    s.camera.farPlane = std::numeric_limits<double>::infinity();
    s.camera.fovYDeg = 59.99999999999999;
    s.meshes[0].positions[3] = 0.1f;
    const std::string text = serializeScene(s);
    const Scene back = parseScene(text, "/nowhere/back.json");
    expectSceneEq(s, back);
    EXPECT_EQ(serializeScene(back), text);
}

TEST(SceneJson, BuiltinScenesRoundTripThroughFiles) {
    const std::string dir = tempDir();
    for (const auto& info : builtinScenes()) {
        const Scene s = makeBuiltinScene(info.name);
        const std::string path = dir + "/" + info.name + ".json";
        saveSceneFile(s, path);
        const Scene back = loadSceneFile(path);
        SCOPED_TRACE(info.name);
        expectSceneEq(s, back);
    }
    // No temporary files left beside the saved ones.
    for (const auto& e : fs::directory_iterator(dir))
        EXPECT_EQ(e.path().extension(), ".json") << e.path();
    fs::remove_all(dir);
}

TEST(SceneJson, MeshByRelativePath) {
    const std::string dir = tempDir();
    fs::create_directories(dir + "/meshes");
    std::ofstream(dir + "/meshes/quad.obj") << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
    std::string text = replaceLine(kBase, 19, R"(      "path": "meshes/quad.obj",)");
    text = replaceLine(text, 20, "");
    std::ofstream(dir + "/s.json") << text;
    const Scene s = loadSceneFile(dir + "/s.json");
    ASSERT_EQ(s.meshes.size(), 1u);
    EXPECT_EQ(s.meshes[0].sourcePath, "meshes/quad.obj");
    EXPECT_EQ(s.meshes[0].triangleCount(), 2u);
    saveSceneFile(s, dir + "/s2.json");
    expectSceneEq(s, loadSceneFile(dir + "/s2.json"));

    // A missing mesh: the scene file, the field and the line, and the mesh path.
    std::ofstream(dir + "/bad.json") << replaceLine(text, 19, R"(      "path": "meshes/nope.obj",)");
    try {
        loadSceneFile(dir + "/bad.json");
        FAIL();
    } catch (const InputError& e) {
        EXPECT_EQ(e.file(), dir + "/bad.json");
        EXPECT_EQ(e.field(), "meshes[0].path");
        EXPECT_EQ(e.line(), 19);
        EXPECT_NE(std::string(e.what()).find("nope.obj"), std::string::npos);
    }
    fs::remove_all(dir);
}

TEST(SceneJson, EveryErrorNamesFileFieldAndLine) {
    const std::vector<ErrorCase> cases = {
        {2, R"(  "format": "other",)", "format", 2, "lightcull-scene"},
        {3, R"(  "version": 2,)", "version", 3, "version 1"},
        {3, R"(  "version": "1",)", "version", 3, "whole number"},
        {3, "", "version", 1, "missing"},
        {4, R"(  "name": 5,)", "name", 4, "string"},
        {4, R"(  "nmae": "t",)", "nmae", 4, "unknown field"},
        {6, R"(    "position": [0, 1],)", "camera.position", 6, "3 numbers"},
        {6, R"(    "position": [0, "x", 5],)", "camera.position[1]", 6, "number"},
        {6, "", "camera.position", 5, "missing"},
        {7, R"(    "target": [0, 1, 5],)", "camera.target", 7, "differ"},
        {8, R"(    "projection": "fisheye",)", "camera.projection", 8, "fisheye"},
        {9, R"(    "fov_y_deg": 180,)", "camera.fov_y_deg", 9, "(0, 180)"},
        {10, R"(    "near": 0,)", "camera.near", 10, "> 0"},
        {11, R"(    "far": 0.05,)", "camera.far", 11, "greater"},
        {11, R"(    "far": "inf",)", "camera.far", 11, "reversed_z"},
        {11, R"(    "far": "infinite",)", "camera.far", 11, "inf"},
        {12, R"(    "width": -3,)", "camera.width", 12, "[0, 4294967295]"},
        {12, R"(    "width": 640.5,)", "camera.width", 12, "whole number, not 640.5"},
        {12, R"(    "width": 0,)", "camera.width", 12, "[1, 16384]"},
        {14, R"(    "tile_size": 300)", "camera.tile_size", 14, "256"},
        {19, R"(      "positions": [0, 0, 0, 1, 0, 0, 0, 1],)", "meshes[0].positions", 19, "3n"},
        {20, R"(      "indices": [0, 1, 3],)", "meshes[0].indices[2]", 20, "out of range"},
        {20, "", "meshes[0]", 17, "positions"},
        {21, R"(      "transform": [1, 0, 0])", "meshes[0].transform", 21, "16"},
        {21, R"(      "transform": {"translate": [1, 2, 3], "spin": 1})", "meshes[0].transform.spin", 21, "unknown"},
        {25, R"(    {"name": "a", "position": [0, 1, 0], "intensity": -2},)", "lights[0].intensity", 25, ">= 0"},
        {25, R"(    {"name": "a", "position": [0, 1, 0], "min_intensity": 0},)", "lights[0].min_intensity", 25, "> 0"},
        {25, R"(    {"name": "a", "position": [0, 1, 0], "color": [1, -1, 0]},)", "lights[0].color", 25, ">= 0"},
        {25, R"(    {"name": "a", "posiiton": [0, 1, 0]},)", "lights[0].posiiton", 25, "unknown"},
        {25, R"(    {"name": "a", "position": [0, 1, 0], "name": "b"},)", "lights[0].name", 25, "duplicate"},
        {25, R"(    7,)", "lights[0]", 25, "object"},
        {30, R"(      "radius": -4)", "lights[1].radius", 30, ">= 0"},
        {28, "", "lights[1].position", 26, "missing"},
        {29, R"(      "intensity": 3,,)", "", 29, "syntax"},
        {31, R"(    ])", "", 31, "syntax"},
    };
    for (const auto& c : cases) {
        const std::string text = c.line ? replaceLine(kBase, c.line, c.with) : std::string(kBase);
        SCOPED_TRACE("case: line " + std::to_string(c.line) + " -> " + c.with);
        try {
            parseScene(text, "dir/case.json");
            ADD_FAILURE() << "no error";
        } catch (const InputError& e) {
            EXPECT_EQ(e.file(), "dir/case.json");
            EXPECT_EQ(e.field(), c.field) << e.what();
            EXPECT_EQ(e.line(), c.expectLine) << e.what();
            const std::string what = e.what();
            EXPECT_NE(what.find("dir/case.json:" + std::to_string(c.expectLine)), std::string::npos) << what;
            EXPECT_NE(what.find(c.message), std::string::npos) << what;
        }
    }
}

TEST(SceneJson, FileLevelErrors) {
    const std::string dir = tempDir();
    EXPECT_THROW(loadSceneFile(dir + "/missing.json"), InputError);
    std::ofstream(dir + "/empty.json") << "  \n";
    try {
        loadSceneFile(dir + "/empty.json");
        FAIL();
    } catch (const InputError& e) {
        EXPECT_EQ(e.file(), dir + "/empty.json");
    }
    try {
        parseScene("[1, 2]", "x.json");
        FAIL();
    } catch (const InputError& e) {
        EXPECT_EQ(e.line(), 1);
    }
    // Nesting is bounded before the parser builds a path per level (100,000
    // levels in 200 KB took the whole machine's memory).
    try {
        parseScene("{\"format\": \"lightcull-scene\",\n\"name\": " + std::string(100000, '[') +
                       std::string(100000, ']') + "}",
                   "deep.json");
        FAIL();
    } catch (const InputError& e) {
        EXPECT_EQ(e.line(), 2);
        EXPECT_NE(std::string(e.what()).find("nested more than 256 deep"), std::string::npos) << e.what();
    }
    // Saving into a folder that does not exist fails cleanly.
    EXPECT_THROW(saveSceneFile(makeBuiltinScene("sky"), dir + "/no/such/dir/s.json"), InputError);
    fs::remove_all(dir);
}

// Found by fuzz_scene_json: a scene without a camera whose mesh lies far from
// the origin (the fuzzer's shape: a triangle collapsed to one point at 1e20;
// also a 1 m triangle moved there by its transform) got a framing camera on
// its own target, and parseScene returned a scene that fails validate().
TEST(SceneJson, WithoutACameraAMeshFarFromTheOriginIsFramedByAValidCamera) {
    for (const char* mesh : {R"("positions": [1e20, 1e20, 1e20, 1e20, 1e20, 1e20, 1e20, 1e20, 1e20], "indices": [0, 1, 2])",
                             R"("positions": [1e16, 1e16, 1e16, 1e16, 1e16, 1e16, 1e16, 1e16, 1e16], "indices": [0, 1, 2])",
                             R"("positions": [0, 0, 0, 1, 0, 0, 0, 1, 0], "indices": [0, 1, 2],
                                "transform": {"translate": [1e20, 1e20, 1e20]})"}) {
        SCOPED_TRACE(mesh);
        const Scene s = parseScene(std::string(R"({"format": "lightcull-scene", "version": 1, "meshes": [{)") + mesh + "}]}",
                                   "far.json");
        EXPECT_NO_THROW(s.validate());
        EXPECT_EQ(s.camera.validate(), "");
        // Still looking at the mesh.
        const auto [lo, hi] = s.bounds();
        EXPECT_LE(glm::length(s.camera.target - 0.5 * (lo + hi)), 1e-12 * glm::length(lo));
    }
}

TEST(SceneJson, ExampleScenesInResourcesLoadAndValidate) {
    int n = 0;
    for (const auto& e : fs::directory_iterator(std::string(LC_SOURCE_DIR) + "/resources/scenes")) {
        if (e.path().extension() != ".json") continue;
        SCOPED_TRACE(e.path().string());
        const Scene s = loadSceneFile(e.path().string());
        EXPECT_NO_THROW(s.validate());
        EXPECT_GT(s.triangleCount(), 0u);
        EXPECT_FALSE(s.lights.empty());
        ++n;
    }
    EXPECT_GE(n, 2);
}
