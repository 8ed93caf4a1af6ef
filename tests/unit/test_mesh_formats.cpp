// The project's own PLY and OFF readers (culling/src/scene/mesh_ply.cpp,
// mesh_off.cpp): every format variant against expectations derived by hand or
// by an independent path (a tiny reference reader below, the OBJ parser), and
// the exact error for truncated and garbage input.
#include "culling/core/errors.hpp"
#include "culling/scene/scene_io.hpp"

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>

using namespace lc;

namespace {

const std::string kAssets = LC_ASSETS_DIR;

std::string tempPath(const std::string& name) {
    return (std::filesystem::temp_directory_path() / ("lc_fmt_" + std::to_string(::getpid()) + "_" + name))
        .string();
}

// A file removed when the test ends.
struct TempFile {
    std::string path;
    TempFile(const std::string& name, const std::string& bytes) : path(tempPath(name)) {
        std::ofstream(path, std::ios::binary) << bytes;
    }
    ~TempFile() { std::remove(path.c_str()); }
};

std::string loadErrorText(const std::string& path) {
    try {
        loadMesh(path);
    } catch (const InputError& e) {
        return e.what();
    }
    return "(loaded without error)";
}

// Binary PLY body writer: each value with its PLY type, in either byte order.
class Body {
  public:
    explicit Body(bool bigEndian) : big_(bigEndian) {}
    template <typename T> Body& put(T v) {
        unsigned char b[sizeof(T)];
        std::memcpy(b, &v, sizeof(T));
        if (big_) std::reverse(b, b + sizeof(T)); // the test machine is little-endian
        bytes.append(reinterpret_cast<const char*>(b), sizeof(T));
        return *this;
    }
    std::string bytes;

  private:
    bool big_;
};

// One mesh in many encodings: 5 vertices (a unit square and an apex), one
// quad and one triangle. Expected triangles: quad (0,1,2,3) fans to (0,1,2),
// (0,2,3); triangle (1,4,2).
const std::vector<float> kSquarePositions = {0, 0, 0, 2, 0, 0, 2, 2, 0, 0, 2, 0, 1.5f, -0.25f, 3};
const std::vector<std::uint32_t> kSquareIndices = {0, 1, 2, 0, 2, 3, 1, 4, 2};

// Header shared by the odd-typed PLY variants (CRLF line ends): a material
// element before the vertices (with a list to skip), the vertex columns out of
// order and in mixed types (z double, a list of uchar tags with an int count,
// x float, an int16 column, y float), the faces with "vertex_index" (ushort
// count, int index) after a skipped uchar, and an edge element after them.
std::string oddHeader(const std::string& format) {
    return "ply\r\nformat " + format +
           " 1.0\r\n"
           "comment made by hand\r\n"
           "obj_info not a real scanner\r\n"
           "element material 2\r\n"
           "property list uchar float weights\r\n"
           "property uint id\r\n"
           "element vertex 5\r\n"
           "property double z\r\n"
           "property list int uchar tags\r\n"
           "property float x\r\n"
           "property int16 confidence\r\n"
           "property float y\r\n"
           "element face 2\r\n"
           "property uchar flags\r\n"
           "property list ushort int vertex_index\r\n"
           "element edge 1\r\n"
           "property int vertex1\r\n"
           "property int vertex2\r\n"
           "end_header\r\n";
}

std::string oddBinary(bool big) {
    Body b(big);
    // materials: 3 weights + id, then none + id
    b.put<std::uint8_t>(3).put<float>(0.5f).put<float>(0.25f).put<float>(1.f).put<std::uint32_t>(7);
    b.put<std::uint8_t>(0).put<std::uint32_t>(8);
    for (int v = 0; v < 5; ++v) {
        b.put<double>(kSquarePositions[3 * v + 2]);
        b.put<std::int32_t>(v % 3); // tags: 0, 1 or 2 uchar items
        for (int t = 0; t < v % 3; ++t)
            b.put<std::uint8_t>(std::uint8_t(200 + t));
        b.put<float>(kSquarePositions[3 * v]);
        b.put<std::int16_t>(std::int16_t(-v));
        b.put<float>(kSquarePositions[3 * v + 1]);
    }
    b.put<std::uint8_t>(1)
        .put<std::uint16_t>(4)
        .put<std::int32_t>(0)
        .put<std::int32_t>(1)
        .put<std::int32_t>(2)
        .put<std::int32_t>(3);
    b.put<std::uint8_t>(0).put<std::uint16_t>(3).put<std::int32_t>(1).put<std::int32_t>(4).put<std::int32_t>(
        2);
    b.put<std::int32_t>(0).put<std::int32_t>(1);
    return oddHeader(big ? "binary_big_endian" : "binary_little_endian") + b.bytes;
}

const char* kOddAscii = "3 0.5 0.25 1 7\n"
                        "0 8\n"
                        "0 0 0 +0 0\n"
                        "0 1 200 2 -1 0\n"
                        "0 2 200 201 2 -2 2\n"
                        "0 0 0 -3 2.0e0\n"
                        "3.0 1 200 1.5 -4 -0.25\n"
                        "1 4 0 1 2 3\n"
                        "0 3 1 4 2\n"
                        "0 1\n";

void expectSquare(const Mesh& m, const MeshLoadReport& rep) {
    EXPECT_EQ(m.positions, kSquarePositions);
    EXPECT_EQ(m.indices, kSquareIndices);
    EXPECT_EQ(rep.polygonsTriangulated, 1u);
    EXPECT_EQ(rep.degenerateFacesDropped, 0u);
}

} // namespace

