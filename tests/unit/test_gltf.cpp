// glTF 2.0 scenes (culling/scene/gltf_io.hpp): round trips through .glb and .gltf,
// every geometry feature the reader claims (docs/FORMATS.md), lights and
// cameras with their conventions, and hostile files, each of which must be a
// one-line InputError naming the file and the JSON path.
#include "cli_support.hpp"

#include "culling/core/errors.hpp"
#include "culling/scene/gltf_io.hpp"
#include "culling/scene/scene_io.hpp"

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <fstream>

using lc_test::ScratchDir;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

constexpr double kPi = 3.14159265358979323846;

// A glTF document under construction: JSON plus one binary buffer, written as
// .gltf (buffer as data: URI or external .bin) or .glb.
struct GltfBuilder {
    json doc = {{"asset", {{"version", "2.0"}}}};
    std::string bin;

    template <typename T>
    int view(const std::vector<T>& data, std::size_t stride = 0) {
        while (bin.size() % 4) bin.push_back('\0');
        json v = {{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", data.size() * sizeof(T)}};
        if (stride) v["byteStride"] = stride;
        bin.append(reinterpret_cast<const char*>(data.data()), data.size() * sizeof(T));
        doc["bufferViews"].push_back(v);
        return int(doc["bufferViews"].size() - 1);
    }
    int accessor(int bufferView, int componentType, std::size_t count, const char* type, bool normalized = false) {
        json a = {{"componentType", componentType}, {"count", count}, {"type", type}};
        if (bufferView >= 0) a["bufferView"] = bufferView;
        if (normalized) a["normalized"] = true;
        doc["accessors"].push_back(a);
        return int(doc["accessors"].size() - 1);
    }
    int positions(const std::vector<float>& xyz) {
        return accessor(view(xyz), 5126, xyz.size() / 3, "VEC3");
    }
    int mesh(json primitives, const std::string& name = "") {
        json m = {{"primitives", primitives}};
        if (!name.empty()) m["name"] = name;
        doc["meshes"].push_back(m);
        return int(doc["meshes"].size() - 1);
    }
    int node(json n) {
        doc["nodes"].push_back(n);
        return int(doc["nodes"].size() - 1);
    }
    void scene(std::vector<int> roots) { doc["scenes"] = json::array({{{"nodes", roots}}}), doc["scene"] = 0; }

    json withBuffer(const std::string& uri) const {
        json d = doc;
        if (!bin.empty()) {
            json b = {{"byteLength", bin.size()}};
            if (!uri.empty()) b["uri"] = uri;
            d["buffers"] = json::array({b});
        }
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
    // .gltf with the buffer inline as a data: URI.
    std::string gltfText() const { return withBuffer("data:application/octet-stream;base64," + base64(bin)).dump(); }
    std::string glb() const { return glbWithJson(withBuffer("").dump()); }
    // A GLB of this binary chunk around JSON text given as it is.
    std::string glbWithJson(std::string js) const {
        while (js.size() % 4) js += ' ';
        std::string b = bin;
        while (b.size() % 4) b.push_back('\0');
        std::string out = "glTF";
        auto u32 = [&](std::uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
        u32(2);
        u32(std::uint32_t(12 + 8 + js.size() + (b.empty() ? 0 : 8 + b.size())));
        u32(std::uint32_t(js.size()));
        u32(0x4E4F534A);
        out += js;
        if (!b.empty()) {
            u32(std::uint32_t(b.size()));
            u32(0x004E4942);
            out += b;
        }
        return out;
    }
};

void writeBytes(const fs::path& p, const std::string& bytes) {
    std::ofstream(p, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}

// One triangle, reused by the camera and light tests.
GltfBuilder oneTriangle() {
    GltfBuilder b;
    const int pos = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
    b.mesh(json::array({{{"attributes", {{"POSITION", pos}}}}}), "tri");
    return b;
}

glm::dvec3 worldVertex(const lc::Mesh& m, std::uint32_t corner) {
    return glm::dvec3(m.transform * glm::dvec4(glm::dvec3(m.vertex(m.indices[corner])), 1.0));
}

std::string loadError(const fs::path& p, const lc::GltfReadOptions& o = {}) {
    try {
        lc::loadGltfScene(p.string(), o);
    } catch (const lc::InputError& e) {
        return e.what();
    } catch (const lc::Error& e) {
        return std::string("(not an InputError) ") + e.what();
    }
    return "(no error)";
}

void expectSameScene(const lc::Scene& a, const lc::Scene& b) {
    ASSERT_EQ(a.triangleCount(), b.triangleCount());
    // Triangles in world space, corner by corner (the writer keeps the order).
    std::vector<glm::dvec3> wa, wb;
    for (const auto& m : a.meshes)
        for (std::size_t k = 0; k < m.indices.size(); ++k) wa.push_back(worldVertex(m, std::uint32_t(k)));
    for (const auto& m : b.meshes)
        for (std::size_t k = 0; k < m.indices.size(); ++k) wb.push_back(worldVertex(m, std::uint32_t(k)));
    ASSERT_EQ(wa.size(), wb.size());
    for (std::size_t k = 0; k < wa.size(); ++k) ASSERT_LT(glm::length(wa[k] - wb[k]), 1e-4) << "corner " << k;
    ASSERT_EQ(a.lights.size(), b.lights.size());
    for (std::size_t i = 0; i < a.lights.size(); ++i) {
        const auto &la = a.lights[i], &lb = b.lights[i];
        EXPECT_EQ(la.name, lb.name);
        EXPECT_EQ(la.kind, lb.kind) << la.name;
        EXPECT_LT(glm::length(la.position - lb.position), 1e-9) << la.name;
        EXPECT_LT(glm::length(la.color - lb.color), 1e-12) << la.name;
        EXPECT_DOUBLE_EQ(la.intensity, lb.intensity) << la.name;
        EXPECT_DOUBLE_EQ(la.minIntensity, lb.minIntensity) << la.name;
        EXPECT_NEAR(la.radius(), lb.radius(), 1e-9 * la.radius()) << la.name;
        EXPECT_EQ(la.explicitRadius > 0, lb.explicitRadius > 0) << la.name;
        if (la.isSpot()) {
            EXPECT_LT(glm::length(glm::normalize(la.direction) - glm::normalize(lb.direction)), 1e-9) << la.name;
            EXPECT_NEAR(la.outerAngleDeg, lb.outerAngleDeg, 1e-9) << la.name;
            EXPECT_NEAR(la.innerAngleDeg, lb.innerAngleDeg, 1e-9) << la.name;
        }
    }
    const lc::Camera &ca = a.camera, &cb = b.camera;
    EXPECT_EQ(ca.projection, cb.projection);
    EXPECT_EQ(ca.width, cb.width);
    EXPECT_EQ(ca.height, cb.height);
    EXPECT_EQ(ca.tileSize, cb.tileSize);
    EXPECT_NEAR(ca.fovYDeg, cb.fovYDeg, 1e-9);
    EXPECT_NEAR(ca.nearPlane, cb.nearPlane, 1e-12);
    EXPECT_EQ(std::isinf(ca.farPlane), std::isinf(cb.farPlane));
    if (!std::isinf(ca.farPlane)) EXPECT_NEAR(ca.farPlane, cb.farPlane, 1e-9);
    if (lc::isOrthographic(ca.projection)) EXPECT_NEAR(ca.orthoHeight, cb.orthoHeight, 1e-9);
    const glm::dmat4 va = ca.viewFromWorld(), vb = cb.viewFromWorld();
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) EXPECT_NEAR(va[c][r], vb[c][r], 1e-9) << "view matrix [" << c << "][" << r << "]";
    EXPECT_NEAR(glm::length(ca.target - ca.position), glm::length(cb.target - cb.position), 1e-9);
}

} // namespace

TEST(Gltf, BuiltinScenesRoundTripThroughGlbAndGltf) {
    ScratchDir s;
    for (const char* name : {"atrium", "forest"}) {
        lc::Scene scene = lc::makeBuiltinScene(name);
        lc::LightGenSettings g = lc::defaultLightGen(scene, 40, 3);
        g.spotFraction = 0.5;
        scene.lights = lc::generateLights(g);
        scene.lights[0].explicitRadius = 2.5; // one explicit radius among inverse-square ones
        std::size_t hard = scene.lights.size();
        for (std::size_t i = 0; i < scene.lights.size(); ++i) {
            auto& l = scene.lights[i];
            if (!l.isSpot()) continue;
            // One hard-edged spot: KHR_lights_punctual wants inner < outer.
            if (hard == scene.lights.size()) hard = i;
            l.innerAngleDeg = i == hard ? l.outerAngleDeg : 0.5 * l.outerAngleDeg;
        }
        ASSERT_LT(hard, scene.lights.size());
        for (const char* ext : {".glb", ".gltf"}) {
            // A file name other than the scene's: the name comes from scenes[].name.
            const fs::path p = s.path / (std::string("copy_of_") + name + ext);
            lc::saveSceneAny(scene, p.string());
            SCOPED_TRACE(p.string());
            const lc::Scene back = lc::loadSceneAny(p.string());
            expectSameScene(scene, back);
            EXPECT_EQ(back.name, scene.name);
            EXPECT_NEAR(back.lights[hard].innerAngleDeg, back.lights[hard].outerAngleDeg, 1e-12);
            if (std::string(ext) == ".gltf") {
                const json doc = json::parse(lc_test::slurp(p));
                for (const auto& l : doc["extensions"]["KHR_lights_punctual"]["lights"])
                    if (l.contains("spot"))
                        EXPECT_LT(l["spot"].value("innerConeAngle", 0.0), l["spot"]["outerConeAngle"].get<double>()) << l;
            }
        }
    }
}

TEST(Gltf, EveryProjectionRoundTrips) {
    ScratchDir s;
    const lc::ProjectionKind kinds[] = {lc::ProjectionKind::Perspective, lc::ProjectionKind::PerspectiveGL,
                                        lc::ProjectionKind::ReversedZ, lc::ProjectionKind::Orthographic,
                                        lc::ProjectionKind::OrthographicGL};
    for (const auto kind : kinds) {
        lc::Scene scene = lc::makeBuiltinScene("atrium");
        scene.camera.projection = kind;
        scene.camera.width = 333;
        scene.camera.height = 201;
        scene.camera.tileSize = 24;
        scene.camera.orthoHeight = 17.5;
        if (kind == lc::ProjectionKind::ReversedZ) scene.camera.farPlane = std::numeric_limits<double>::infinity();
        const fs::path p = s.path / "cam.glb";
        lc::saveGltfScene(scene, p.string());
        SCOPED_TRACE(lc::toString(kind));
        expectSameScene(scene, lc::loadGltfScene(p.string()));
    }
}

TEST(Gltf, GeometryFeatures) {
    ScratchDir s;
    GltfBuilder b;
    // A unit quad as a strip (4 vertices, unsigned byte indices), as a fan
    // (unsigned short indices) and as non-indexed triangles.
    const int quad = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0});
    const int strip = b.accessor(b.view(std::vector<std::uint8_t>{0, 1, 2, 3}), 5121, 4, "SCALAR");
    const int fanPos = b.positions({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0});
    const int fan = b.accessor(b.view(std::vector<std::uint16_t>{0, 1, 2, 3}), 5123, 4, "SCALAR");
    const int soup = b.positions({0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 1, 0, 1, 0});
    // KHR_mesh_quantization: normalised shorts, 32767 = 1.0, -32767 = -1.0.
    const int quant = b.accessor(b.view(std::vector<std::int16_t>{0, 0, 0, 32767, 0, 0, 0, -32767, 0}), 5122, 3, "VEC3", true);
    // A sparse accessor: 3 zero vertices, vertex 1 and 2 substituted.
    const int sparse = b.accessor(-1, 5126, 3, "VEC3");
    b.doc["accessors"][std::size_t(sparse)]["sparse"] = {
        {"count", 2},
        {"indices", {{"bufferView", b.view(std::vector<std::uint32_t>{1, 2})}, {"componentType", 5125}}},
        {"values", {{"bufferView", b.view(std::vector<float>{2, 0, 0, 0, 2, 0})}}}};
    const int lines = b.accessor(b.view(std::vector<std::uint32_t>{0, 1}), 5125, 2, "SCALAR");
    const int meshA = b.mesh(json::array({{{"attributes", {{"POSITION", quad}}}, {"indices", strip}, {"mode", 5}},
                                          {{"attributes", {{"POSITION", fanPos}}}, {"indices", fan}, {"mode", 6}},
                                          {{"attributes", {{"POSITION", soup}}}},
                                          {{"attributes", {{"POSITION", quad}}}, {"indices", lines}, {"mode", 1}}}),
                             "mixed");
    const int meshB = b.mesh(json::array({{{"attributes", {{"POSITION", quant}}}},
                                          {{"attributes", {{"POSITION", sparse}}}}}),
                             "packed");
    // The hierarchy: a parent translated by (10,0,0) and scaled 2x, with two
    // children instancing meshA (one rotated 90 degrees about +Y by a matrix)
    // and meshB once at the root.
    const glm::dmat4 rot = glm::rotate(glm::dmat4(1.0), kPi / 2, glm::dvec3(0, 1, 0));
    std::vector<double> rm;
    for (int k = 0; k < 16; ++k) rm.push_back(rot[k / 4][k % 4]);
    const int c1 = b.node({{"mesh", meshA}});
    const int c2 = b.node({{"mesh", meshA}, {"matrix", rm}});
    const int parent = b.node({{"children", {c1, c2}}, {"translation", {10, 0, 0}}, {"scale", {2, 2, 2}}});
    const int packed = b.node({{"mesh", meshB}, {"translation", {0, 5, 0}}});
    b.node({{"mesh", meshB}}); // in no scene: must not be read
    b.scene({parent, packed});
    b.doc["extensionsUsed"] = {"KHR_mesh_quantization"};
    b.doc["extensionsRequired"] = {"KHR_mesh_quantization"};

    const fs::path glb = s.path / "features.glb", gltf = s.path / "features.gltf";
    writeBytes(glb, b.glb());
    writeBytes(gltf, b.gltfText());
    // External .bin beside a .gltf.
    writeBytes(s.path / "features_ext.bin", b.bin);
    writeBytes(s.path / "features_ext.gltf", b.withBuffer("features_ext.bin").dump());

    for (const fs::path& p : {glb, gltf, s.path / "features_ext.gltf"}) {
        SCOPED_TRACE(p.string());
        lc::GltfReadReport rep;
        const lc::Scene sc = lc::loadGltfScene(p.string(), {}, &rep);
        ASSERT_EQ(sc.meshes.size(), 1u);
        const lc::Mesh& m = sc.meshes[0];
        // meshA: strip 2 + fan 2 + soup 2 = 6 triangles, twice; meshB: 1 + 1.
        EXPECT_EQ(m.triangleCount(), 14u);
        // The lines primitive is skipped with a warning naming its mesh.
        bool warned = false;
        for (const auto& w : rep.warnings) warned |= w.find("'mixed'") != std::string::npos && w.find("lines") != std::string::npos;
        EXPECT_TRUE(warned);
        // Every triangle, in order, with its winding: the same corners in the
        // same cyclic order as the specification gives them (glTF 2.0,
        // 3.7.2.1: strip triangle i is {v_i, v_i+(1+i%2), v_i+(2-i%2)}, so odd
        // ones swap two corners; fan triangle i is {v_i+1, v_i+2, v_0}). A
        // reader that winds the second strip or fan triangle the other way
        // draws it facing away.
        {
            using V = glm::dvec3;
            struct Tri {
                V a, b, c;
            };
            const V q0(0, 0, 0), q1(1, 0, 0), q2(0, 1, 0), q3(1, 1, 0); // the strip's quad
            const V f0(0, 0, 0), f1(1, 0, 0), f2(1, 1, 0), f3(0, 1, 0); // the fan's
            const std::vector<Tri> meshA = {
                {q0, q1, q2}, {q1, q3, q2},                           // strip: i = 0, 1
                {f1, f2, f0}, {f2, f3, f0},                           // fan: i = 0, 1
                {V(0, 0, 0), V(1, 0, 0), V(0, 0, 1)}, {V(0, 0, 0), V(0, 0, 1), V(0, 1, 0)}}; // soup
            const std::vector<Tri> meshB = {{V(0, 0, 0), V(1, 0, 0), V(0, -1, 0)},  // quantised
                                            {V(0, 0, 0), V(2, 0, 0), V(0, 2, 0)}}; // sparse
            // The instances: x' = 10 + 2x; 10 + 2 R(x) with R 90 degrees about
            // +Y, (x, y, z) -> (z, y, -x); meshB at +5 in y.
            const auto first = [](V v) { return V(10, 0, 0) + 2.0 * v; };
            const auto second = [](V v) { return V(10, 0, 0) + 2.0 * V(v.z, v.y, -v.x); };
            const auto packedAt = [](V v) { return v + V(0, 5, 0); };
            std::vector<Tri> want;
            for (const Tri& t : meshA) want.push_back({first(t.a), first(t.b), first(t.c)});
            for (const Tri& t : meshA) want.push_back({second(t.a), second(t.b), second(t.c)});
            for (const Tri& t : meshB) want.push_back({packedAt(t.a), packedAt(t.b), packedAt(t.c)});
            ASSERT_EQ(m.triangleCount(), want.size());
            const auto near = [](V x, V y) { return glm::length(x - y) < 1e-4; }; // quantised: 1/32767
            for (std::size_t t = 0; t < want.size(); ++t) {
                const V got[3] = {worldVertex(m, std::uint32_t(3 * t)), worldVertex(m, std::uint32_t(3 * t + 1)),
                                  worldVertex(m, std::uint32_t(3 * t + 2))};
                const V w[3] = {want[t].a, want[t].b, want[t].c};
                bool same = false; // equal up to a cyclic rotation: the same triangle, wound the same way
                for (int r = 0; r < 3 && !same; ++r)
                    same = near(got[0], w[r]) && near(got[1], w[(r + 1) % 3]) && near(got[2], w[(r + 2) % 3]);
                EXPECT_TRUE(same) << "triangle " << t << ": (" << got[0].x << "," << got[0].y << "," << got[0].z
                                  << ") (" << got[1].x << "," << got[1].y << "," << got[1].z << ") (" << got[2].x
                                  << "," << got[2].y << "," << got[2].z << ")";
            }
        }
        // First instance: x' = 10 + 2x.
        EXPECT_LT(glm::length(worldVertex(m, 0) - glm::dvec3(10, 0, 0)), 1e-6);
        EXPECT_LT(glm::length(worldVertex(m, 1) - glm::dvec3(12, 0, 0)), 1e-6);
        EXPECT_LT(glm::length(worldVertex(m, 2) - glm::dvec3(10, 2, 0)), 1e-6);
        // Second instance (corner 18 = first corner of its strip): the quad's
        // (1,0,0) corner rotated about +Y goes to (0,0,-1), then x2 and +10.
        EXPECT_LT(glm::length(worldVertex(m, 19) - glm::dvec3(10, 0, -2)), 1e-6);
        // meshB at +5 in y: the quantised triangle spans x in [0, 1], y in [4, 5].
        EXPECT_LT(glm::length(worldVertex(m, 36) - glm::dvec3(0, 5, 0)), 1e-6);
        EXPECT_LT(glm::length(worldVertex(m, 37) - glm::dvec3(1, 5, 0)), 1e-4);
        EXPECT_LT(glm::length(worldVertex(m, 38) - glm::dvec3(0, 4, 0)), 1e-4);
        // The sparse triangle: (0,0,0), (2,0,0), (0,2,0) at +5 in y.
        EXPECT_LT(glm::length(worldVertex(m, 40) - glm::dvec3(2, 5, 0)), 1e-6);
        EXPECT_LT(glm::length(worldVertex(m, 41) - glm::dvec3(0, 7, 0)), 1e-6);
        // loadMesh (Import, and a scene JSON's "path") gives the same geometry.
        const lc::Mesh viaLoadMesh = lc::loadMesh(p.string());
        EXPECT_EQ(viaLoadMesh.positions, m.positions);
        EXPECT_EQ(viaLoadMesh.indices, m.indices);
    }
}

TEST(Gltf, SceneJsonReferencesAGlbAsAMesh) {
    ScratchDir s;
    lc::Scene scene = lc::makeBuiltinScene("atrium");
    lc::saveGltfScene(scene, (s.path / "atrium.glb").string());
    // Converting the glb to scene JSON writes a mesh "path" to the glb.
    const lc::Scene fromGlb = lc::loadGltfScene((s.path / "atrium.glb").string());
    lc::saveSceneFile(fromGlb, (s.path / "atrium.json").string());
    const json j = json::parse(lc_test::slurp(s.path / "atrium.json"));
    EXPECT_EQ(j["meshes"][0]["path"], "atrium.glb");
    expectSameScene(fromGlb, lc::loadSceneFile((s.path / "atrium.json").string()));
}

TEST(Gltf, LightsFollowTheirNodes) {
    ScratchDir s;
    GltfBuilder b = oneTriangle();
    b.doc["extensionsUsed"] = {"KHR_lights_punctual"};
    b.doc["extensions"]["KHR_lights_punctual"]["lights"] = json::array({
        {{"type", "point"}, {"name", "ranged"}, {"intensity", 50.0}, {"range", 3.0}, {"color", {1.0, 0.5, 0.25}}},
        {{"type", "point"}, {"intensity", 4.0}, {"color", {0.5, 1.0, 0.5}}},
        {{"type", "spot"}, {"name", "spot"}, {"intensity", 9.0}, {"range", 7.0},
         {"spot", {{"innerConeAngle", 0.2}, {"outerConeAngle", 0.6}}}},
        {{"type", "directional"}, {"name", "sun"}}});
    auto lightNode = [](int i) { return json{{"extensions", {{"KHR_lights_punctual", {{"light", i}}}}}}; };
    json n0 = lightNode(0);
    n0["translation"] = {1, 2, 3};
    json n1 = lightNode(1);
    n1["name"] = "unnamed-light-node";
    // The spot: rotated 90 degrees about +X, so its -Z points down -Y... then
    // +Y: rotation about +X by +90 takes -Z to +Y.
    json n2 = lightNode(2);
    const glm::dquat q = glm::angleAxis(kPi / 2, glm::dvec3(1, 0, 0));
    n2["rotation"] = {q.x, q.y, q.z, q.w};
    const int spot = b.node(n2);
    const int l0 = b.node(n0), l1 = b.node(n1), sun = b.node(lightNode(3));
    const int scaled = b.node({{"children", {l0}}, {"scale", {2, 2, 2}}, {"translation", {0, 0, -5}}});
    const int tri = b.node({{"mesh", 0}});
    b.scene({tri, scaled, l1, spot, sun});
    const fs::path p = s.path / "lights.gltf";
    writeBytes(p, b.gltfText());

    lc::GltfReadOptions o;
    o.minIntensity = 0.25;
    lc::GltfReadReport rep;
    const lc::Scene sc = lc::loadGltfScene(p.string(), o, &rep);
    ASSERT_EQ(sc.lights.size(), 3u); // the directional light is skipped
    const auto& ranged = sc.lights[0];
    EXPECT_EQ(ranged.name, "ranged");
    EXPECT_LT(glm::length(ranged.position - glm::dvec3(2, 4, 1)), 1e-12); // 2 x (1,2,3) + (0,0,-5)
    EXPECT_DOUBLE_EQ(ranged.radius(), 3.0); // KHR_lights_punctual: the node's scale leaves the range
    EXPECT_LT(glm::length(ranged.color - glm::dvec3(1, 0.5, 0.25)), 1e-15);
    EXPECT_DOUBLE_EQ(ranged.intensity, 50.0);
    const auto& noRange = sc.lights[1];
    EXPECT_EQ(noRange.name, "unnamed-light-node");
    EXPECT_DOUBLE_EQ(noRange.radius(), std::sqrt(4.0 * 1.0 / 0.25)); // inverse square at I_min 0.25
    const auto& sp = sc.lights[2];
    ASSERT_TRUE(sp.isSpot());
    EXPECT_LT(glm::length(glm::normalize(sp.direction) - glm::dvec3(0, 1, 0)), 1e-12);
    EXPECT_NEAR(sp.outerAngleDeg, 0.6 * 180 / kPi, 1e-12);
    EXPECT_NEAR(sp.innerAngleDeg, 0.2 * 180 / kPi, 1e-12);
    EXPECT_DOUBLE_EQ(sp.radius(), 7.0);
    bool warned = false;
    for (const auto& w : rep.warnings) warned |= w.find("directional light 'sun'") != std::string::npos;
    EXPECT_TRUE(warned);
    EXPECT_EQ(rep.warnings.size(), 1u); // nothing else to say of this file
    // I_min must be usable.
    o.minIntensity = 0.0;
    EXPECT_THROW(lc::loadGltfScene(p.string(), o), lc::SettingsError);
    // An inner cone past the outer one is taken as the outer, and said so.
    b.doc["extensions"]["KHR_lights_punctual"]["lights"][2]["spot"]["innerConeAngle"] = 0.7;
    writeBytes(p, b.gltfText());
    lc::GltfReadReport rep2;
    const lc::Scene sc2 = lc::loadGltfScene(p.string(), {}, &rep2);
    EXPECT_DOUBLE_EQ(sc2.lights[2].innerAngleDeg, sc2.lights[2].outerAngleDeg);
    bool coneWarned = false;
    for (const auto& w : rep2.warnings) coneWarned |= w.find("innerConeAngle of light 'spot' is past its outerConeAngle") != std::string::npos;
    EXPECT_TRUE(coneWarned);
    // A spot under a zero scale has no direction: the error says why.
    b.doc["nodes"][std::size_t(spot)]["scale"] = {0, 0, 0};
    writeBytes(p, b.gltfText());
    const std::string msg = loadError(p);
    EXPECT_NE(msg.find("light 'spot': its direction, the node's -Z axis, is zero (a zero scale?)"), std::string::npos) << msg;
    // A written range of 0 is refused (KHR_lights_punctual: range > 0), not
    // read as no range (tinygltf gives 0 for both).
    b.doc["nodes"][std::size_t(spot)].erase("scale");
    b.doc["extensions"]["KHR_lights_punctual"]["lights"][1]["range"] = 0.0;
    writeBytes(p, b.gltfText());
    const std::string zero = loadError(p);
    EXPECT_NE(zero.find("extensions.KHR_lights_punctual.lights[1].range: must be > 0"), std::string::npos) << zero;
}

TEST(Gltf, CamerasAreChosenAndConverted) {
    ScratchDir s;
    GltfBuilder b = oneTriangle();
    b.doc["cameras"] = json::array({
        {{"type", "perspective"}, {"name", "wide"}, {"perspective", {{"yfov", 1.2}, {"znear", 0.05}, {"zfar", 80.0}, {"aspectRatio", 2.0}}}},
        {{"type", "perspective"}, {"name", "endless"}, {"perspective", {{"yfov", 0.8}, {"znear", 0.1}}}},
        {{"type", "orthographic"}, {"name", "plan"}, {"orthographic", {{"xmag", 8.0}, {"ymag", 4.0}, {"znear", 0.5}, {"zfar", 50.0}}}}});
    const glm::dquat yaw = glm::angleAxis(kPi / 2, glm::dvec3(0, 1, 0)); // -Z turns to -X
    const int tri = b.node({{"mesh", 0}});
    const int ortho = b.node({{"camera", 2}, {"name", "plan-node"}, {"translation", {0, 0, 10}}});
    const int wide = b.node({{"camera", 0}, {"translation", {5, 1, 0}}, {"rotation", {yaw.x, yaw.y, yaw.z, yaw.w}}});
    const int endless = b.node({{"camera", 1}, {"translation", {0, 0, 4}}});
    // Node order: the grouping node's child (the ortho camera) comes first.
    const int group = b.node({{"children", {ortho}}});
    b.scene({tri, group, wide, endless});
    const fs::path p = s.path / "cams.gltf";
    writeBytes(p, b.gltfText());

    lc::GltfReadReport rep;
    const lc::Camera first = lc::loadGltfScene(p.string(), {}, &rep).camera;
    EXPECT_EQ(first.projection, lc::ProjectionKind::Orthographic);
    EXPECT_DOUBLE_EQ(first.orthoHeight, 8.0);
    EXPECT_EQ(first.height, 640u); // 1280 / (xmag / ymag)
    EXPECT_NE(rep.camera.find("'plan'"), std::string::npos) << rep.camera;

    lc::GltfReadOptions o;
    o.camera = "wide";
    const lc::Camera w = lc::loadGltfScene(p.string(), o).camera;
    EXPECT_EQ(w.projection, lc::ProjectionKind::Perspective);
    EXPECT_NEAR(w.fovYDeg, 1.2 * 180 / kPi, 1e-12);
    EXPECT_DOUBLE_EQ(w.nearPlane, 0.05);
    EXPECT_DOUBLE_EQ(w.farPlane, 80.0);
    EXPECT_EQ(w.height, 640u);
    EXPECT_LT(glm::length(w.position - glm::dvec3(5, 1, 0)), 1e-12);
    EXPECT_LT(glm::length(glm::normalize(w.target - w.position) - glm::dvec3(-1, 0, 0)), 1e-12);

    o.camera = "1"; // an index into cameras
    const lc::Camera e = lc::loadGltfScene(p.string(), o).camera;
    EXPECT_EQ(e.projection, lc::ProjectionKind::ReversedZ); // no zfar: infinite far plane
    EXPECT_TRUE(std::isinf(e.farPlane));

    o.camera = "plan-node"; // a node name works too
    EXPECT_EQ(lc::loadGltfScene(p.string(), o).camera.projection, lc::ProjectionKind::Orthographic);

    o.camera = "missing";
    try {
        lc::loadGltfScene(p.string(), o);
        ADD_FAILURE() << "no error for a missing camera";
    } catch (const lc::SettingsError& err) {
        EXPECT_NE(std::string(err.what()).find("'missing'"), std::string::npos) << err.what();
        EXPECT_NE(std::string(err.what()).find("0 'wide'"), std::string::npos) << err.what();
    }

    // A name two cameras answer to (here the endless camera's node is named
    // like the wide camera) is refused, not settled by node order.
    b.doc["nodes"][std::size_t(endless)]["name"] = "wide";
    writeBytes(p, b.gltfText());
    o.camera = "wide";
    try {
        lc::loadGltfScene(p.string(), o);
        ADD_FAILURE() << "no error for an ambiguous camera name";
    } catch (const lc::SettingsError& err) {
        EXPECT_NE(std::string(err.what()).find("'wide' names more than one camera"), std::string::npos) << err.what();
        EXPECT_NE(std::string(err.what()).find("give the camera's index"), std::string::npos) << err.what();
    }
    o.camera = "0";
    EXPECT_EQ(lc::loadGltfScene(p.string(), o).camera.projection, lc::ProjectionKind::Perspective);
}

TEST(Gltf, WithoutACameraTheSceneIsFramed) {
    ScratchDir s;
    GltfBuilder b;
    // A 2 m model far from the origin.
    const int pos = b.positions({100, 0, 50, 102, 0, 50, 100, 2, 52, 101, 1, 51});
    const int ind = b.accessor(b.view(std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}), 5125, 6, "SCALAR");
    b.mesh(json::array({{{"attributes", {{"POSITION", pos}}}, {"indices", ind}}}));
    b.scene({b.node({{"mesh", 0}})});
    const fs::path p = s.path / "nocam.glb";
    writeBytes(p, b.glb());
    const lc::Scene sc = lc::loadGltfScene(p.string());
    const lc::Camera& c = sc.camera;
    ASSERT_EQ(c.validate(), "");
    // Every corner of the bounds is in front of the camera, between near and
    // far, and inside the field of view.
    const auto [lo, hi] = sc.bounds();
    const glm::dmat4 v = c.viewFromWorld();
    const double tanY = std::tan(c.fovYDeg * kPi / 360.0), tanX = tanY * c.aspect();
    for (int k = 0; k < 8; ++k) {
        const glm::dvec3 corner(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z);
        const glm::dvec3 q = glm::dvec3(v * glm::dvec4(corner, 1.0));
        const double depth = -q.z;
        EXPECT_GT(depth, c.nearPlane) << k;
        EXPECT_LT(depth, c.farPlane) << k;
        EXPECT_LT(std::abs(q.x) / depth, tanX) << k;
        EXPECT_LT(std::abs(q.y) / depth, tanY) << k;
    }
}

