// Camera paths (culling/scene/camera_path.hpp): JSON lists of cameras (partial
// cameras keep the base camera's values, default times, every error naming the
// file, JSON path and line) and glTF camera animations, built here as a small
// exporter would write them, each sampled value checked against what the
// exporter knows it wrote (LINEAR, STEP, CUBICSPLINE, slerped rotations, an
// animated parent), and hostile files, each a one-line InputError.
#include "cli_support.hpp"

#include "culling/core/errors.hpp"
#include "culling/scene/camera_path.hpp"

#include <glm/gtc/quaternion.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>

using lc_test::ScratchDir;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

constexpr double kPi = 3.14159265358979323846;

void writeText(const fs::path& p, const std::string& bytes) {
    std::ofstream(p, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}

// The camera every test starts from: not the library default, so that a value
// a path leaves alone is seen to come from here.
lc::Camera baseCamera() {
    lc::Camera c;
    c.position = {0, 0, 5};
    c.target = {0, 0, 0};
    c.projection = lc::ProjectionKind::ReversedZ;
    c.fovYDeg = 50;
    c.nearPlane = 0.25;
    c.farPlane = std::numeric_limits<double>::infinity();
    c.width = 320;
    c.height = 200;
    c.tileSize = 8;
    return c;
}

void expectNear(const glm::dvec3& got, const glm::dvec3& want, double tol, const std::string& what) {
    EXPECT_LT(glm::length(got - want), tol) << what << ": got (" << got.x << ", " << got.y << ", " << got.z
                                            << "), want (" << want.x << ", " << want.y << ", " << want.z << ")";
}

glm::dvec3 forward(const lc::Camera& c) { return glm::normalize(c.target - c.position); }

// What an error must carry: the file, the JSON path, the line (JSON paths
// only; 0 for glTF) and a phrase of the message.
struct Expected {
    std::string field;
    int line;
    std::string phrase;
};
void expectInputError(const std::function<void()>& load, const std::string& file, const Expected& e) {
    try {
        load();
        ADD_FAILURE() << "no error; expected " << e.field << ": " << e.phrase;
    } catch (const lc::InputError& err) {
        EXPECT_EQ(err.file(), file) << err.what();
        EXPECT_EQ(err.field(), e.field) << err.what();
        EXPECT_EQ(err.line(), e.line) << err.what();
        EXPECT_NE(std::string(err.what()).find(e.phrase), std::string::npos) << err.what();
        EXPECT_EQ(std::string(err.what()).find('\n'), std::string::npos) << err.what();
    } catch (const std::exception& err) {
        ADD_FAILURE() << "not an InputError: " << err.what();
    }
}

// ---------------------------------------------------------------- a glTF exporter

// A glTF document with one binary buffer, as an exporter writes a scene with
// an animated camera: float key accessors, animations with samplers and
// channels.
struct AnimatedGltf {
    json doc = {{"asset", {{"version", "2.0"}}},
                {"cameras", json::array({{{"type", "perspective"},
                                          {"perspective", {{"yfov", 0.8}, {"znear", 0.1}, {"zfar", 100.0}}}}})}};
    std::string bin;

    // An accessor of float keys: SCALAR, VEC3 or VEC4 by `type`.
    int keys(const std::vector<float>& v, const char* type) {
        const std::size_t comps = std::string(type) == "SCALAR" ? 1 : std::string(type) == "VEC3" ? 3 : 4;
        while (bin.size() % 4) bin.push_back('\0');
        doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", v.size() * 4}});
        bin.append(reinterpret_cast<const char*>(v.data()), v.size() * 4);
        doc["accessors"].push_back({{"bufferView", doc["bufferViews"].size() - 1},
                                    {"componentType", 5126},
                                    {"count", v.size() / comps},
                                    {"type", type}});
        return int(doc["accessors"].size() - 1);
    }
    int node(json n) {
        doc["nodes"].push_back(n);
        return int(doc["nodes"].size() - 1);
    }
    int cameraNode(const std::string& name, json extra = json::object()) {
        json n = {{"camera", 0}, {"name", name}};
        n.update(extra);
        return node(n);
    }
    void scene(std::vector<int> roots) { doc["scenes"] = json::array({{{"nodes", roots}}}), doc["scene"] = 0; }

    struct Channel {
        int node;
        std::string path;                // translation, rotation, scale
        std::vector<float> times, values;
        std::string interpolation = "LINEAR";
    };
    int animation(const std::string& name, const std::vector<Channel>& channels) {
        json a = {{"name", name}, {"channels", json::array()}, {"samplers", json::array()}};
        for (const Channel& c : channels) {
            const int in = keys(c.times, "SCALAR");
            const int out = keys(c.values, c.path == "rotation" ? "VEC4" : "VEC3");
            a["samplers"].push_back({{"input", in}, {"output", out}, {"interpolation", c.interpolation}});
            a["channels"].push_back({{"sampler", a["samplers"].size() - 1}, {"target", {{"node", c.node}, {"path", c.path}}}});
        }
        doc["animations"].push_back(a);
        return int(doc["animations"].size() - 1);
    }

    json withBuffer(const std::string& uri) const {
        json d = doc;
        json b = {{"byteLength", bin.size()}};
        if (!uri.empty()) b["uri"] = uri;
        d["buffers"] = json::array({b});
        return d;
    }
    static std::string base64(const std::string& s) {
        static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        std::string out;
        for (std::size_t i = 0; i < s.size(); i += 3) {
            std::uint32_t n = std::uint8_t(s[i]) << 16;
            if (i + 1 < s.size()) n |= std::uint8_t(s[i + 1]) << 8;
            if (i + 2 < s.size()) n |= std::uint8_t(s[i + 2]);
            out += t[(n >> 18) & 63];
            out += t[(n >> 12) & 63];
            out += i + 1 < s.size() ? t[(n >> 6) & 63] : '=';
            out += i + 2 < s.size() ? t[n & 63] : '=';
        }
        return out;
    }
    std::string gltfText() const { return withBuffer("data:application/octet-stream;base64," + base64(bin)).dump(); }
    std::string glb() const {
        std::string js = withBuffer("").dump();
        while (js.size() % 4) js += ' ';
        std::string b = bin;
        while (b.size() % 4) b.push_back('\0');
        std::string out = "glTF";
        auto u32 = [&](std::uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
        u32(2);
        u32(std::uint32_t(12 + 8 + js.size() + 8 + b.size()));
        u32(std::uint32_t(js.size()));
        u32(0x4E4F534A);
        out += js;
        u32(std::uint32_t(b.size()));
        u32(0x004E4942);
        out += b;
        return out;
    }
};

// One camera node flown along x then up y by LINEAR keys at 0, 1 and 2 s.
AnimatedGltf linearFlight() {
    AnimatedGltf g;
    const int cam = g.cameraNode("Cam");
    g.scene({cam});
    g.animation("Fly", {{cam, "translation", {0, 1, 2}, {0, 0, 0, 2, 0, 0, 2, 4, 0}}});
    return g;
}

lc::CameraPath loadGltf(const fs::path& p, const AnimatedGltf& g, double fps = 4, const std::string& animation = {},
                        const std::string& camera = {}) {
    writeText(p, p.extension() == ".glb" ? g.glb() : g.gltfText());
    return lc::loadCameraPath(p.string(), baseCamera(), fps, animation, lc::kCameraPathMaxFrames, camera);
}

// ---------------------------------------------------------------- JSON

json cameraJson(const lc::Camera& c) {
    json j = {{"position", {c.position.x, c.position.y, c.position.z}},
              {"target", {c.target.x, c.target.y, c.target.z}},
              {"up", {c.up.x, c.up.y, c.up.z}},
              {"projection", lc::toString(c.projection)},
              {"fov_y_deg", c.fovYDeg},
              {"ortho_height", c.orthoHeight},
              {"near", c.nearPlane},
              {"width", c.width},
              {"height", c.height},
              {"tile_size", c.tileSize}};
    if (std::isinf(c.farPlane)) j["far"] = "inf";
    else j["far"] = c.farPlane;
    return j;
}

} // namespace

TEST(CameraPathJson, FullCamerasRoundTripExactly) {
    ScratchDir s;
    std::vector<lc::Camera> cams;
    for (int i = 0; i < 5; ++i) {
        lc::Camera c = baseCamera();
        c.position = {0.1 * i, 1.0 / 3.0 + i, 7.25 - i};
        c.target = {-1e-7 * i, 0.5, -3};
        c.up = {0.01 * i, 1, 0};
        c.projection = i % 2 ? lc::ProjectionKind::Orthographic : lc::ProjectionKind::PerspectiveGL;
        c.fovYDeg = 20 + 13.7 * i;
        c.orthoHeight = 3 + i;
        c.nearPlane = 0.01 * (i + 1);
        c.farPlane = 500 + i;
        c.width = 17 + i;
        c.height = 9 * (i + 1);
        c.tileSize = 1 << i;
        cams.push_back(c);
    }
    json doc = {{"cameras", json::array()}};
    for (std::size_t i = 0; i < cams.size(); ++i) {
        doc["cameras"].push_back(cameraJson(cams[i]));
        doc["cameras"].back()["time"] = 0.75 * double(i * i);
    }
    const fs::path p = s.path / "flight.json";
    writeText(p, doc.dump(2));
    const lc::CameraPath path = lc::loadCameraPath(p.string(), lc::Camera{});
    ASSERT_EQ(path.frames.size(), cams.size());
    for (std::size_t i = 0; i < cams.size(); ++i) {
        EXPECT_TRUE(path.frames[i].camera == cams[i]) << "camera " << i;
        EXPECT_EQ(path.frames[i].time, 0.75 * double(i * i)) << "camera " << i;
    }
    EXPECT_EQ(path.description, "5 cameras of flight.json");
}

TEST(CameraPathJson, PartialCamerasKeepTheBaseAndTimesDefaultToIndexOverFps) {
    ScratchDir s;
    const fs::path p = s.path / "path.json";
    writeText(p, R"({
  "fps": 10,
  "cameras": [
    {"position": [0, 1, 5], "target": [0, 1, 0]},
    {"position": [1, 1, 5]},
    {"fov_y_deg": 40, "width": 64, "height": 32},
    {"time": 7.5, "projection": "perspective", "far": 80}
  ]
})");
    const lc::Camera base = baseCamera();
    const lc::CameraPath path = lc::loadCameraPath(p.string(), base, 25);
    ASSERT_EQ(path.frames.size(), 4u);
    EXPECT_EQ(path.description, "4 cameras of path.json");

    lc::Camera want = base;
    want.position = {0, 1, 5};
    want.target = {0, 1, 0};
    EXPECT_TRUE(path.frames[0].camera == want);
    want = base; // keys left out keep the base's values, not the previous camera's
    want.position = {1, 1, 5};
    EXPECT_TRUE(path.frames[1].camera == want);
    want = base;
    want.fovYDeg = 40, want.width = 64, want.height = 32;
    EXPECT_TRUE(path.frames[2].camera == want);
    want = base;
    want.projection = lc::ProjectionKind::Perspective, want.farPlane = 80;
    EXPECT_TRUE(path.frames[3].camera == want);
    // The file's fps, not the argument's, gives the default times.
    EXPECT_DOUBLE_EQ(path.frames[0].time, 0.0);
    EXPECT_DOUBLE_EQ(path.frames[1].time, 0.1);
    EXPECT_DOUBLE_EQ(path.frames[2].time, 0.2);
    EXPECT_DOUBLE_EQ(path.frames[3].time, 7.5);

    // Without "fps" in the file the argument's counts; one camera is a path.
    writeText(p, R"({"cameras": [{}, {}, {}]})");
    const lc::CameraPath three = lc::loadCameraPath(p.string(), base, 25);
    ASSERT_EQ(three.frames.size(), 3u);
    EXPECT_DOUBLE_EQ(three.frames[2].time, 2.0 / 25);
    EXPECT_TRUE(three.frames[2].camera == base);
    writeText(p, R"({"cameras": [{"position": [3, 3, 3]}]})");
    EXPECT_EQ(lc::loadCameraPath(p.string(), base).description, "1 camera of path.json");
}