TEST(MeshPly, AsciiWithOddTypesExtraElementsAndListsToSkip) {
    TempFile f("odd_ascii.ply", oddHeader("ascii") + kOddAscii);
    MeshLoadReport rep;
    expectSquare(loadMesh(f.path, &rep), rep);
}

TEST(MeshPly, BinaryLittleAndBigEndianWithOddTypes) {
    for (bool big : {false, true}) {
        SCOPED_TRACE(big ? "big-endian" : "little-endian");
        TempFile f(big ? "odd_be.ply" : "odd_le.ply", oddBinary(big));
        MeshLoadReport rep;
        expectSquare(loadMesh(f.path, &rep), rep);
    }
}

TEST(MeshPly, FacesBeforeVerticesAndEveryIndexType) {
    // Index types int8 .. uint32 and count types uchar .. uint: the same
    // triangle list each time.
    const char* types[] = {"char", "uchar", "short", "ushort", "int", "uint", "int8", "uint16", "int32"};
    for (const char* indexType : types) {
        SCOPED_TRACE(indexType);
        Body b(false);
        // count type uint, indices of the type under test
        auto index = [&](int v) {
            const std::string t = indexType;
            if (t == "char" || t == "int8")
                b.put<std::int8_t>(std::int8_t(v));
            else if (t == "uchar")
                b.put<std::uint8_t>(std::uint8_t(v));
            else if (t == "short")
                b.put<std::int16_t>(std::int16_t(v));
            else if (t == "ushort" || t == "uint16")
                b.put<std::uint16_t>(std::uint16_t(v));
            else if (t == "int" || t == "int32")
                b.put<std::int32_t>(v);
            else
                b.put<std::uint32_t>(std::uint32_t(v));
        };
        b.put<std::uint32_t>(4);
        for (int v : {0, 1, 2, 3})
            index(v);
        b.put<std::uint32_t>(3);
        for (int v : {1, 4, 2})
            index(v);
        for (float x : kSquarePositions)
            b.put<float>(x);
        const std::string header = std::string("ply\nformat binary_little_endian 1.0\nelement face 2\n"
                                               "property list uint ") +
                                   indexType +
                                   " vertex_indices\nelement vertex 5\nproperty float x\nproperty float y\n"
                                   "property float z\nend_header\n";
        TempFile f("faces_first.ply", header + b.bytes);
        MeshLoadReport rep;
        expectSquare(loadMesh(f.path, &rep), rep);
    }
}

// A tiny independent reader for the bunny's layout (ASCII, x y z first on
// each vertex line, "3 a b c" faces), from the header's own counts.
TEST(MeshPly, BunnyMatchesAReferenceReaderValueForValue) {
    const std::string path = kAssets + "/stanford_bunny/bun_zipper.ply";
    std::ifstream in(path);
    ASSERT_TRUE(in) << path;
    std::string line;
    std::size_t nv = 0, nf = 0;
    while (std::getline(in, line) && line.rfind("end_header", 0) != 0) {
        std::istringstream w(line);
        std::string key, name;
        std::size_t n = 0;
        if (w >> key >> name >> n && key == "element") (name == "vertex" ? nv : nf) = n;
    }
    std::vector<float> positions;
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (std::size_t v = 0; v < nv && std::getline(in, line); ++v) {
        char* p = line.data();
        for (int k = 0; k < 3; ++k) {
            const float x = std::strtof(p, &p);
            positions.push_back(x);
            lo[k] = std::min(lo[k], x);
            hi[k] = std::max(hi[k], x);
        }
    }
    std::vector<std::uint32_t> indices;
    for (std::size_t f = 0; f < nf && std::getline(in, line); ++f) {
        std::istringstream w(line);
        int n = 0;
        w >> n;
        ASSERT_EQ(n, 3) << "face " << f;
        for (int k = 0; k < 3; ++k) {
            std::uint32_t i = 0;
            w >> i;
            indices.push_back(i);
        }
    }
    ASSERT_EQ(positions.size(), nv * 3);
    ASSERT_EQ(indices.size(), nf * 3);

    MeshLoadReport rep;
    const Mesh m = loadMesh(path, &rep);
    EXPECT_EQ(m.vertexCount(), nv);
    EXPECT_EQ(m.triangleCount() + rep.degenerateFacesDropped, nf);
    EXPECT_EQ(m.positions, positions); // bit for bit: both round once to float
    // The bunny has no degenerate faces, so the triangle list is the file's.
    EXPECT_EQ(rep.degenerateFacesDropped, 0u);
    EXPECT_EQ(m.indices, indices);
    for (int k = 0; k < 3; ++k) {
        float mlo = INFINITY, mhi = -INFINITY;
        for (std::size_t v = 0; v < m.vertexCount(); ++v) {
            mlo = std::min(mlo, m.positions[3 * v + k]);
            mhi = std::max(mhi, m.positions[3 * v + k]);
        }
        EXPECT_EQ(mlo, lo[k]) << "axis " << k;
        EXPECT_EQ(mhi, hi[k]) << "axis " << k;
    }
}