// Found by fuzz_gltf: without a camera, a model far from the origin (a 1 m
// triangle at 1e20, or a triangle collapsed to one point there) was framed
// from a distance that vanished in rounding: the camera sat on its target and
// the reader returned a scene that fails validate().
TEST(Gltf, WithoutACameraAModelFarFromTheOriginIsFramedByAValidCamera) {
    ScratchDir s;
    for (const double at : {1e8, 1e16, 1e20}) {
        for (const bool point : {false, true}) {
            SCOPED_TRACE(std::to_string(at) + (point ? " point" : " triangle"));
            GltfBuilder b;
            const int pos = b.positions(point ? std::vector<float>(9, 0.0f) : std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0});
            b.mesh(json::array({{{"attributes", {{"POSITION", pos}}}}}));
            b.scene({b.node({{"mesh", 0}, {"translation", {at, at, at}}})});
            const fs::path p = s.path / "far.gltf";
            writeBytes(p, b.gltfText());
            const lc::Scene sc = lc::loadGltfScene(p.string());
            EXPECT_NO_THROW(sc.validate());
            const lc::Camera& c = sc.camera;
            EXPECT_EQ(c.validate(), "");
            // Still looking at the model.
            const auto [lo, hi] = sc.bounds();
            EXPECT_LE(glm::length(c.target - 0.5 * (lo + hi)), 1e-12 * at);
        }
    }
}