TEST(CameraPathJson, EveryErrorNamesFileFieldAndLine) {
    const std::string kBase = R"({
  "fps": 30,
  "cameras": [
    {"position": [0, 1, 5], "target": [0, 1, 0]},
    {"position": [1, 1, 5], "time": 1},
    {"position": [2, 1, 5], "time": 2}
  ]
})";
    struct Case {
        int line;          // the line replaced (0: the whole text is `with`)
        std::string with;
        Expected e;
    };
    const std::vector<Case> cases = {
        {2, R"(  "fps": 0,)", {"fps", 2, "(0, 1000]"}},
        {2, R"(  "fps": 1001,)", {"fps", 2, "(0, 1000]"}},
        {2, R"(  "fps": "30",)", {"fps", 2, "must be a number"}},
        {2, R"(  "fsp": 30,)", {"fsp", 2, "unknown field 'fsp' (known here: cameras, fps)"}},
        {5, R"(    {"position": [1, 1], "time": 1},)", {"cameras[1].position", 5, "3 numbers"}},
        {5, R"(    {"position": [1, "x", 5], "time": 1},)", {"cameras[1].position[1]", 5, "number"}},
        {5, R"(    {"posiiton": [1, 1, 5], "time": 1},)", {"cameras[1].posiiton", 5, "unknown field"}},
        {5, R"(    {"position": [1, 1, 5], "time": 1, "time": 2},)", {"cameras[1].time", 5, "duplicate"}},
        // The base camera's target is the origin: a position there is refused.
        {5, R"(    {"position": [0, 0, 0], "time": 1},)", {"cameras[1].target", 5, "differ"}},
        {5, R"(    {"position": [1, 1, 5], "up": [0, 0, 1], "target": [1, 1, 0]},)", {"cameras[1].up", 5, "parallel"}},
        {5, R"(    {"position": [1, 1, 5], "fov_y_deg": 190},)", {"cameras[1].fov_y_deg", 5, "(0, 180)"}},
        {5, R"(    {"position": [1, 1, 5], "projection": "perspective"},)", {"cameras[1].far", 5, "reversed_z"}},
        {5, R"(    {"position": [1, 1, 5], "projection": "fisheye"},)", {"cameras[1].projection", 5, "fisheye"}},
        {5, R"(    {"position": [1, 1, 5], "tile_size": 300},)", {"cameras[1].tile_size", 5, "256"}},
        {5, R"(    {"position": [1, 1, 5], "time": "1"},)", {"cameras[1].time", 5, "must be a number"}},
        {5, R"(    {"position": [1, 1, 5], "time": 3},)", {"cameras[2].time", 6, "comes before the previous camera's 3 s"}},
        {6, R"(    {"position": [2, 1, 5]})", {"cameras[2]", 6, "give it a \"time\""}},
        {5, R"(    7,)", {"cameras[1]", 5, "must be an object"}},
        {5, R"(    {"position": [1, 1, 5], "time": 1,,)", {"", 5, "JSON syntax error"}},
        {0, R"({"cameras": []})", {"cameras", 1, "at least one camera"}},
        {0, R"({"cameras": {}})", {"cameras", 1, "must be an array"}},
        {0, "{\n  \"fps\": 30\n}", {"cameras", 1, "missing required field"}},
        {0, R"([{"position": [1, 1, 1]}])", {"", 1, "must be a JSON object"}},
        {0, "\n\n", {"", 0, "empty file"}},
    };
    ScratchDir s;
    const fs::path p = s.path / "case.json";
    for (const Case& c : cases) {
        std::string text = kBase;
        if (c.line == 0) {
            text = c.with;
        } else {
            std::vector<std::string> lines;
            std::istringstream in(kBase);
            for (std::string l; std::getline(in, l);) lines.push_back(l);
            lines[std::size_t(c.line - 1)] = c.with;
            text.clear();
            for (const auto& l : lines) text += l + "\n";
        }
        SCOPED_TRACE(c.with);
        writeText(p, text);
        expectInputError([&] { lc::loadCameraPath(p.string(), baseCamera()); }, p.string(), c.e);
    }
    expectInputError([&] { lc::loadCameraPath((s.path / "missing.json").string(), baseCamera()); },
                     (s.path / "missing.json").string(), {"", 0, "file not found"});
    expectInputError([&] { lc::loadCameraPath(s.path.string(), baseCamera()); }, s.path.string(), {"", 0, "is a folder"});
}