// The spot OBJ written out as binary big-endian PLY (double coordinates) and
// as OFF with colours must load to the same mesh as the OBJ itself: the OBJ
// parser is the independent path.
TEST(MeshFormats, SpotThroughPlyAndOffEqualsTheObj) {
    const Mesh obj = loadMesh(kAssets + "/spot/spot.obj");
    ASSERT_GT(obj.triangleCount(), 0u);
    Body b(true);
    for (float x : obj.positions)
        b.put<double>(double(x));
    for (std::size_t t = 0; t < obj.triangleCount(); ++t) {
        b.put<std::uint8_t>(3);
        for (int k = 0; k < 3; ++k)
            b.put<std::uint32_t>(obj.indices[3 * t + k]);
    }
    TempFile ply("spot_be.ply",
                 "ply\nformat binary_big_endian 1.0\nelement vertex " + std::to_string(obj.vertexCount()) +
                     "\nproperty double x\nproperty double y\nproperty double z\nelement face " +
                     std::to_string(obj.triangleCount()) +
                     "\nproperty list uchar uint vertex_indices\nend_header\n" + b.bytes);
    std::ostringstream off;
    off.precision(9);
    off << "COFF\n# spot, from the OBJ\n" << obj.vertexCount() << " " << obj.triangleCount() << " 0\n";
    for (std::size_t v = 0; v < obj.vertexCount(); ++v)
        off << obj.positions[3 * v] << " " << obj.positions[3 * v + 1] << " " << obj.positions[3 * v + 2]
            << " 0.5 0.5 0.5 1\n";
    for (std::size_t t = 0; t < obj.triangleCount(); ++t)
        off << "3 " << obj.indices[3 * t] << " " << obj.indices[3 * t + 1] << " " << obj.indices[3 * t + 2]
            << " 255 0 0\n";
    TempFile offFile("spot.off", off.str());
    for (const std::string& path : {ply.path, offFile.path}) {
        SCOPED_TRACE(path);
        const Mesh m = loadMesh(path);
        EXPECT_EQ(m.positions, obj.positions);
        EXPECT_EQ(m.indices, obj.indices);
    }
}

TEST(MeshPly, ProgressRisesToOneAndCancelStopsMidRead) {
    const std::string path = kAssets + "/stanford_bunny/bun_zipper.ply";
    std::vector<double> seen;
    loadMesh(path, nullptr, nullptr, [&](double f) { seen.push_back(f); });
    ASSERT_GE(seen.size(), 2u); // one tick per 64k elements (105k here), then 1.0
    EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
    EXPECT_GT(seen.front(), 0.0);
    EXPECT_DOUBLE_EQ(seen.back(), 1.0);

    // Cancelling from the first progress report stops the load before it
    // reports again.
    CancelToken token;
    int reports = 0;
    EXPECT_THROW(loadMesh(path, nullptr, &token,
                          [&](double) {
                              ++reports;
                              token.cancelled = true;
                          }),
                 Cancelled);
    EXPECT_EQ(reports, 1);
}

TEST(MeshOff, CommentsColoursPolygonsAndCountsOnTheKeywordLine) {
    // CRLF endings, comments everywhere, counts after the keyword, a
    // pentagon (3 fan triangles) with colour columns, vertex colours.
    TempFile f("poly.off", "# leading comment\r\n"
                           "COFF 6 2 0 # counts here\r\n"
                           "\r\n"
                           "0 0 0 255 0 0 255\r\n"
                           "1 0 0 255 0 0 255 # a comment after a vertex\r\n"
                           "2 1 0 0 255 0 255\r\n"
                           "1 2 0 0 0 255 255\r\n"
                           "0 1 0 9 9 9 9\r\n"
                           "# between vertices and faces\r\n"
                           "+5e-1 -2.5e+0 1e0\r\n"
                           "5 0 1 2 3 4 0.1 0.2 0.3 1\r\n"
                           "3 0 1 5\r\n");
    MeshLoadReport rep;
    const Mesh m = loadMesh(f.path, &rep);
    const std::vector<float> positions = {0, 0, 0, 1, 0, 0, 2, 1, 0, 1, 2, 0, 0, 1, 0, 0.5f, -2.5f, 1};
    const std::vector<std::uint32_t> indices = {0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 1, 5};
    EXPECT_EQ(m.positions, positions);
    EXPECT_EQ(m.indices, indices);
    EXPECT_EQ(rep.polygonsTriangulated, 1u);
}

