// Mesh paths in saved scenes: written relative to the folder the scene is
// saved in, whatever folder it was loaded from or imported out of.
#include "culling/scene/scene_io.hpp"
#include "culling/scene/scene.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

using namespace lc;
namespace fs = std::filesystem;

namespace {

fs::path freshDir(const std::string& tag) {
    const fs::path d = fs::temp_directory_path() /
                       ("lc_scene_paths_" + tag + "_" + std::to_string(::getpid()));
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

void writeQuad(const fs::path& p) {
    fs::create_directories(p.parent_path());
    std::ofstream(p) << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
}

std::string meshPathInFile(const fs::path& scene) {
    std::ifstream in(scene);
    const auto j = nlohmann::json::parse(in);
    return j.at("meshes").at(0).at("path").get<std::string>();
}

} // namespace

// An imported mesh (absolute path, as the studio's Import gives it) is saved by
// a path relative to the scene file, and the saved scene loads it again.
TEST(ScenePaths, ImportedMeshSavedRelativeToSceneFile) {
    const fs::path dir = freshDir("import");
    writeQuad(dir / "assets" / "quad.obj");
    Scene s = makeBuiltinScene("sky");
    s.meshes.push_back(loadMesh((dir / "assets" / "quad.obj").string()));
    ASSERT_TRUE(fs::path(s.meshes.back().resolvedPath).is_absolute());

    fs::create_directories(dir / "scenes");
    saveSceneFile(s, (dir / "scenes" / "a.json").string());
    Scene tmp = makeBuiltinScene("sky");
    const std::size_t meshIndex = tmp.meshes.size();
    std::ifstream in(dir / "scenes" / "a.json");
    const auto j = nlohmann::json::parse(in);
    EXPECT_EQ(j.at("meshes").at(meshIndex).at("path").get<std::string>(), "../assets/quad.obj");

    const Scene back = loadSceneFile((dir / "scenes" / "a.json").string());
    ASSERT_EQ(back.meshes.size(), s.meshes.size());
    EXPECT_EQ(back.meshes.back().positions, s.meshes.back().positions);
    EXPECT_EQ(back.meshes.back().indices, s.meshes.back().indices);
    fs::remove_all(dir);
}

// A scene loaded from one folder and saved into another keeps finding its
// mesh: the relative path is rebased, not copied verbatim.
TEST(ScenePaths, SaveAsIntoAnotherFolderRebasesMeshPath) {
    const fs::path dir = freshDir("rebase");
    writeQuad(dir / "a" / "meshes" / "quad.obj");
    Scene s;
    s.meshes.push_back(loadMesh((dir / "a" / "meshes" / "quad.obj").string()));
    saveSceneFile(s, (dir / "a" / "s.json").string());
    EXPECT_EQ(meshPathInFile(dir / "a" / "s.json"), "meshes/quad.obj");

    const Scene loaded = loadSceneFile((dir / "a" / "s.json").string());
    EXPECT_EQ(loaded.meshes.at(0).sourcePath, "meshes/quad.obj");
    fs::create_directories(dir / "b" / "deeper");
    saveSceneFile(loaded, (dir / "b" / "deeper" / "s.json").string());
    EXPECT_EQ(meshPathInFile(dir / "b" / "deeper" / "s.json"), "../../a/meshes/quad.obj");
    const Scene moved = loadSceneFile((dir / "b" / "deeper" / "s.json").string());
    EXPECT_EQ(moved.meshes.at(0).triangleCount(), 2u);

    // Without a folder to be relative to, serializeScene writes the path as given.
    EXPECT_NE(serializeScene(loaded).find("\"meshes/quad.obj\""), std::string::npos);
    fs::remove_all(dir);
}