TEST(CameraPathJson, MoreFramesThanAllowedAreRefusedWithTheirCount) {
    ScratchDir s;
    const fs::path p = s.path / "long.json";
    writeText(p, R"({"cameras": [{}, {}, {}]})");
    expectInputError([&] { lc::loadCameraPath(p.string(), baseCamera(), 30, {}, 2); }, p.string(),
                     {"cameras", 1, "3 cameras, more than the 2 frames"});
    std::string text = "{\"cameras\": [";
    for (std::size_t i = 0; i <= lc::kCameraPathMaxFrames; ++i) text += i ? ",{}" : "{}";
    writeText(p, text + "]}");
    expectInputError([&] { lc::loadCameraPath(p.string(), baseCamera()); }, p.string(),
                     {"cameras", 1, "100001 cameras, more than the 100000"});
}

TEST(CameraPath, BadArgumentsAreSettingsErrors) {
    ScratchDir s;
    const fs::path p = s.path / "p.json";
    writeText(p, R"({"cameras": [{}]})");
    auto field = [&](const std::function<void()>& f) -> std::string {
        try {
            f();
        } catch (const lc::SettingsError& e) {
            return e.field();
        } catch (const std::exception& e) {
            return std::string("not a SettingsError: ") + e.what();
        }
        return "no error";
    };
    EXPECT_EQ(field([&] { lc::loadCameraPath(p.string(), baseCamera(), 0); }), "fps");
    EXPECT_EQ(field([&] { lc::loadCameraPath(p.string(), baseCamera(), 1000.5); }), "fps");
    EXPECT_EQ(field([&] { lc::loadCameraPath(p.string(), baseCamera(), std::nan("")); }), "fps");
    EXPECT_EQ(field([&] { lc::loadCameraPath(p.string(), baseCamera(), 30, {}, 0); }), "max-frames");
    lc::Camera bad = baseCamera();
    bad.nearPlane = -1;
    EXPECT_EQ(field([&] { lc::loadCameraPath(p.string(), bad); }), "camera");
    EXPECT_EQ(field([&] { lc::loadCameraPath(p.string(), baseCamera(), 30, "Fly"); }), "animation");
    EXPECT_EQ(lc::loadCameraPath(p.string(), baseCamera(), 1000).frames.size(), 1u);
}