TEST(MeshOff, NormalsAndTextureVariantsAndTwoNumberCounts) {
    for (const char* keyword : {"OFF", "NOFF", "STOFF", "CNOFF", "STCNOFF"}) {
        SCOPED_TRACE(keyword);
        TempFile f("variant.off",
                   std::string(keyword) + "\n3 1\n0 0 0 0 0 1\n4 0 0 0 0 1\n0 5 0 0 0 1\n3 0 1 2\n");
        const Mesh m = loadMesh(f.path);
        const std::vector<float> positions = {0, 0, 0, 4, 0, 0, 0, 5, 0};
        EXPECT_EQ(m.positions, positions);
        EXPECT_EQ(m.triangleCount(), 1u);
    }
}

// Exact messages: the file, the line (ASCII) or element and byte offset (binary).
TEST(MeshPly, TruncatedAndGarbageInputGiveExactErrors) {
    const std::string head =
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    {
        TempFile f("trunc.ply", head + "0 0 0\n1 0 0\n0 1 0\n3 0 1\n");
        EXPECT_EQ(loadErrorText(f.path), f.path + ":13: PLY file ends inside element 'face' 0 of 1");
    }
    {
        TempFile f("word.ply", head + "0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n");
        EXPECT_EQ(loadErrorText(f.path),
                  f.path + ":11: element 'vertex' 1 of 3, property 'y': 'zero' is not a number");
    }
    {
        TempFile f("nan.ply", head + "0 0 0\n1 0 0\n0 nan 0\n3 0 1 2\n");
        EXPECT_EQ(loadErrorText(f.path), f.path + ":12: vertex 2 has a non-finite coordinate 'nan'");
    }
    {
        TempFile f("big.ply", head + "0 0 0\n1 0 0\n0 1e39 0\n3 0 1 2\n");
        EXPECT_EQ(loadErrorText(f.path), f.path + ":12: vertex 2 has a non-finite coordinate '1e39'");
    }
    {
        TempFile f("range.ply", head + "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n");
        EXPECT_EQ(loadErrorText(f.path), f.path + ":13: face 0 refers to vertex 3, outside 0..2");
    }
    {
        TempFile f("count.ply", head + "0 0 0\n1 0 0\n0 1 0\n-1 0 1 2\n");
        EXPECT_EQ(loadErrorText(f.path),
                  f.path + ":13: element 'face' 0 of 1: list 'vertex_indices' announces -1 items; "
                           "expected a count the rest of the file can hold");
    }
    {
        TempFile f("half.ply", head + "0 0 0\n1 0 0\n0 1 0\n3 0 1.5 2\n");
        EXPECT_EQ(loadErrorText(f.path),
                  f.path +
                      ":13: element 'face' 0 of 1, property 'vertex_indices': '1.5' is not a whole number");
    }
    {
        TempFile f("nox.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float y\nproperty float z\n"
                              "element face 0\nproperty list uchar int vertex_indices\nend_header\n0 0\n");
        EXPECT_EQ(loadErrorText(f.path), f.path + ":3: PLY header: element 'vertex' has no property 'x'");
    }
    {
        TempFile f("noface.ply",
                   "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                   "property float z\nend_header\n0 0 0\n");
        EXPECT_EQ(loadErrorText(f.path), f.path + ":7: PLY header declares no 'face' element");
    }
    {
        TempFile f("floatidx.ply",
                   "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                   "property float z\nelement face 1\nproperty list uchar float vertex_indices\n"
                   "end_header\n0 0 0\n");
        EXPECT_EQ(loadErrorText(f.path),
                  f.path + ":7: PLY header: face property 'vertex_indices' must hold integer vertex indices");
    }
    {
        TempFile f("noformat.ply", "ply\nelement vertex 1\nproperty float x\nend_header\n0\n");
        EXPECT_EQ(loadErrorText(f.path), f.path + ":4: PLY header: no format line before end_header");
    }
}

TEST(MeshPly, BinaryErrorsNameTheElementAndByteOffset) {
    const std::string head = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
                             "property float y\nproperty float z\nelement face 1\n"
                             "property list uchar int vertex_indices\nend_header\n";
    const std::size_t body = head.size();
    Body vertices(false);
    for (float x : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f})
        vertices.put<float>(x);
    {
        // A face with a flags byte after its list: the file ends before it.
        std::string flagged = head;
        flagged.insert(flagged.find("end_header"), "property uchar flags\n");
        Body b = vertices;
        b.put<std::uint8_t>(3).put<std::int32_t>(0).put<std::int32_t>(1).put<std::int32_t>(2);
        TempFile f("trunc_le.ply", flagged + b.bytes);
        EXPECT_EQ(loadErrorText(f.path), f.path +
                                             ": PLY file ends inside element 'face' 0 of 1 (byte offset " +
                                             std::to_string(flagged.size() + 36 + 1 + 12) + ")");
    }
    {
        Body b = vertices;
        b.put<std::uint8_t>(3).put<std::int32_t>(0).put<std::int32_t>(-1).put<std::int32_t>(2);
        TempFile f("neg_le.ply", head + b.bytes);
        EXPECT_EQ(loadErrorText(f.path), f.path + ": face 0 refers to vertex -1, outside 0..2 (byte offset " +
                                             std::to_string(body + 36 + 1 + 8) + ")");
    }
    {
        Body b = vertices;
        b.put<std::uint8_t>(250).put<std::int32_t>(0).put<std::int32_t>(1).put<std::int32_t>(2);
        TempFile f("longlist_le.ply", head + b.bytes);
        EXPECT_EQ(loadErrorText(f.path),
                  f.path +
                      ": element 'face' 0 of 1: list 'vertex_indices' announces 250 items; "
                      "expected a count the rest of the file can hold (byte offset " +
                      std::to_string(body + 36 + 1) + ")");
    }
    {
        Body b(false);
        for (float x : {0.f, 0.f, 0.f, 1.f, std::nanf(""), 0.f, 0.f, 1.f, 0.f})
            b.put<float>(x);
        b.put<std::uint8_t>(3).put<std::int32_t>(0).put<std::int32_t>(1).put<std::int32_t>(2);
        TempFile f("nan_le.ply", head + b.bytes);
        EXPECT_EQ(loadErrorText(f.path), f.path + ": vertex 1 has a non-finite coordinate (byte offset " +
                                             std::to_string(body + 20) + ")");
    }
    {
        // Vertices of 12 bytes each: 3 announced, 20 bytes given.
        TempFile f("short_le.ply", head + vertices.bytes.substr(0, 20));
        EXPECT_EQ(
            loadErrorText(f.path),
            f.path + ":3: PLY header: element 'vertex' announces 3 items of at least 12 bytes, more than the "
                     "20 bytes after the header hold");
    }
}

