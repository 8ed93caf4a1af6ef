// Regression tests for inputs the fuzzers (tests/fuzz/, scripts/fuzz.sh) found.
// Each input file is kept verbatim in tests/data/fuzz_*.
#include "culling/errors.hpp"
#include "culling/scene_io.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
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

// fuzz_mesh_ply: OpenMesh's PLY reader looped forever on a header without
// "end_header" (a hang in the studio and the CLI). The file has 12 lines; the
// error names the last one read.
TEST(MeshHostile, PlyHeaderWithoutEndHeaderIsAClearError) {
    const std::string path = kData + "/fuzz_ply_no_end_header.ply";
    EXPECT_EQ(loadError(path, std::chrono::seconds(20)),
              path + ":12: PLY header has no \"end_header\" line");
}

TEST(MeshHostile, PlyWithoutPlyFirstLineIsAClearError) {
    const std::string path = kData + "/garbage.ply";
    EXPECT_EQ(loadError(path, std::chrono::seconds(20)), path + ":1: a PLY file starts with the line \"ply\"");
}

// fuzz_mesh_off: a 31-byte OFF file announcing ~1.1e9 vertices made the
// importer reserve 13.7 GB before reading a single vertex.
TEST(MeshHostile, OffHeaderCountsDoNotDriveAllocations) {
    const std::string path = kData + "/fuzz_off_huge_counts.off";
    gLargestAllocation = 0;
    const std::string error = loadError(path, std::chrono::seconds(20));
    EXPECT_EQ(error.rfind(path + ": ", 0), 0u) << error;
    EXPECT_LT(gLargestAllocation.load(), std::size_t(1) << 20) << "an allocation of " << gLargestAllocation.load()
                                                              << " bytes for a 31-byte file";
}

} // namespace
