// Mesh loading: the shared real assets, small hand-made files whose expected
// contents are derived by hand, and broken files that must give InputError
// naming the file.
#include "culling/core/errors.hpp"
#include "culling/scene/gltf_io.hpp"
#include "culling/scene/scene_io.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

using namespace lc;

namespace {
const std::string kAssets = LC_ASSETS_DIR;
const std::string kData = LC_TEST_DATA_DIR;

void expectInputErrorNaming(const std::string& path, const std::string& alsoContains = "") {
    try {
        loadMesh(path);
        FAIL() << "expected InputError for " << path;
    } catch (const InputError& e) {
        EXPECT_EQ(e.file(), path);
        EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
        if (!alsoContains.empty())
            EXPECT_NE(std::string(e.what()).find(alsoContains), std::string::npos) << e.what();
    }
}

std::string tempPath(const std::string& name) {
    return (std::filesystem::temp_directory_path() / ("lc_mesh_" + std::to_string(::getpid()) + "_" + name)).string();
}
} // namespace

TEST(MeshIo, SpotObjLoadsAllTriangles) {
    MeshLoadReport rep;
    const Mesh m = loadMesh(kAssets + "/spot/spot.obj", &rep);
    EXPECT_EQ(m.triangleCount(), 23062u);  // asset README table
    EXPECT_EQ(rep.degenerateFacesDropped, 0u);
    EXPECT_TRUE(rep.warning.empty());
    EXPECT_EQ(m.validate(), "");
}

TEST(MeshIo, BunnyPlyWithExtraColumnsAndUnusedVertices) {
    MeshLoadReport rep;
    const Mesh m = loadMesh(kAssets + "/stanford_bunny/bun_zipper.ply", &rep);
    EXPECT_EQ(m.triangleCount(), 69451u);
    EXPECT_EQ(m.vertexCount(), 35947u);  // the header's "element vertex"
    EXPECT_EQ(m.validate(), "");
    // The first vertex of the file, with its extra confidence/intensity
    // columns skipped: -0.0378297 0.12794 0.00447467.
    EXPECT_FLOAT_EQ(m.positions[0], -0.0378297f);
    EXPECT_FLOAT_EQ(m.positions[1], 0.12794f);
    EXPECT_FLOAT_EQ(m.positions[2], 0.00447467f);
}

TEST(MeshIo, MaizeObjLoads) {
    MeshLoadReport rep;
    const Mesh m = loadMesh(kAssets + "/maize/maize_single2.obj", &rep);
    EXPECT_EQ(m.triangleCount(), 14752u);
    EXPECT_EQ(rep.degenerateFacesDropped, 0u);
}

TEST(MeshIo, BuildingsObjDropsOnlyZeroAreaFacesAndIsFast) {
    MeshLoadReport rep;
    double lastProgress = -1;
    bool monotonic = true;
    const auto t0 = std::chrono::steady_clock::now();
    const Mesh m = loadMesh(kAssets + "/buildings/buildings.obj", &rep, nullptr, [&](double f) {
        monotonic = monotonic && f >= lastProgress;
        lastProgress = f;
    });
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("buildings.obj: %zu triangles, %zu dropped, %.3f s\n", m.triangleCount(),
                rep.degenerateFacesDropped, s);
    // Every face is either kept or counted as dropped.
    EXPECT_EQ(m.triangleCount() + rep.degenerateFacesDropped, 400020u);
    // README: "330 zero-area faces". Exactly-zero area in float coordinates
    // gives 284; the README's count uses some tolerance. Accept the range.
    EXPECT_GE(rep.degenerateFacesDropped, 250u);
    EXPECT_LE(rep.degenerateFacesDropped, 400u);
    EXPECT_NE(rep.warning.find("buildings.obj"), std::string::npos);
    EXPECT_TRUE(monotonic);
    EXPECT_DOUBLE_EQ(lastProgress, 1.0);
    EXPECT_EQ(m.vertexCount(), 200062u);  // no vertex split at the non-manifold vertex
}

TEST(MeshIo, CancelStopsALoad) {
    CancelToken token;
    token.cancelled = true;
    EXPECT_THROW(loadMesh(kAssets + "/buildings/buildings.obj", nullptr, &token), Cancelled);
    EXPECT_THROW(loadMesh(kAssets + "/stanford_bunny/bun_zipper.ply", nullptr, &token), Cancelled);
}

TEST(MeshIo, SmallObjTriangulatesAndDropsDegenerates) {
    MeshLoadReport rep;
    const Mesh m = loadMesh(kData + "/small.obj", &rep);
    // quad -> 2 triangles; "f 1 1 2" (repeated index) and "f 1 2 5" (collinear)
    // dropped; "f 1/1/1 2/2/2 3/3/3" kept; "f -4 -3 -1" = vertices 1, 2, 4.
    EXPECT_EQ(m.vertexCount(), 5u);
    ASSERT_EQ(m.triangleCount(), 4u);
    EXPECT_EQ(rep.polygonsTriangulated, 1u);
    EXPECT_EQ(rep.degenerateFacesDropped, 2u);
    const std::vector<std::uint32_t> expected = {0, 1, 2, 0, 2, 3, 0, 1, 2, 1, 2, 4};
    EXPECT_EQ(m.indices, expected);
    EXPECT_FALSE(rep.warning.empty());
}