TEST(MeshOff, TruncatedAndGarbageInputGiveExactErrors) {
    auto error = [](const std::string& name, const std::string& text) {
        TempFile f(name, text);
        const std::string e = loadErrorText(f.path);
        return e.rfind(f.path, 0) == 0 ? e.substr(f.path.size()) : "(no file name) " + e;
    };
    EXPECT_EQ(error("a.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n"), ":4: OFF file ends before vertex 2 of 3");
    EXPECT_EQ(error("b.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n"), ":5: OFF file ends before face 0 of 1");
    EXPECT_EQ(error("c.off", "OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n"),
              ":4: OFF file: vertex 1 needs three coordinates, not '1 0'");
    EXPECT_EQ(error("d.off", "OFF\n3 1 0\n0 0 0\n1 x 0\n0 1 0\n3 0 1 2\n"),
              ":4: OFF file: vertex 1: 'x' is not a number");
    EXPECT_EQ(error("e.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n"),
              ":6: OFF file: face 0 announces 4 vertices but its line holds 3 numbers after the count");
    EXPECT_EQ(error("f.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2.5\n"),
              ":6: OFF file: face 0: '2.5' is not a vertex index");
    EXPECT_EQ(error("h.off", "4OFF\n1 1 0\n0 0 0 1\n"),
              ":1: OFF file: 4OFF (4-D or n-D vertices) is not supported");
    EXPECT_EQ(error("i.off", "PLY\n3 1 0\n"),
              ":1: OFF file: the first line must name the OFF format, not 'PLY'");
    EXPECT_EQ(error("j.off", "# only a comment\n\n"),
              ":2: OFF file: no OFF keyword (only blank or comment lines)");
    EXPECT_EQ(error("k.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1e39 0\n3 0 1 2\n"),
              ":5: vertex 2 has a non-finite coordinate '1e39'");
    EXPECT_EQ(error("l.off", "OFF\n3 x 0\n"),
              ":2: OFF file: the counts line is \"<vertices> <faces> <edges>\", not '3 x 0'");
}

// ---- binary OFF ------------------------------------------------------------