// ---------------------------------------------------------------- bad input

struct BadCase {
    const char* name;
    const char* expectInMessage;
};

TEST(GltfHostile, EveryDefectIsOneLineNamingFileAndPath) {
    ScratchDir s;
    const GltfBuilder good = [] {
        GltfBuilder b = oneTriangle();
        b.scene({b.node({{"mesh", 0}})});
        return b;
    }();
    const std::string glb = good.glb();
    std::vector<std::pair<std::string, std::string>> cases; // file bytes, expected text
    auto patched = [&](const std::function<void(json&)>& f) {
        json d = good.withBuffer("data:application/octet-stream;base64," + GltfBuilder::base64(good.bin));
        f(d);
        return d.dump();
    };
    cases.push_back({glb.substr(0, 10), "header: truncated"});
    cases.push_back({"glTX" + glb.substr(4), "header.magic"});
    {
        std::string v = glb;
        v[4] = 1;
        cases.push_back({v, "header.version: GLB version 1"});
    }
    cases.push_back({glb.substr(0, glb.size() - 8), "header.length"});
    {
        std::string v = glb;
        const std::uint32_t huge = 0x7FFFFFF0;
        std::memcpy(&v[12], &huge, 4);
        cases.push_back({v, "chunks[0].length"});
    }
    cases.push_back({patched([](json& d) { d["accessors"][0]["count"] = 4294967295ull; }),
                     "accessors[0].count: 4,294,967,295 VEC3 elements do not fit bufferViews[0] (36 bytes)"});
    cases.push_back({patched([](json& d) { d["bufferViews"][0]["byteLength"] = 4000; }), "bufferViews[0]"});
    cases.push_back({patched([](json& d) { d["accessors"][0]["bufferView"] = 7; }), "accessors[0].bufferView: 7 is not an index"});
    cases.push_back({patched([](json& d) {
                         d["nodes"][0]["children"] = {1};
                         d["nodes"].push_back({{"children", {0}}});
                     }),
                     "reached twice"});
    cases.push_back({patched([](json& d) { d["nodes"][0]["mesh"] = 3; }), "nodes[0].mesh: 3 is not an index"});
    cases.push_back({patched([](json& d) { d["extensionsRequired"] = {"KHR_draco_mesh_compression"}; }),
                     "extensionsRequired[0]: 'KHR_draco_mesh_compression'"});
    cases.push_back({patched([](json& d) { d["extensionsRequired"] = {"EXT_meshopt_compression"}; }),
                     "'EXT_meshopt_compression'"});
    // tinygltf reads a non-array "nodes" as none; the scene's reference fails.
    cases.push_back({patched([](json& d) { d["nodes"] = 5; }), "scenes[0].nodes[0]: 0 is not an index into nodes (0)"});
    cases.push_back({patched([](json& d) { d["nodes"][0]["matrix"] = {1, 2, 3}; }), "nodes[0].matrix: must have 16 numbers"});
    cases.push_back({patched([](json& d) { d["nodes"][0]["rotation"] = {0, 0, 0, 0}; }), "nodes[0].rotation: is a zero quaternion"});
    cases.push_back({patched([](json& d) { d["scene"] = 4; }), "scene: 4 is not an index into scenes"});
    cases.push_back({patched([](json& d) { d["asset"]["version"] = "3.0"; }), "asset.version: '3.0': this reads glTF 2.x"});
    cases.push_back({patched([](json& d) {
                         d["nodes"][0]["matrix"] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0.5, 0, 0, 0, 1};
                     }),
                     "nodes[0].matrix: is not affine"});
    cases.push_back({patched([](json& d) { d["buffers"][0]["uri"] = "missing.bin"; }), "not valid glTF"});
    cases.push_back({patched([](json& d) {
                         d["meshes"][0]["primitives"][0]["indices"] = 1;
                         // Bytes 12..24 of the positions: the float 1.0f read as an index.
                         d["accessors"].push_back({{"bufferView", 0}, {"byteOffset", 12}, {"componentType", 5125}, {"count", 3}, {"type", "SCALAR"}});
                     }),
                     "meshes[0].primitives[0].indices: index 1065353216 at element 0 is outside the 3 vertices"});
    cases.push_back({"{ not json", "not valid glTF"});
    // Nesting that would take tinygltf's recursive parser past the stack
    // (20,000 levels in `extras`, 40 KB), as text and as a GLB's JSON chunk.
    {
        const std::string deep = std::string(20000, '[') + std::string(20000, ']');
        json d = good.withBuffer("data:application/octet-stream;base64," + GltfBuilder::base64(good.bin));
        d["extras"] = "X";
        std::string text = d.dump();
        text.replace(text.find("\"X\""), 3, deep);
        cases.push_back({text, ":1: arrays and objects nested more than 256 deep"});
        GltfBuilder b = good;
        b.doc["extras"] = "X";
        std::string chunk = b.withBuffer("").dump();
        chunk.replace(chunk.find("\"X\""), 3, deep);
        const std::string glbDeep = b.glbWithJson(chunk);
        cases.push_back({glbDeep, "arrays and objects nested more than 256 deep"});
    }
    // A data: URI that does not decode to the buffer's byteLength: tinygltf
    // quotes the whole URI; the message keeps its head.
    cases.push_back({patched([](json& d) {
                         d["buffers"][0]["byteLength"] = d["buffers"][0]["byteLength"].get<int>() + 4;
                         std::string uri = d["buffers"][0]["uri"];
                         d["buffers"][0]["uri"] = uri + std::string(4000, 'A');
                     }),
                     "data:application/octet-stream;base64,... ("});
    {
        // NaN in the position data.
        GltfBuilder b;
        const int pos = b.positions({0, 0, 0, std::nanf(""), 0, 0, 0, 1, 0});
        b.mesh(json::array({{{"attributes", {{"POSITION", pos}}}}}));
        b.scene({b.node({{"mesh", 0}})});
        cases.push_back({b.glb(), "accessors[0]: element 1 has a non-finite coordinate"});
    }
    {
        // A sparse accessor that asks for a billion zero vertices from a few bytes.
        GltfBuilder b;
        const int acc = b.accessor(-1, 5126, 1000000000, "VEC3");
        b.doc["accessors"][0]["sparse"] = {
            {"count", 1},
            {"indices", {{"bufferView", b.view(std::vector<std::uint32_t>{1})}, {"componentType", 5125}}},
            {"values", {{"bufferView", b.view(std::vector<float>{1, 1, 1})}}}};
        b.mesh(json::array({{{"attributes", {{"POSITION", acc}}}}}));
        b.scene({b.node({{"mesh", 0}})});
        cases.push_back({b.glb(), "accessors[0].count: 1,000,000,000 vertices without data"});
    }
    {
        // Sparse indices must increase strictly (glTF 2.0, 3.6.2.3).
        GltfBuilder b;
        const int acc = b.accessor(-1, 5126, 3, "VEC3");
        b.doc["accessors"][0]["sparse"] = {
            {"count", 2},
            {"indices", {{"bufferView", b.view(std::vector<std::uint32_t>{2, 1})}, {"componentType", 5125}}},
            {"values", {{"bufferView", b.view(std::vector<float>{1, 0, 0, 0, 1, 0})}}}};
        b.mesh(json::array({{{"attributes", {{"POSITION", acc}}}}}));
        b.scene({b.node({{"mesh", 0}})});
        cases.push_back({b.glb(), "accessors[0].sparse.indices: element 1 (1) is not greater than the one before"});
    }
    for (std::size_t i = 0; i < cases.size(); ++i) {
        const bool binary = cases[i].first.rfind("glT", 0) == 0;
        const fs::path p = s.path / ("bad" + std::to_string(i) + (binary ? ".glb" : ".gltf"));
        writeBytes(p, cases[i].first);
        const std::string msg = loadError(p);
        SCOPED_TRACE("case " + std::to_string(i));
        EXPECT_EQ(msg.rfind(p.string(), 0), 0u) << msg;            // names the file first
        EXPECT_NE(msg.find(cases[i].second), std::string::npos) << msg;
        EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;        // one line
        EXPECT_LT(msg.size(), 500u) << msg;
    }
}