// ---------------------------------------------------------------- glTF

TEST(CameraPathGltf, LinearTranslationIsSampledAtTheFrameRate) {
    ScratchDir s;
    const AnimatedGltf g = linearFlight();
    for (const char* name : {"linear.gltf", "linear.glb"}) {
        SCOPED_TRACE(name);
        const lc::CameraPath path = loadGltf(s.path / name, g, 4);
        EXPECT_EQ(path.description,
                  std::string("animation 'Fly' of ") + name + ": camera node 'Cam' (nodes[0]), 0..2 s at 4 fps, 9 frames");
        ASSERT_EQ(path.frames.size(), 9u); // 0, 0.25, ..., 2 s
        for (std::size_t f = 0; f < 9; ++f) {
            EXPECT_DOUBLE_EQ(path.frames[f].time, 0.25 * double(f));
            const double t = 0.25 * double(f);
            const glm::dvec3 want = t <= 1 ? glm::dvec3(2 * t, 0, 0) : glm::dvec3(2, 4 * (t - 1), 0);
            expectNear(path.frames[f].camera.position, want, 1e-6, "frame " + std::to_string(f));
            // No rotation: looking down -Z, +Y up, at the base camera's target distance.
            expectNear(path.frames[f].camera.target, want + glm::dvec3(0, 0, -5), 1e-6, "target");
            expectNear(path.frames[f].camera.up, {0, 1, 0}, 1e-12, "up");
            // Everything else is the base camera's, not the file's camera's.
            lc::Camera rest = path.frames[f].camera;
            rest.position = baseCamera().position, rest.target = baseCamera().target, rest.up = baseCamera().up;
            EXPECT_TRUE(rest == baseCamera());
        }
    }
    // A GLB is known by its magic whatever its name.
    writeText(s.path / "flight.bin", g.glb());
    EXPECT_EQ(lc::loadCameraPath((s.path / "flight.bin").string(), baseCamera(), 4).frames.size(), 9u);
    // Key times need not start at 0; a span a hair short of whole frames
    // (float key times) ends on the last key without an extra frame.
    AnimatedGltf late;
    const int cam = late.cameraNode("Cam");
    late.scene({cam});
    late.animation("Late", {{cam, "translation", {1.0f, 1.0f + 1.0f / 3.0f}, {0, 0, 0, 3, 0, 0}}});
    const lc::CameraPath lp = loadGltf(s.path / "late.gltf", late, 24);
    ASSERT_EQ(lp.frames.size(), 9u);
    EXPECT_DOUBLE_EQ(lp.frames.front().time, 1.0);
    EXPECT_DOUBLE_EQ(lp.frames.back().time, double(1.0f + 1.0f / 3.0f));
    expectNear(lp.frames.back().camera.position, {3, 0, 0}, 1e-6, "last key");
}