// The square mesh (a quad and a triangle) as binary OFF under `keyword`'s
// prefixes, in OpenMesh's little-endian layout (colours 3 int32 per vertex and
// face, no face colour count) or Geomview's big-endian one (vertex colour 4
// float32, per face a colour count and that many float32). Prefix data are
// filled with values that are not coordinates so a misplaced read shows.
std::string squareBinaryOff(const std::string& keyword, bool big, int faceColours = 0) {
    const bool st = keyword.find("ST") != std::string::npos;
    const bool c = keyword.find('C') != std::string::npos;
    const bool n = keyword.find('N') != std::string::npos;
    Body b(big);
    b.put<std::int32_t>(5).put<std::int32_t>(2).put<std::int32_t>(7);
    for (std::size_t v = 0; v < 5; ++v) {
        for (int k = 0; k < 3; ++k)
            b.put<float>(kSquarePositions[3 * v + std::size_t(k)]);
        if (n) b.put<float>(-7.f).put<float>(-8.f).put<float>(-9.f);
        if (c && big) b.put<float>(0.25f).put<float>(0.5f).put<float>(0.75f).put<float>(1.f);
        if (c && !big) b.put<std::int32_t>(200).put<std::int32_t>(100).put<std::int32_t>(50);
        if (st) b.put<float>(0.125f).put<float>(0.875f);
    }
    auto colour = [&] {
        if (big) {
            b.put<std::int32_t>(faceColours);
            for (int k = 0; k < faceColours; ++k)
                b.put<float>(0.5f);
        } else if (c) {
            b.put<std::int32_t>(255).put<std::int32_t>(0).put<std::int32_t>(3);
        }
    };
    b.put<std::int32_t>(4).put<std::int32_t>(0).put<std::int32_t>(1).put<std::int32_t>(2).put<std::int32_t>(
        3);
    colour();
    b.put<std::int32_t>(3).put<std::int32_t>(1).put<std::int32_t>(4).put<std::int32_t>(2);
    colour();
    return keyword + " BINARY\n" + b.bytes;
}

TEST(MeshOff, BinaryBothByteOrdersAndPrefixesEqualTheAsciiOff) {
    TempFile ascii("square_ascii.off", "OFF\n5 2 0\n0 0 0\n2 0 0\n2 2 0\n0 2 0\n1.5 -0.25 3\n"
                                       "4 0 1 2 3\n3 1 4 2\n");
    const Mesh reference = loadMesh(ascii.path);
    ASSERT_EQ(reference.positions, kSquarePositions);
    ASSERT_EQ(reference.indices, kSquareIndices);
    for (const char* keyword : {"OFF", "COFF", "NOFF", "STOFF", "CNOFF", "STCNOFF"})
        for (bool big : {false, true})
            for (int faceColours : {0, 3, 4}) {
                if (!big && faceColours != 0) continue; // OpenMesh's layout has no colour count
                SCOPED_TRACE(std::string(keyword) +
                             (big ? " big-endian, face colours " : " little-endian, ") +
                             std::to_string(faceColours));
                TempFile f("square_bin.off", squareBinaryOff(keyword, big, faceColours));
                const Mesh m = loadMesh(f.path);
                EXPECT_EQ(m.positions, reference.positions);
                EXPECT_EQ(m.indices, reference.indices);
            }
    // Geomview allows white space and a comment between BINARY and the
    // newline that ends the header, and comment lines before it.
    const std::string body = squareBinaryOff("OFF", true).substr(std::string("OFF BINARY\n").size());
    TempFile commented("square_comment.off", "# made by hand\nOFF BINARY\t# binary data follow\r\n" + body);
    const Mesh m = loadMesh(commented.path);
    EXPECT_EQ(m.positions, reference.positions);
    EXPECT_EQ(m.indices, reference.indices);
}

// Independent check: the spot mesh written as binary OFF by OpenMesh 9's own
// writer (plain, and with normals, colours and texture coordinates) loads to
// the same mesh as the OBJ it came from.
TEST(MeshOff, BinaryWrittenByOpenMeshEqualsTheObj) {
    const Mesh obj = loadMesh(kAssets + "/spot/spot.obj");
    ASSERT_GT(obj.triangleCount(), 0u);
    using PolyMesh = OpenMesh::PolyMesh_ArrayKernelT<>;
    PolyMesh om;
    om.request_vertex_normals();
    om.request_vertex_colors();
    om.request_face_colors();
    om.request_vertex_texcoords2D();
    std::vector<PolyMesh::VertexHandle> vh;
    for (std::size_t v = 0; v < obj.vertexCount(); ++v) {
        vh.push_back(
            om.add_vertex({obj.positions[3 * v], obj.positions[3 * v + 1], obj.positions[3 * v + 2]}));
        om.set_normal(vh.back(), {1e30f, -1e30f, 3.f}); // not coordinates: a misplaced read shows
        om.set_color(vh.back(), {10, 20, 30});
        om.set_texcoord2D(vh.back(), {0.5f, 2e20f});
    }
    for (std::size_t t = 0; t < obj.triangleCount(); ++t) {
        const auto f =
            om.add_face(vh[obj.indices[3 * t]], vh[obj.indices[3 * t + 1]], vh[obj.indices[3 * t + 2]]);
        ASSERT_TRUE(f.is_valid()) << "triangle " << t;
        om.set_color(f, {255, 0, 7});
    }
    using Opt = OpenMesh::IO::Options;
    for (Opt::Flag extra : {Opt::Default, Opt::Flag(Opt::VertexNormal | Opt::VertexColor | Opt::FaceColor |
                                                    Opt::VertexTexCoord)}) {
        SCOPED_TRACE(extra == Opt::Default ? "OFF BINARY" : "STCNOFF BINARY");
        const std::string path = tempPath("spot_openmesh.off");
        ASSERT_TRUE(OpenMesh::IO::write_mesh(om, path, Opt(Opt::Binary | extra)));
        const Mesh m = loadMesh(path);
        std::remove(path.c_str());
        EXPECT_EQ(m.positions, obj.positions);
        EXPECT_EQ(m.indices, obj.indices);
    }
}