// A scene JSON naming that OBJ: the dropped faces are one warning of the
// scene's load (what `run`, `convert` and the studio print), not lost inside it.
TEST(MeshIo, ASceneNamingAMeshWithDegenerateFacesWarnsOfThem) {
    const std::filesystem::path dir = tempPath("scene_dir");
    std::filesystem::create_directories(dir);
    std::filesystem::copy_file(kData + "/small.obj", dir / "small.obj",
                               std::filesystem::copy_options::overwrite_existing);
    const std::string scene = (dir / "scene.json").string();
    std::ofstream(scene) << R"({"format": "lightcull-scene", "version": 1, "meshes": [{"path": "small.obj"}]})";
    GltfReadReport rep;
    const Scene s = loadSceneAny(scene, GltfReadOptions{}, &rep);
    EXPECT_EQ(s.triangleCount(), 4u);
    ASSERT_EQ(rep.warnings.size(), 1u);
    EXPECT_NE(rep.warnings[0].find("small.obj: dropped 2 degenerate face(s)"), std::string::npos) << rep.warnings[0];
    std::vector<std::string> direct;
    loadSceneFile(scene, nullptr, {}, &direct);
    EXPECT_EQ(direct, rep.warnings);
    std::filesystem::remove_all(dir);
}

TEST(MeshIo, OffAndStlAndBinaryPly) {
    const std::string off = tempPath("quad.off");
    std::ofstream(off) << "OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";
    MeshLoadReport rep;
    Mesh m = loadMesh(off, &rep);
    EXPECT_EQ(m.triangleCount(), 2u);
    EXPECT_EQ(rep.polygonsTriangulated, 1u);

    const std::string stl = tempPath("tri.stl");
    std::ofstream(stl) << "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 2 0 0\n"
                          "vertex 0 3 0\nendloop\nendfacet\nendsolid t\n";
    m = loadMesh(stl);
    ASSERT_EQ(m.triangleCount(), 1u);
    const glm::vec3 b = m.vertex(m.indices[1]), c = m.vertex(m.indices[2]);
    EXPECT_FLOAT_EQ(b.x + c.x, 2.f);
    EXPECT_FLOAT_EQ(b.y + c.y, 3.f);

    const std::string ply = tempPath("bin.ply");
    {
        std::ofstream f(ply, std::ios::binary);
        f << "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
             "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
        const float v[9] = {0, 0, 0, 4, 0, 0, 0, 5, 0};
        f.write(reinterpret_cast<const char*>(v), sizeof v);
        const unsigned char n = 3;
        const int idx[3] = {0, 1, 2};
        f.write(reinterpret_cast<const char*>(&n), 1);
        f.write(reinterpret_cast<const char*>(idx), sizeof idx);
    }
    m = loadMesh(ply);
    ASSERT_EQ(m.triangleCount(), 1u);
    EXPECT_FLOAT_EQ(m.positions[3], 4.f);
    EXPECT_FLOAT_EQ(m.positions[7], 5.f);
    for (auto& p : {off, stl, ply}) std::filesystem::remove(p);
}

TEST(MeshIo, BrokenFilesGiveInputErrorNamingTheFile) {
    expectInputErrorNaming(kData + "/nan_vertex.obj", "non-finite");
    expectInputErrorNaming(kData + "/index_out_of_range.obj", "vertex 7");
    expectInputErrorNaming(kData + "/index_out_of_range.off", "vertex 9");
    expectInputErrorNaming(kData + "/inf_vertex.off", "non-finite");
    expectInputErrorNaming(kData + "/empty.obj", "empty");
    expectInputErrorNaming(kData + "/garbage.obj");
    expectInputErrorNaming(kData + "/garbage.ply");
    expectInputErrorNaming(kData + "/does_not_exist.obj", "not found");
    expectInputErrorNaming(kData + "/unsupported.txt", "unsupported");
    expectInputErrorNaming(kData, "");  // a folder
}

TEST(MeshIo, ObjErrorsCarryTheLine) {
    try {
        loadMesh(kData + "/nan_vertex.obj");
        FAIL();
    } catch (const InputError& e) {
        EXPECT_EQ(e.line(), 2);  // "v nan 0 0" is the second line
    }
    try {
        loadMesh(kData + "/index_out_of_range.obj");
        FAIL();
    } catch (const InputError& e) {
        EXPECT_EQ(e.line(), 4);
    }
}