TEST(CameraPathGltf, StepHoldsEachKeyUntilTheNext) {
    ScratchDir s;
    AnimatedGltf g;
    const int cam = g.cameraNode("Cam");
    g.scene({cam});
    g.animation("Cuts", {{cam, "translation", {0, 1, 2}, {0, 0, 0, 5, 0, 0, 5, 5, 0}, "STEP"}});
    const lc::CameraPath path = loadGltf(s.path / "step.gltf", g, 4);
    ASSERT_EQ(path.frames.size(), 9u);
    const std::vector<glm::dvec3> want = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {5, 0, 0},
                                          {5, 0, 0}, {5, 0, 0}, {5, 0, 0}, {5, 5, 0}};
    for (std::size_t f = 0; f < 9; ++f) expectNear(path.frames[f].camera.position, want[f], 1e-12, "frame " + std::to_string(f));
}

TEST(CameraPathGltf, CubicSplineIsTheHermiteOfValuesAndTangents) {
    ScratchDir s;
    AnimatedGltf g;
    const int cam = g.cameraNode("Cam");
    g.scene({cam});
    // Per key: in-tangent, value, out-tangent. The first in-tangent and the
    // last out-tangent are never used (9s and 7s would show if they were).
    g.animation("Swoop", {{cam, "translation", {0, 2},
                           {9, 9, 9, 0, 0, 0, 1, 0, 0,   // key 0
                            0, 3, 0, 4, 0, 0, 7, 7, 7},  // key 1
                           "CUBICSPLINE"}});
    const lc::CameraPath path = loadGltf(s.path / "cubic.gltf", g, 4);
    ASSERT_EQ(path.frames.size(), 9u);
    // At t = 0.5: s = 0.25, td = 2; h00 = 0.84375, h10 = 0.140625, h01 =
    // 0.15625, h11 = -0.046875; p = h10*td*(1,0,0) + h01*(4,0,0) + h11*td*(0,3,0).
    expectNear(path.frames[2].camera.position, {0.90625, -0.28125, 0}, 1e-12, "t = 0.5");
    expectNear(path.frames[0].camera.position, {0, 0, 0}, 1e-12, "t = 0");
    expectNear(path.frames[8].camera.position, {4, 0, 0}, 1e-12, "t = 2");
    // At s = 0.5 every basis function is easy: h00 = h01 = 0.5, h10 = 0.125, h11 = -0.125.
    expectNear(path.frames[4].camera.position, {0.125 * 2 + 2, -0.125 * 2 * 3, 0}, 1e-12, "t = 1");
}

TEST(CameraPathGltf, RotationIsSlerpedTheShortWayAndNormalised) {
    ScratchDir s;
    // Key 1 is 120 degrees about +Y, written at twice unit length and negated
    // (the same rotation): the reader normalises it and slerps the short way.
    const double half = kPi / 3; // half of 120 degrees
    const std::vector<float> q0 = {0, 0, 0, 1};
    const std::vector<float> q1 = {0, float(-2 * std::sin(half)), 0, float(-2 * std::cos(half))};
    AnimatedGltf g;
    const int cam = g.cameraNode("Cam", {{"translation", {1, 2, 3}}});
    g.scene({cam});
    std::vector<float> values = q0;
    values.insert(values.end(), q1.begin(), q1.end());
    g.animation("Pan", {{cam, "rotation", {0, 1}, values}});
    const lc::CameraPath path = loadGltf(s.path / "pan.gltf", g, 4);
    ASSERT_EQ(path.frames.size(), 5u);
    for (std::size_t f = 0; f < 5; ++f) {
        const double u = 0.25 * double(f);
        // Slerp by hand between unit q0 = 1 and the short-way q1 = (cos 60, sin 60 * Y):
        // q(u) = (sin((1-u)θ) q0 + sin(uθ) q1) / sin θ with θ = 60 degrees, the
        // half-angle between them; the camera turns by 120 u degrees about +Y.
        const double theta = half;
        const double a = std::sin((1 - u) * theta) / std::sin(theta), b = std::sin(u * theta) / std::sin(theta);
        const glm::dquat q(a + b * std::cos(half), 0, b * std::sin(half), 0);
        const glm::dvec3 want = q * glm::dvec3(0, 0, -1);
        const double turn = 2 * kPi / 3 * u;
        expectNear(want, {-std::sin(turn), 0, -std::cos(turn)}, 1e-12, "the hand slerp");
        expectNear(forward(path.frames[f].camera), want, 1e-6, "forward at frame " + std::to_string(f));
        expectNear(path.frames[f].camera.up, {0, 1, 0}, 1e-6, "up");
        expectNear(path.frames[f].camera.position, {1, 2, 3}, 1e-12, "position (the node's own translation)");
    }
    // nlerp would turn 27.8 degrees at u = 0.25, slerp 30: the reader slerps.
    EXPECT_NEAR(std::atan2(-forward(path.frames[1].camera).x, -forward(path.frames[1].camera).z), kPi / 6, 1e-6);
}