TEST(MeshOff, BinaryTruncatedAndGarbageInputGiveExactErrors) {
    auto error = [](const std::string& name, const std::string& bytes) {
        TempFile f(name, bytes);
        const std::string e = loadErrorText(f.path);
        return e.rfind(f.path, 0) == 0 ? e.substr(f.path.size()) : "(no file name) " + e;
    };
    const std::string le = squareBinaryOff("OFF", false); // header 11 bytes, counts, 60 + 36 bytes
    const std::string be = squareBinaryOff("OFF", true, 3);
    ASSERT_EQ(le.size(), 11u + 12u + 60u + 20u + 16u);
    EXPECT_EQ(
        error("a.off", "OFF BINARY\n"),
        ": binary OFF file ends inside its counts (three int32: vertices, faces, edges) (byte offset 11)");
    EXPECT_EQ(error("b.off", "OFF BINARY"), ":1: binary OFF file ends after its header line");
    EXPECT_EQ(error("c.off", "OFF BINARY 5 2 0\n"),
              ":1: OFF file: binary data must start on the line after \"OFF BINARY\", not after '5'");
    // Cut inside the last face: the counts still fit at minimum face size.
    EXPECT_EQ(
        error("d.off", le.substr(0, le.size() - 4)),
        ": binary OFF file (little-endian (OpenMesh)): face 1 of 2 announces 3 vertices; expected a count "
        "the rest of the file can hold (byte offset 103)");
    EXPECT_EQ(
        error("e.off", be.substr(0, be.size() - 4)),
        ": binary OFF file (big-endian (Geomview)): face 1 of 2 announces 3 colour components; expected a "
        "count the rest of the file can hold (byte offset 135)");
    EXPECT_EQ(error("f.off", be.substr(0, be.size() - 16)),
              ": binary OFF file (big-endian (Geomview)): ends before the colour count of face 1 of 2 "
              "(byte offset 135)");
    // Cut inside the vertices: neither byte order's counts fit.
    EXPECT_EQ(
        error("g.off", le.substr(0, 40)),
        ": binary OFF file announces 5 vertices and 2 faces little-endian (OpenMesh) or 83886080 vertices "
        "and 33554432 faces big-endian (Geomview), more than the 17 bytes after the counts can hold "
        "(byte offset 11)");
    // Garbage: an index out of range, a negative vertex count, a NaN.
    std::string bad = le;
    bad[le.size() - 4] = 9; // face 1's last index (little-endian low byte)
    EXPECT_EQ(error("h.off", bad),
              ": binary OFF file (little-endian (OpenMesh)): face 1 refers to vertex 9, outside 0..4 "
              "(byte offset 115)");
    bad = le;
    bad[103] = '\xff', bad[104] = '\xff', bad[105] = '\xff', bad[106] = '\xff';
    EXPECT_EQ(
        error("i.off", bad),
        ": binary OFF file (little-endian (OpenMesh)): face 1 of 2 announces -1 vertices; expected a count "
        "the rest of the file can hold (byte offset 103)");
    bad = le;
    bad[23 + 12 + 6] = '\xc0', bad[23 + 12 + 7] = '\x7f'; // vertex 1's z: 0x7fc00000, a NaN
    EXPECT_EQ(error("j.off", bad),
              ": binary OFF file (little-endian (OpenMesh)): vertex 1 has a non-finite coordinate "
              "(byte offset 35)");
    Body noFaces(false);
    noFaces.put<std::int32_t>(1)
        .put<std::int32_t>(0)
        .put<std::int32_t>(0)
        .put<float>(0)
        .put<float>(0)
        .put<float>(0);
    EXPECT_EQ(error("k.off", "OFF BINARY\n" + noFaces.bytes),
              ": binary OFF file (little-endian (OpenMesh)) announces 1 vertices and 0 faces: no triangles "
              "(byte offset 11)");
}

