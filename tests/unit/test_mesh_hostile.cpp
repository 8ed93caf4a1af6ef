// Regression tests for inputs the fuzzers (tests/fuzz/, scripts/fuzz.sh) found.
// Each input file is kept verbatim in tests/data/fuzz_*.
#include "culling/core/errors.hpp"
#include "culling/scene/scene_io.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <future>
#include <new>
#include <thread>

// Largest single allocation of the process, to catch header-driven reservations.
static std::atomic<std::size_t> gLargestAllocation{0};

void* operator new(std::size_t n) {
    std::size_t seen = gLargestAllocation.load();
    while (n > seen && !gLargestAllocation.compare_exchange_weak(seen, n)) {
    }
    if (void* p = std::malloc(n ? n : 1)) return p;
    throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace {

const std::string kData = LC_TEST_DATA_DIR;

// Runs loadMesh(path) on a thread; a hang fails the test after `limit` and
// ends the process (the stuck thread cannot be stopped) instead of waiting
// for the CTest timeout.
std::string loadError(const std::string& path, std::chrono::seconds limit) {
    auto done = std::make_shared<std::promise<std::string>>();
    std::future<std::string> result = done->get_future();
    std::thread([path, done] {
        try {
            lc::loadMesh(path);
            done->set_value("(loaded without error)");
        } catch (const lc::InputError& e) {
            done->set_value(e.what());
        } catch (const std::exception& e) {
            done->set_value(std::string("(not an InputError) ") + e.what());
        }
    }).detach();
    if (result.wait_for(limit) != std::future_status::ready) {
        ADD_FAILURE() << "loadMesh(" << path << ") still running after " << limit.count() << " s";
        std::fflush(nullptr);
        std::_Exit(1);
    }
    return result.get();
}

// OpenMesh 9.0's PLY reader looped forever on these headers (a hang in the
// studio and the CLI); the project's own PLY reader refuses them.
// fuzz_mesh_ply found: a mangled property line and no "end_header".
TEST(MeshHostile, PlyUnknownHeaderLineIsAClearError) {
    const std::string path = kData + "/fuzz_ply_no_end_header.ply";
    const std::string error = loadError(path, std::chrono::seconds(20));
    EXPECT_EQ(error.rfind(path + ":5: PLY header: unknown header line 'prope", 0), 0u) << error;
}

// fuzz_mesh_ply found: "element fdices" (no count) on line 8.
TEST(MeshHostile, PlyElementWithoutCountIsAClearError) {
    const std::string path = kData + "/fuzz_ply_element_without_count.ply";
    EXPECT_EQ(loadError(path, std::chrono::seconds(20)),
              path + ":8: PLY header: an element line is \"element <name> <count>\", not 'element fdices'");
}

// fuzz_mesh_ply found (a crash in OpenMesh): the format line "format ascii
// 1oat y" (line 2), after which "property float z" (line 3) has no element.
TEST(MeshHostile, PlyBadFormatLineIsAClearError) {
    const std::string path = kData + "/fuzz_ply_property_before_element.ply";
    EXPECT_EQ(loadError(path, std::chrono::seconds(20)), path + ":2: PLY header: bad format line 'format ascii 1oat y'");
}

// fuzz_mesh_ply found: "property list uchar i\xba...nt vertex_indices" (line
// 8) made OpenMesh read garbage list counts and allocate 2 GB.
TEST(MeshHostile, PlyUnknownPropertyTypeIsAClearError) {
    const std::string path = kData + "/fuzz_ply_unknown_list_type.ply";
    const std::string error = loadError(path, std::chrono::seconds(20));
    EXPECT_EQ(error.rfind(path + ":8: PLY header: unknown property type in 'property list uchar i", 0), 0u) << error;
}

TEST(MeshHostile, PlyPropertyBeforeAnyElementIsAClearError) {
    const std::string path = ::testing::TempDir() + "/lc_property_first.ply";
    std::ofstream(path) << "ply\nformat ascii 1.0\nproperty float z\nelement vertex 1\nend_header\n0\n";
    EXPECT_EQ(loadError(path, std::chrono::seconds(20)),
              path + ":3: PLY header: property before any element: 'property float z'");
    std::remove(path.c_str());
}

// fuzz_mesh_off found: "0 0 1" as the counts (after a comment line) made
// OpenMesh's OFF reader spin.
TEST(MeshHostile, OffAnnouncingNoVerticesIsAClearError) {
    const std::string path = kData + "/fuzz_off_zero_counts.off";
    EXPECT_EQ(loadError(path, std::chrono::seconds(20)),
              path + ":3: OFF file announces 0 vertices and 0 faces: no triangles");
}

// Hand-written: six valid header lines and nothing else (the last one named).
TEST(MeshHostile, PlyWithoutEndHeaderIsAClearError) {
    const std::string path = kData + "/ply_without_end_header.ply";
    EXPECT_EQ(loadError(path, std::chrono::seconds(20)), path + ":6: PLY header has no \"end_header\" line");
}

TEST(MeshHostile, PlyWithoutPlyFirstLineIsAClearError) {
    const std::string path = kData + "/garbage.ply";
    EXPECT_EQ(loadError(path, std::chrono::seconds(20)), path + ":1: PLY header: the first line must be \"ply\"");
}

// fuzz_mesh_off found: "OF4\0 4 2 0" as the counts line made OpenMesh's OFF
// reader spin.
TEST(MeshHostile, OffCountsLineThatIsNotNumbersIsAClearError) {
    const std::string path = kData + "/fuzz_off_bad_counts_line.off";
    const std::string error = loadError(path, std::chrono::seconds(20));
    EXPECT_EQ(error.rfind(path + ":2: OFF file: the counts line is \"<vertices> <faces> <edges>\"", 0), 0u) << error;
}

// fuzz_mesh_off found: a 31-byte OFF file whose header made the importer
// reserve 13.7 GB before reading a single vertex.
TEST(MeshHostile, OffHeaderCountsDoNotDriveAllocations) {
    const std::string path = kData + "/fuzz_off_huge_counts.off";
    gLargestAllocation = 0;
    const std::string error = loadError(path, std::chrono::seconds(20));
    EXPECT_EQ(error.rfind(path + ":2: OFF file: ", 0), 0u) << error;
    EXPECT_LT(gLargestAllocation.load(), std::size_t(1) << 20) << "an allocation of " << gLargestAllocation.load()
                                                              << " bytes for a 31-byte file";
}

// Well-formed headers announcing more elements than the file can hold.
TEST(MeshHostile, AnnouncedCountsBeyondTheFileSizeAreAClearError) {
    const std::string off = ::testing::TempDir() + "/lc_huge_counts.off";
    const std::string ply = ::testing::TempDir() + "/lc_huge_counts.ply";
    {
        std::ofstream(off) << "OFF\n2000000000 1 0\n0 0 0\n";
        std::ofstream(ply) << "ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\nend_header\n0\n";
    }
    gLargestAllocation = 0;
    EXPECT_EQ(loadError(off, std::chrono::seconds(20)),
              off + ":2: OFF file announces 2000000000 vertices and 1 faces, more than the 25-byte file can hold");
    EXPECT_EQ(loadError(ply, std::chrono::seconds(20)),
              ply + ":3: PLY header: element 'vertex' announces 4000000000 items, more than the 77-byte file can hold");
    EXPECT_LT(gLargestAllocation.load(), std::size_t(1) << 20);
    std::remove(off.c_str());
    std::remove(ply.c_str());
}

// Binary OFF: counts (and a face's vertex count) near 2^31 in either byte
// order neither drive an allocation nor a loop; each is a clear error.
TEST(MeshHostile, BinaryOffHugeCountsAreAClearErrorWithoutAllocating) {
    const std::string path = ::testing::TempDir() + "/lc_huge_counts_bin.off";
    auto le32 = [](std::uint32_t v) {
        return std::string{char(v & 0xFF), char(v >> 8 & 0xFF), char(v >> 16 & 0xFF), char(v >> 24)};
    };
    const std::string zero = le32(0), one = le32(0x3f800000); // 0.0f and 1.0f
    {
        std::ofstream(path, std::ios::binary) << "OFF BINARY\n" << le32(0x7FFFFFFF) << le32(1) << le32(0) << zero;
    }
    gLargestAllocation = 0;
    EXPECT_EQ(loadError(path, std::chrono::seconds(20)),
              path + ": binary OFF file announces 2147483647 vertices and 1 faces little-endian (OpenMesh) or "
                     "-129 vertices and 16777216 faces big-endian (Geomview), more than the 4 bytes after the "
                     "counts can hold (byte offset 11)");
    {
        std::ofstream(path, std::ios::binary) << "OFF BINARY\n"
                                              << le32(3) << le32(1) << le32(0) << zero << zero << zero << one
                                              << zero << zero << zero << one << zero << le32(0x7FFFFFF0) << zero;
    }
    EXPECT_EQ(loadError(path, std::chrono::seconds(20)),
              path + ": binary OFF file (little-endian (OpenMesh)): face 0 of 1 announces 2147483632 vertices; "
                     "expected a count the rest of the file can hold (byte offset 59)");
    EXPECT_LT(gLargestAllocation.load(), std::size_t(1) << 20);
    std::remove(path.c_str());
}

} // namespace

// fuzz_mesh_off found (out of memory in OpenMesh's reader, which took "-3"
// as a face's vertex count of 4294967293): "OFF\t4 2 0\n0\n\n-3\n". The
// project's reader reads one vertex per line, so the first vertex line is
// already short.
TEST(MeshHostile, OffNegativeFaceVertexCountIsAClearError) {
    const std::string path = kData + "/fuzz_off_negative_face_count.off";
    EXPECT_EQ(loadError(path, std::chrono::seconds(20)),
              path + ":2: OFF file: vertex 0 needs three coordinates, not '0'");
}

// Hand-written: "-3" exactly where face 0's vertex count is read.
TEST(MeshHostile, OffFaceCountThatIsNotAWholeNumberIsAClearError) {
    const std::string dir = testing::TempDir();
    const std::string path = dir + "/lc_neg_face.off";
    std::ofstream(path) << "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n-3 0 1 2\n";
    EXPECT_EQ(loadError(path, std::chrono::seconds(20)),
              path + ":6: OFF file: face 0 gives '-3' as its vertex count; expected a whole number");
    std::ofstream(path) << "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    EXPECT_EQ(lc::loadMesh(path).triangleCount(), 1u); // the well-formed twin loads
    std::remove(path.c_str());
}

// fuzz_mesh_off found with a random seed (a timeout: OpenMesh's ASCII OFF
// reader looped in read_ascii/add_face on it); the input was kept from a CI
// clone's artifacts. The project's reader stops at the short vertex line.
TEST(MeshHostile, OffThatHungOpenMeshIsAClearError) {
    const std::string path = kData + "/fuzz_off_openmesh_timeout.off";
    EXPECT_EQ(loadError(path, std::chrono::seconds(20)),
              path + ":2: OFF file: vertex 0 needs three coordinates, not 'B0  1'");
}

// fuzz_mesh_ply found (out of memory in OpenMesh's ASCII PLY reader):
// "0-1" as a vertex's z, after which OpenMesh read the face counts shifted.
TEST(MeshHostile, PlyThatExhaustedOpenMeshMemoryIsAClearError) {
    const std::string path = kData + "/fuzz_ply_openmesh_oom.ply";
    gLargestAllocation = 0;
    EXPECT_EQ(loadError(path, std::chrono::seconds(20)),
              path + ":11: element 'vertex' 1 of 2, property 'z': '0-1' is not a number");
    EXPECT_LT(gLargestAllocation.load(), std::size_t(1) << 20);
}