TEST(CameraPathGltf, AnimatedParentsMoveTheCameraAndKeysClampOutsideTheirTimes) {
    ScratchDir s;
    AnimatedGltf g;
    const int cam = g.cameraNode("Cam", {{"translation", {0, 0, 2}}});
    const int boom = g.node({{"name", "Boom"}, {"children", {cam}}});
    const int rig = g.node({{"name", "Rig"}, {"translation", {0, 0, 10}}, {"children", {boom}}});
    g.scene({rig});
    const glm::dquat quarter = glm::angleAxis(kPi / 2, glm::dvec3(0, 1, 0));
    // The boom slides along x over 0..1 s, then turns a quarter about +Y over 1..2 s.
    g.animation("Crane", {{boom, "translation", {0, 1}, {0, 0, 0, 4, 0, 0}},
                          {boom, "rotation", {1, 2}, {0, 0, 0, 1, float(quarter.x), float(quarter.y), float(quarter.z), float(quarter.w)}}});
    const lc::CameraPath path = loadGltf(s.path / "crane.gltf", g, 2);
    EXPECT_EQ(path.description, "animation 'Crane' of crane.gltf: camera node 'Cam' (nodes[0]) and 1 animated ancestor, "
                                "0..2 s at 2 fps, 5 frames");
    ASSERT_EQ(path.frames.size(), 5u);
    // t = 0.5: halfway along, not yet turned (the rotation clamps to its first key).
    expectNear(path.frames[1].camera.position, {2, 0, 12}, 1e-6, "t = 0.5");
    expectNear(forward(path.frames[1].camera), {0, 0, -1}, 1e-6, "t = 0.5 forward");
    // t = 1.5: all the way along (the translation clamps to its last key), turned 45 degrees.
    const double r = std::sqrt(0.5);
    expectNear(path.frames[3].camera.position, {4 + 2 * r, 0, 10 + 2 * r}, 1e-6, "t = 1.5");
    expectNear(forward(path.frames[3].camera), {-r, 0, -r}, 1e-6, "t = 1.5 forward");
    // t = 2: a quarter turn: the camera's local +Z offset now points along +X.
    expectNear(path.frames[4].camera.position, {6, 0, 10}, 1e-6, "t = 2");
    expectNear(forward(path.frames[4].camera), {-1, 0, 0}, 1e-6, "t = 2 forward");

    // A scaled, animated parent: the world matrix carries the scale, the
    // camera's axes are normalised.
    g.doc["nodes"][std::size_t(boom)]["scale"] = {3, 3, 3};
    const lc::CameraPath scaled = loadGltf(s.path / "crane.gltf", g, 2);
    expectNear(scaled.frames[1].camera.position, {2, 0, 16}, 1e-6, "scaled, t = 0.5");
    expectNear(forward(scaled.frames[1].camera), {0, 0, -1}, 1e-6, "scaled forward");
    EXPECT_NEAR(glm::length(scaled.frames[1].camera.target - scaled.frames[1].camera.position), 5, 1e-9);
}

TEST(CameraPathGltf, TheFirstAnimationThatMovesTheCameraUnlessOneIsNamed) {
    ScratchDir s;
    AnimatedGltf g;
    const int cam = g.cameraNode("Cam");
    const int lamp = g.node({{"name", "Lamp"}});
    g.scene({lamp, cam});
    g.animation("Flicker", {{lamp, "translation", {0, 1}, {0, 0, 0, 0, 1, 0}}});
    g.animation("Fly", {{cam, "translation", {0, 1}, {0, 0, 0, 1, 0, 0}}});
    g.animation("Orbit", {{cam, "translation", {0, 3}, {0, 0, 0, 0, 0, 9}}});
    const fs::path p = s.path / "many.gltf";
    const lc::CameraPath fly = loadGltf(p, g, 4);
    EXPECT_EQ(fly.description, "animation 'Fly' of many.gltf: camera node 'Cam' (nodes[0]), 0..1 s at 4 fps, 5 frames; "
                               "the first of 2 animations that move it (also 'Orbit' (animations[2]))");
    for (const std::string& pick : {std::string("Orbit"), std::string("2")}) {
        const lc::CameraPath orbit = loadGltf(p, g, 4, pick);
        EXPECT_EQ(orbit.frames.size(), 13u) << pick;
        expectNear(orbit.frames.back().camera.position, {0, 0, 9}, 1e-6, pick);
        EXPECT_EQ(orbit.description.find("the first of"), std::string::npos) << orbit.description;
    }
    expectInputError([&] { loadGltf(p, g, 4, "Flicker"); }, p.string(),
                     {"animations[0]", 0, "'Flicker' (animations[0]) does not move the camera node 'Cam' (nodes[0])"});
    try {
        loadGltf(p, g, 4, "Dolly");
        ADD_FAILURE() << "no error for a missing animation";
    } catch (const lc::SettingsError& e) {
        EXPECT_EQ(e.field(), "animation");
        EXPECT_NE(std::string(e.what()).find("'Flicker' (animations[0]), 'Fly' (animations[1]), 'Orbit' (animations[2])"),
                  std::string::npos)
            << e.what();
    }
    g.doc["animations"][2]["name"] = "Fly";
    try {
        loadGltf(p, g, 4, "Fly");
        ADD_FAILURE() << "no error for an ambiguous animation name";
    } catch (const lc::SettingsError& e) {
        EXPECT_NE(std::string(e.what()).find("give the animation's index"), std::string::npos) << e.what();
    }
}