// Counts that both byte orders can hold: 65,536 vertices and 256 faces written
// big-endian read as 256 and 65,536 little-endian, which a 790 kB file can
// also hold. Little-endian is tried first, fails on face 0, and the
// big-endian reading wins; the little-endian twin loads as little-endian.
TEST(MeshOff, BinaryCountsThatFitBothByteOrdersFallBackToTheOneThatParses) {
    for (bool big : {true, false}) {
        SCOPED_TRACE(big ? "big-endian file" : "little-endian file");
        const std::int32_t nv = big ? 65536 : 256, nf = big ? 256 : 65536;
        Body b(big);
        b.put<std::int32_t>(nv).put<std::int32_t>(nf).put<std::int32_t>(0);
        std::vector<float> positions;
        for (std::int32_t v = 0; v < nv; ++v)
            for (float x : {float(v), float(v % 2), 1.f}) {
                b.put<float>(x);
                positions.push_back(x);
            }
        std::vector<std::uint32_t> indices;
        for (std::int32_t f = 0; f < nf; ++f) {
            const std::uint32_t i = std::uint32_t(f % (std::min(nv, nf) - 2));
            b.put<std::int32_t>(3).put<std::int32_t>(std::int32_t(i)).put<std::int32_t>(std::int32_t(i + 1));
            b.put<std::int32_t>(std::int32_t(i + 2));
            if (big) b.put<std::int32_t>(0);
            indices.insert(indices.end(), {i, i + 1, i + 2});
        }
        TempFile file("both_orders.off", "OFF BINARY\n" + b.bytes);
        MeshLoadReport rep;
        const Mesh m = loadMesh(file.path, &rep);
        EXPECT_EQ(m.positions.size(), positions.size());
        EXPECT_TRUE(m.positions == positions);
        EXPECT_TRUE(m.indices == indices);
    }
}

// Progress and cancel every 64k elements in binary OFF too.
TEST(MeshOff, BinaryReportsProgressAndCancel) {
    constexpr int kFaces = 70000;
    Body b(true);
    b.put<std::int32_t>(3).put<std::int32_t>(kFaces).put<std::int32_t>(0);
    for (float x : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f})
        b.put<float>(x);
    for (int f = 0; f < kFaces; ++f)
        b.put<std::int32_t>(3)
            .put<std::int32_t>(0)
            .put<std::int32_t>(1)
            .put<std::int32_t>(2)
            .put<std::int32_t>(0);
    TempFile file("many_bin.off", "OFF BINARY\n" + b.bytes);
    std::vector<double> seen;
    const Mesh m = loadMesh(file.path, nullptr, nullptr, [&](double f) { seen.push_back(f); });
    EXPECT_EQ(m.triangleCount(), std::size_t(kFaces));
    ASSERT_EQ(seen.size(), 2u);
    EXPECT_GT(seen[0], 0.5);
    EXPECT_LT(seen[0], 0.9);
    EXPECT_DOUBLE_EQ(seen[1], 1.0);
    CancelToken token;
    int reports = 0;
    EXPECT_THROW(loadMesh(file.path, nullptr, &token,
                          [&](double) {
                              ++reports;
                              token.cancelled = true;
                          }),
                 Cancelled);
    EXPECT_EQ(reports, 1);
}

// The OFF and binary PLY readers report progress and honour cancel every 64k
// elements too (70,000 faces: one report inside the faces, then 1.0).
TEST(MeshFormats, OffAndBinaryPlyReportProgressAndCancel) {
    constexpr int kFaces = 70000;
    std::string off = "OFF\n3 " + std::to_string(kFaces) + " 0\n0 0 0\n1 0 0\n0 1 0\n";
    Body ply(false);
    for (float x : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f})
        ply.put<float>(x);
    for (int f = 0; f < kFaces; ++f) {
        off += "3 0 1 2\n";
        ply.put<std::uint8_t>(3).put<std::int32_t>(0).put<std::int32_t>(1).put<std::int32_t>(2);
    }
    TempFile offFile("many.off", off);
    TempFile plyFile("many.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
                                 "property float y\nproperty float z\nelement face " +
                                     std::to_string(kFaces) +
                                     "\nproperty list uchar int vertex_indices\nend_header\n" + ply.bytes);
    for (const std::string& path : {offFile.path, plyFile.path}) {
        SCOPED_TRACE(path);
        std::vector<double> seen;
        const Mesh m = loadMesh(path, nullptr, nullptr, [&](double f) { seen.push_back(f); });
        EXPECT_EQ(m.triangleCount(), std::size_t(kFaces));
        ASSERT_EQ(seen.size(), 2u);
        EXPECT_GT(seen[0], 0.5); // 65,535 of 70,000 faces read
        EXPECT_LT(seen[0], 0.9);
        EXPECT_DOUBLE_EQ(seen[1], 1.0);

        CancelToken token;
        int reports = 0;
        EXPECT_THROW(loadMesh(path, nullptr, &token,
                              [&](double) {
                                  ++reports;
                                  token.cancelled = true;
                              }),
                     Cancelled);
        EXPECT_EQ(reports, 1);
    }
}