TEST(GltfHostile, InstancingPastTheCapIsRefusedBeforeAllocating) {
    ScratchDir s;
    // One mesh of 2^20 triangles (non-indexed, from a small sparse accessor
    // would be refused; here the data is real) placed 40 times: 40 x 2^20 > 2^25.
    GltfBuilder b;
    std::vector<float> xyz(std::size_t(3) * 3 * (1u << 20));
    for (std::size_t v = 0; v < xyz.size() / 3; ++v) {
        xyz[3 * v] = float(v % 3 == 1);
        xyz[3 * v + 1] = float(v % 3 == 2);
        xyz[3 * v + 2] = float(v / 3) * 1e-3f;
    }
    b.mesh(json::array({{{"attributes", {{"POSITION", b.positions(xyz)}}}}}));
    std::vector<int> roots;
    for (int k = 0; k < 40; ++k) roots.push_back(b.node({{"mesh", 0}, {"translation", {k, 0, 0}}}));
    b.scene(roots);
    const fs::path p = s.path / "many.glb";
    writeBytes(p, b.glb());
    const std::string msg = loadError(p);
    EXPECT_NE(msg.find("more than 33,554,432 triangles"), std::string::npos) << msg;
}

TEST(GltfCli, RunAndConvertTakeGltf) {
    ScratchDir s;
    GltfBuilder b = oneTriangle();
    (void)b;
    // A real scene with lights and a camera: the atrium as a .glb.
    lc::Scene scene = lc::makeBuiltinScene("atrium");
    scene.lights = lc::generateLights(lc::defaultLightGen(scene, 64, 2));
    lc::saveGltfScene(scene, (s.path / "atrium.glb").string());
    auto r = lc_test::runCli({"convert", (s.path / "atrium.glb").string(), (s.path / "atrium.gltf").string()}, s.path);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("64 lights"), std::string::npos) << r.out;
    for (const char* in : {"atrium.glb", "atrium.gltf"}) {
        r = lc_test::runCli({"run", "--scene", (s.path / in).string(), "--camera", "culling camera", "--backend", "cpu",
                             "--width", "320", "--height", "180", "--no-image-error", "--out", (s.path / (std::string(in) + ".out")).string()},
                            s.path);
        ASSERT_EQ(r.code, 0) << r.err;
        const json j = json::parse(lc_test::slurp(s.path / (std::string(in) + ".out") / "summary.json"));
        EXPECT_EQ(j["metrics"]["false_negatives"], 0);
        EXPECT_EQ(j["lights"], 64);
    }
    r = lc_test::runCli({"run", "--scene", (s.path / "atrium.glb").string(), "--camera", "nope", "--out", (s.path / "x").string()}, s.path);
    EXPECT_NE(r.code, 0);
    EXPECT_NE(r.err.find("no camera 'nope'"), std::string::npos) << r.err;
    // Scene files are told apart by extension: another one is refused, not
    // written as scene JSON under its name, and a mesh is not read as a scene.
    for (const char* out : {"atrium.obj", "atrium.txt", "atrium"}) {
        r = lc_test::runCli({"convert", (s.path / "atrium.glb").string(), (s.path / out).string()}, s.path);
        EXPECT_EQ(r.code, 2) << out;
        EXPECT_NE(r.err.find("OUT: "), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("a scene is .json (scene JSON), .gltf or .glb"), std::string::npos) << r.err;
        EXPECT_FALSE(fs::exists(s.path / out)) << out;
    }
    std::ofstream(s.path / "tri.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    r = lc_test::runCli({"run", "--scene", (s.path / "tri.obj").string(), "--out", (s.path / "y").string()}, s.path);
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("tri.obj is a mesh, not a scene"), std::string::npos) << r.err;
    // The library's reader (the studio's File > Open, --scene) says the same,
    // not a JSON syntax error at the mesh's first line.
    try {
        lc::loadSceneAny((s.path / "tri.obj").string());
        ADD_FAILURE() << "a mesh read as a scene";
    } catch (const lc::InputError& e) {
        EXPECT_NE(std::string(e.what()).find("a mesh (obj), not a scene"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("tri.obj"), std::string::npos) << e.what();
    }
}