TEST(CameraPathGltf, TheCameraNodeIsTheOneTheSceneReaderPicks) {
    ScratchDir s;
    AnimatedGltf g;
    const int a = g.cameraNode("A");
    const int b = g.cameraNode("B");
    g.scene({a, b});
    g.animation("MoveA", {{a, "translation", {0, 1}, {0, 0, 0, 1, 0, 0}}});
    g.animation("MoveB", {{b, "translation", {0, 1}, {0, 0, 0, 0, 1, 0}}});
    const fs::path p = s.path / "two.gltf";
    EXPECT_EQ(loadGltf(p, g, 1).description.rfind("animation 'MoveA'", 0), 0u);
    const lc::CameraPath pb = loadGltf(p, g, 1, {}, "B");
    EXPECT_EQ(pb.description.rfind("animation 'MoveB' of two.gltf: camera node 'B' (nodes[1])", 0), 0u) << pb.description;
    expectNear(pb.frames.back().camera.position, {0, 1, 0}, 1e-6, "B at 1 s");
    EXPECT_THROW(loadGltf(p, g, 1, {}, "C"), lc::SettingsError);
}

TEST(CameraPathGltf, HostileFilesAreInputErrorsNamingTheJsonPath) {
    ScratchDir s;
    const fs::path p = s.path / "bad.gltf";
    // linearFlight: accessors[0] key times (SCALAR), accessors[1] translations
    // (VEC3), bufferViews alike; animations[0].samplers[0].
    struct Case {
        std::string what;
        std::function<void(AnimatedGltf&)> edit;
        Expected e;
        double fps = 4;
    };
    const std::vector<Case> cases = {
        {"no animations", [](AnimatedGltf& g) { g.doc.erase("animations"); },
         {"animations", 0, "no animation moves the camera node 'Cam' (nodes[0]) or its ancestors (the file has no animations)"}},
        {"an animation of another node",
         [](AnimatedGltf& g) {
             g.node({{"name", "Other"}});
             g.doc["animations"][0]["channels"][0]["target"]["node"] = 1;
         },
         {"animations", 0, "(the file has 'Fly' (animations[0]))"}},
        {"no camera node", [](AnimatedGltf& g) { g.doc["nodes"][0].erase("camera"); }, {"", 0, "no camera node in the scene"}},
        {"count past the view", [](AnimatedGltf& g) { g.doc["accessors"][0]["count"] = 4294967295u; },
         {"accessors[0].count", 0, "4,294,967,295 key times do not fit bufferViews[0] (12 bytes)"}},
        {"offset past the view", [](AnimatedGltf& g) { g.doc["accessors"][0]["byteOffset"] = 8; },
         {"accessors[0].count", 0, "do not fit bufferViews[0]"}},
        {"view past the buffer", [](AnimatedGltf& g) { g.doc["bufferViews"][1]["byteLength"] = 4000; },
         {"bufferViews[1]", 0, "run past the end of buffers[0]"}},
        {"stride below one element", [](AnimatedGltf& g) { g.doc["bufferViews"][1]["byteStride"] = 8; },
         {"bufferViews[1].byteStride", 0, "smaller than one element"}},
        {"input accessor out of range", [](AnimatedGltf& g) { g.doc["animations"][0]["samplers"][0]["input"] = 9; },
         {"animations[0].samplers[0].input", 0, "9 is not an index into accessors (2)"}},
        {"sampler out of range", [](AnimatedGltf& g) { g.doc["animations"][0]["channels"][0]["sampler"] = 3; },
         {"animations[0].channels[0].sampler", 0, "3 is not an index into the animation's samplers (1)"}},
        {"channel node out of range",
         [](AnimatedGltf& g) {
             g.doc["animations"][0]["channels"].push_back({{"sampler", 0}, {"target", {{"node", 7}, {"path", "scale"}}}});
         },
         {"animations[0].channels[1].target.node", 0, "7 is not an index into nodes (1)"}},
        {"decreasing times",
         [](AnimatedGltf& g) {
             const float t[3] = {0, 1.5f, 1};
             std::memcpy(g.bin.data(), t, 12);
         },
         {"accessors[0]", 0, "key time 2 (1 s) comes before key time 1 (1.5 s)"}},
        {"NaN time",
         [](AnimatedGltf& g) {
             const float nan = std::numeric_limits<float>::quiet_NaN();
             std::memcpy(g.bin.data() + 4, &nan, 4);
         },
         {"accessors[0]", 0, "element 1 is not finite"}},
        {"infinite translation",
         [](AnimatedGltf& g) {
             const float inf = std::numeric_limits<float>::infinity();
             std::memcpy(g.bin.data() + 12 + 4, &inf, 4);
         },
         {"accessors[1]", 0, "element 0 is not finite"}},
        {"times not FLOAT", [](AnimatedGltf& g) { g.doc["accessors"][0]["componentType"] = 5123; },
         {"accessors[0].componentType", 0, "5123 is not FLOAT (5126)"}},
        {"times not SCALAR", [](AnimatedGltf& g) { g.doc["accessors"][0]["type"] = "VEC2"; },
         {"accessors[0].type", 0, "key times must be SCALAR"}},
        {"translation as VEC4", [](AnimatedGltf& g) { g.doc["accessors"][1]["type"] = "VEC4"; },
         {"accessors[1].type", 0, "translation keys must be VEC3"}},
        {"sparse keys",
         [](AnimatedGltf& g) {
             g.doc["accessors"][1]["sparse"] = {{"count", 1},
                                                {"indices", {{"bufferView", 0}, {"componentType", 5121}}},
                                                {"values", {{"bufferView", 1}}}};
         },
         {"accessors[1].sparse", 0, "sparse accessors are not read for animations"}},
        {"keys without data", [](AnimatedGltf& g) { g.doc["accessors"][1].erase("bufferView"); },
         {"accessors[1].bufferView", 0, "missing: translation keys need data"}},
        {"wrong output count", [](AnimatedGltf& g) { g.doc["accessors"][1]["count"] = 2; },
         {"accessors[1].count", 0, "2 elements for 3 key times: LINEAR and STEP need one per key"}},
        {"CUBICSPLINE with one value per key",
         [](AnimatedGltf& g) { g.doc["animations"][0]["samplers"][0]["interpolation"] = "CUBICSPLINE"; },
         {"accessors[1].count", 0, "CUBICSPLINE needs 3 per key"}},
        {"unknown interpolation", [](AnimatedGltf& g) { g.doc["animations"][0]["samplers"][0]["interpolation"] = "QUADRATIC"; },
         {"animations[0].samplers[0].interpolation", 0, "'QUADRATIC' is not LINEAR, STEP or CUBICSPLINE"}},
        {"an animated node with a matrix",
         [](AnimatedGltf& g) { g.doc["nodes"][0]["matrix"] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}; },
         {"nodes[0].matrix", 0, "the node is animated by animations[0] but has a matrix"}},
        {"one property animated twice",
         [](AnimatedGltf& g) { g.doc["animations"][0]["channels"].push_back(g.doc["animations"][0]["channels"][0]); },
         {"animations[0].channels[1]", 0, "animates nodes[0].translation again (as channels[0] does)"}},
        {"longer than the frames allowed",
         [](AnimatedGltf& g) {
             const float t[3] = {0, 1, 3334};
             std::memcpy(g.bin.data(), t, 12);
         },
         {"animations[0]", 0, "at 30 fps that is 100021 frames, more than the 100000"}, 30},
        {"a scale to zero",
         [](AnimatedGltf& g) {
             AnimatedGltf z;
             const int cam = z.cameraNode("Cam");
             z.scene({cam});
             z.animation("Shrink", {{cam, "scale", {0, 1}, {1, 1, 1, 0, 0, 0}}});
             g = z;
         },
         {"animations[0]", 0, "at 1 s (frame 4) the camera node 'Cam' (nodes[0])'s world transform is singular"}},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.what);
        AnimatedGltf g = linearFlight();
        c.edit(g);
        writeText(p, g.gltfText());
        expectInputError([&] { lc::loadCameraPath(p.string(), baseCamera(), c.fps); }, p.string(), c.e);
    }

    // Rotation keys as normalised shorts (KHR_animation... exporters may
    // write them): refused with what to do instead.
    AnimatedGltf g;
    const int cam = g.cameraNode("Cam");
    g.scene({cam});
    g.animation("Pan", {{cam, "rotation", {0, 1}, {0, 0, 0, 1, 0, 1, 0, 0}}});
    g.doc["accessors"][1]["componentType"] = 5122;
    g.doc["accessors"][1]["normalized"] = true;
    writeText(p, g.gltfText());
    expectInputError([&] { lc::loadCameraPath(p.string(), baseCamera()); }, p.string(),
                     {"accessors[1].componentType", 0, "rotation keys as normalised integers are not read; export float keys"});
    // A zero quaternion key.
    g.doc["accessors"][1]["componentType"] = 5126;
    g.doc["accessors"][1].erase("normalized");
    std::memset(g.bin.data() + 8, 0, 16);
    writeText(p, g.gltfText());
    expectInputError([&] { lc::loadCameraPath(p.string(), baseCamera()); }, p.string(),
                     {"accessors[1]", 0, "rotation key 0 is a zero quaternion"});
    // Not glTF at all, under a glTF name.
    writeText(p, "{\"cameras\": [{}]}");
    EXPECT_THROW(lc::loadCameraPath(p.string(), baseCamera()), lc::InputError);
}
