// culling/ must stay free of Qt and VTK, and public headers must not expose
// Vulkan (STYLE.md). CMake refuses to configure in the first case; this test
// keeps the rule visible in the suite and also covers the Vulkan rule.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

namespace fs = std::filesystem;

namespace {
std::vector<std::string> offendingIncludes(const fs::path& root, const std::regex& pattern) {
    std::vector<std::string> hits;
    for (const auto& entry : fs::recursive_directory_iterator(root)) {
        if (!entry.is_regular_file()) continue;
        const auto ext = entry.path().extension().string();
        if (ext != ".cpp" && ext != ".hpp" && ext != ".h") continue;
        std::ifstream in(entry.path());
        std::string line;
        int n = 0;
        while (std::getline(in, line)) {
            ++n;
            if (std::regex_search(line, pattern))
                hits.push_back(entry.path().string() + ":" + std::to_string(n) + ": " + line);
        }
    }
    return hits;
}
} // namespace

TEST(Layering, CullingLibraryHasNoQtOrVtk) {
    const std::regex qtOrVtk(R"(#\s*include\s*[<"](Q[A-Za-z]|vtk))");
    const auto hits = offendingIncludes(fs::path(LC_SOURCE_DIR) / "culling", qtOrVtk);
    for (const auto& h : hits) ADD_FAILURE() << h;
    EXPECT_TRUE(hits.empty());
}

TEST(Layering, PublicHeadersDoNotIncludeVulkan) {
    const std::regex vulkan(R"(#\s*include\s*[<"]vulkan/)");
    const auto hits = offendingIncludes(fs::path(LC_SOURCE_DIR) / "culling" / "include", vulkan);
    for (const auto& h : hits) ADD_FAILURE() << h;
    EXPECT_TRUE(hits.empty());
}

TEST(Layering, PatternCatchesAnOffendingInclude) {
    // Guard against a pattern that matches nothing: it must flag real includes.
    const std::regex qtOrVtk(R"(#\s*include\s*[<"](Q[A-Za-z]|vtk))");
    EXPECT_TRUE(std::regex_search(std::string("#include <QWidget>"), qtOrVtk));
    EXPECT_TRUE(std::regex_search(std::string("#include \"vtkActor.h\""), qtOrVtk));
    EXPECT_FALSE(std::regex_search(std::string("#include <glm/glm.hpp>"), qtOrVtk));
}
