#pragma once
// The project's own PLY and OFF readers (mesh_ply.cpp, mesh_off.cpp) and what
// they share. They replace OpenMesh 9's readers, which loop forever, crash or
// allocate gigabytes on malformed input (found by fuzzing; docs/TESTING.md).
//
// Every reader works on the whole file in memory and keeps three promises:
// every loop consumes input or ends, every allocation is bounded by the file's
// size (never by a count the file announces), and every error is an
// InputError naming the file and the line (ASCII) or the element and byte
// offset (binary).

#include "culling/core/depth.hpp"
#include "culling/scene/scene_io.hpp"

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace lc::meshio {

// Vertices and polygons as written; loadMesh validates, triangulates and drops
// degenerates from this.
struct FlatMesh {
    std::vector<float> positions;          // x, y, z per vertex
    std::vector<std::uint32_t> polyStart;  // offsets into polyIndices, one per face
    std::vector<std::int64_t> polyIndices; // vertex indices as the file gave them
};

// What a reader needs besides the bytes: for messages, cancel and progress.
struct ReadContext {
    const std::string& path;
    const CancelToken* cancel = nullptr;
    const Progress* progress = nullptr; // may be null or empty
    // Called every 64k elements: checks cancel, reports 0.9 * offset / size.
    void tick(std::size_t offset, std::size_t size) const;
};

// Reads `size` bytes of the file (its size from stat) into one string, 1 MiB
// at a time, checking cancel between chunks.
std::string readFileBytes(const std::string& path, std::uint64_t size, const CancelToken* cancel);

// PLY: ascii, binary_little_endian, binary_big_endian.
void readPly(std::string_view bytes, const ReadContext& ctx, FlatMesh& out);
// OFF: ASCII ([ST][C][N]OFF keyword, comments, colour columns after a face's
// indices) and binary OFF ("OFF BINARY": little-endian as OpenMesh writes it,
// big-endian as Geomview specifies it; mesh_off.cpp says how they differ).
void readOff(std::string_view bytes, const ReadContext& ctx, FlatMesh& out);

// Text helpers shared by the ASCII readers.
// A whole token as a double: optional leading '+', from_chars; denormal
// underflow reads as the nearest representable value. False if not a number.
bool parseNumber(std::string_view token, double& value);
// The same, rounded once to float (as strtof does, not via double); a value
// beyond float's range comes back infinite.
bool parseFloat(std::string_view token, float& value);
// A whole token as a signed 64-bit integer (optional leading '+').
bool parseInteger(std::string_view token, std::int64_t& value);
// A token or header line quoted in a message: at most 80 characters.
std::string quoted(std::string_view text);

} // namespace lc::meshio
