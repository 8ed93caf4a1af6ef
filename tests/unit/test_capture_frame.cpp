// A renderer's frame read from a RenderDoc capture (culling/capture/
// capture_frame.hpp), without RenderDoc: the description's checks, and the
// decoding of matrices, lights, depth formats and list layouts from the bytes
// a replay hands back. tests/gpu/test_renderdoc.cpp reads real captures.
#include "culling/capture/capture_frame.hpp"
#include "culling/core/errors.hpp"
#include "culling/core/pipeline.hpp"
#include "culling/math/projection.hpp"
#include "culling/scene/scene_io.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

using namespace lc;

namespace {

std::string descriptionError(const std::string& text) {
    try {
        parseCaptureDescription(text, "desc.json");
    } catch (const InputError& e) {
        return e.field() + " | " + e.what();
    }
    return "";
}

// The contract-like description the tests decode with.
const char* kDescription = R"({
  "lights": {"binding": "0.3", "stride": 32, "position": 0, "radius": 12, "spot_axis": 16, "spot_angle": 28},
  "camera": {"binding": "0.0", "projection": 64, "view": 0},
  "depth": {"binding": "0.1"},
  "lists": {"layout": "fixed:8", "binding": "0.4", "tile": 16}
})";

template <typename T> void put(std::string& bytes, std::size_t at, T v) {
    if (bytes.size() < at + sizeof v) bytes.resize(at + sizeof v, '\0');
    std::memcpy(bytes.data() + at, &v, sizeof v);
}

void putMatrix(std::string& bytes, std::size_t at, const glm::dmat4& m, bool rowMajor = false) {
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) put(bytes, at + 4 * std::size_t(rowMajor ? r * 4 + c : c * 4 + r), float(m[c][r]));
}

CaptureBlob blob(const std::string& kind, std::string bytes, std::uint32_t binding) {
    CaptureBlob b;
    b.binding.kind = kind;
    b.binding.binding = binding;
    b.binding.resource = "res" + std::to_string(binding);
    b.bytes = std::move(bytes);
    return b;
}

CaptureBlob depthImage(std::uint32_t w, std::uint32_t h, const std::vector<float>& px, const std::string& format = "D32") {
    CaptureBlob b = blob("image", "", 1);
    b.binding.width = w;
    b.binding.height = h;
    b.binding.format = format;
    b.binding.componentBytes = 4;
    b.binding.components = 1;
    b.binding.componentType = "Depth";
    for (std::size_t i = 0; i < px.size(); ++i) put(b.bytes, 4 * i, px[i]);
    return b;
}

Camera lensCamera(ProjectionKind kind, double nearP, double farP) {
    Camera c;
    c.projection = kind;
    c.fovYDeg = 50;
    c.nearPlane = nearP;
    c.farPlane = farP;
    c.width = 64;
    c.height = 32;
    c.tileSize = 16;
    return c;
}

// A frame of 64x32 pixels (4x2 tiles of 16) with `cam`'s projection and an
// identity view, two lights, and fixed:8 lists that list light 1 in tile 0.
std::map<std::string, CaptureBlob> frameBlobs(const Camera& cam, const glm::dmat4& view = glm::dmat4(1.0)) {
    std::map<std::string, CaptureBlob> m;
    std::string camera;
    putMatrix(camera, 0, view);
    putMatrix(camera, 64, Projection(cam).clipFromView());
    m["camera"] = blob("buffer", camera, 0);
    std::string lights;
    put(lights, 0, 1.0f), put(lights, 4, 2.0f), put(lights, 8, -10.0f), put(lights, 12, 3.0f); // point
    put(lights, 32 + 0, 0.0f), put(lights, 32 + 4, 0.0f), put(lights, 32 + 8, -5.0f), put(lights, 32 + 12, 4.0f);
    put(lights, 32 + 16, 0.0f), put(lights, 32 + 20, 0.0f), put(lights, 32 + 24, -1.0f);
    put(lights, 32 + 28, float(30.0 * 3.14159265358979 / 180.0)); // spot, 30 degrees
    m["lights"] = blob("buffer", lights, 3);
    std::vector<float> px(64 * 32, float(Projection(cam).clearDepth()));
    px[0] = 0.5f;
    m["depth"] = depthImage(64, 32, px);
    std::string lists;
    put(lists, 0, 1u), put(lists, 4, 1u); // tile 0: one light, light 1
    put(lists, 4 * 9 * 8 - 4, 0u);        // 8 lists of 9 words
    m["lists"] = blob("buffer", lists, 4);
    return m;
}

std::string decodeError(const CaptureDescription& d, const std::map<std::string, CaptureBlob>& blobs) {
    try {
        decodeCaptureFrame(d, blobs, "frame.rdc", 7);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

} // namespace

TEST(CaptureDescription, NamesTheJsonPathOfEachMistake) {
    EXPECT_NE(descriptionError("[1]").find("JSON object"), std::string::npos);
    EXPECT_NE(descriptionError("{").find("not JSON"), std::string::npos);
    // A misspelt optional field is refused, not left out: the spot cone,
    // a key of another list layout, a lens beside a projection matrix.
    const std::string base = R"("camera": {"binding": "0.0", "projection": 0}, "depth": {"binding": "0.1"})";
    const std::string typo = descriptionError(R"({"lights": {"binding": "0.3", "stride": 32, "position": 0,
        "radius": 12, "spot_axis": 16, "spot_angel": 28}, )" + base + R"(, "lists": {"layout": "fixed:8", "binding": "0.4"}})");
    EXPECT_NE(typo.find("lights.spot_angel | "), std::string::npos) << typo;
    EXPECT_NE(typo.find("unknown field (lights takes binding, stride"), std::string::npos) << typo;
    const std::string other = descriptionError(R"({"lights": {"binding": "0.3", "stride": 16, "position": 0,
        "radius": 12}, )" + base + R"(, "lists": {"layout": "counts+indices:8", "counts": "0.4", "indices": "0.5",
        "binding": "0.6"}})");
    EXPECT_NE(other.find("lists.binding | "), std::string::npos) << other;
    EXPECT_NE(other.find("lists with layout counts+indices:8 takes"), std::string::npos) << other;
    const std::string lens = descriptionError(R"({"lights": {"binding": "0.3", "stride": 16, "position": 0,
        "radius": 12}, "camera": {"binding": "0.0", "projection": 0, "reversed": true}, "depth": {"binding": "0.1"},
        "lists": {"layout": "fixed:8", "binding": "0.4"}})");
    EXPECT_NE(lens.find("camera.reversed | "), std::string::npos) << lens;
    // A number past a double's range (nlohmann throws out_of_range, not
    // parse_error: found by fuzz_capture).
    EXPECT_NE(descriptionError("{\"lights\": 1" + std::string(400, '7') + "}").find("not JSON"), std::string::npos);
    const std::string noBinding = descriptionError(R"({"lights": {"stride": 16, "position": 0, "radius": 12},
        "camera": {"fov_y_deg": 60, "near": 0.1, "far": 100}, "depth": {"binding": "0.1"},
        "lists": {"layout": "fixed:8", "binding": "0.4"}})");
    EXPECT_EQ(noBinding.rfind("lights.binding | ", 0), 0u) << noBinding;
    const std::string overlap = descriptionError(R"({"lights": {"binding": "0.3", "stride": 16, "position": 0, "radius": 8},
        "camera": {"fov_y_deg": 60, "near": 0.1, "far": 100}, "depth": {"binding": "0.1"},
        "lists": {"layout": "fixed:8", "binding": "0.4"}})");
    EXPECT_EQ(overlap.rfind("lights.radius | ", 0), 0u) << overlap;
    EXPECT_NE(overlap.find("overlaps position"), std::string::npos) << overlap;
    const std::string outside = descriptionError(R"({"lights": {"binding": "0.3", "stride": 16, "position": 0, "radius": 16},
        "camera": {"fov_y_deg": 60, "near": 0.1, "far": 100}, "depth": {"binding": "0.1"},
        "lists": {"layout": "fixed:8", "binding": "0.4"}})");
    EXPECT_EQ(outside.rfind("lights.radius | ", 0), 0u) << outside;
    EXPECT_NE(outside.find("outside the 16-byte stride"), std::string::npos) << outside;
    const std::string infinite = descriptionError(R"({"lights": {"binding": "0.3", "stride": 16, "position": 0, "radius": 12},
        "camera": {"fov_y_deg": 60, "near": 0.1, "far": "infinite"}, "depth": {"binding": "0.1"},
        "lists": {"layout": "fixed:8", "binding": "0.4"}})");
    EXPECT_EQ(infinite.rfind("camera.far | ", 0), 0u) << infinite;
    const std::string layout = descriptionError(R"({"lights": {"binding": "0.3", "stride": 16, "position": 0, "radius": 12},
        "camera": {"fov_y_deg": 60, "near": 0.1, "far": 100}, "depth": {"binding": "0.1"},
        "lists": {"layout": "counts+indices", "counts": "0.4", "indices": "0.5"}})");
    EXPECT_EQ(layout.rfind("lists.layout | ", 0), 0u) << layout;
    const std::string unknown = descriptionError(R"({"light": {}})");
    EXPECT_EQ(unknown.rfind("light | ", 0), 0u) << unknown;
    EXPECT_EQ(descriptionError(kDescription), "");
}

TEST(CaptureFrame, ProjectionMatricesGiveTheCameraTheyWereMadeFrom) {
    const CaptureDescription d = parseCaptureDescription(kDescription, "desc.json");
    struct Case {
        ProjectionKind kind;
        double nearP, farP;
    };
    const double inf = std::numeric_limits<double>::infinity();
    for (const Case& c : {Case{ProjectionKind::Perspective, 0.1, 100.0}, Case{ProjectionKind::ReversedZ, 0.5, 2000.0},
                          Case{ProjectionKind::ReversedZ, 0.1, inf}, Case{ProjectionKind::Orthographic, 1.0, 50.0}}) {
        Camera cam = lensCamera(c.kind, c.nearP, c.farP);
        if (c.kind == ProjectionKind::Orthographic) cam.orthoHeight = 12;
        const CaptureFrame f = decodeCaptureFrame(d, frameBlobs(cam), "frame.rdc", 7);
        const Camera& got = f.scene.camera;
        SCOPED_TRACE(toString(c.kind));
        EXPECT_EQ(got.projection, c.kind);
        EXPECT_NEAR(got.nearPlane, c.nearP, c.nearP * 1e-4);
        if (std::isinf(c.farP))
            EXPECT_TRUE(std::isinf(got.farPlane));
        else
            EXPECT_NEAR(got.farPlane, c.farP, c.farP * 2e-3); // a float matrix holds far to ~1e-4 of near/far
        if (c.kind == ProjectionKind::Orthographic)
            EXPECT_NEAR(got.orthoHeight, 12.0, 1e-5);
        else
            EXPECT_NEAR(got.fovYDeg, 50.0, 1e-4);
        EXPECT_EQ(got.width, 64u);
        EXPECT_EQ(got.height, 32u);
        EXPECT_EQ(f.depth.clearDepth, float(Projection(cam).clearDepth()));
    }
    // Row-major storage of the same matrices.
    CaptureDescription rows = d;
    rows.rowMajor = true;
    auto blobs = frameBlobs(lensCamera(ProjectionKind::ReversedZ, 0.5, 2000.0));
    std::string camera;
    putMatrix(camera, 0, glm::dmat4(1.0), true);
    putMatrix(camera, 64, Projection(lensCamera(ProjectionKind::ReversedZ, 0.5, 2000.0)).clipFromView(), true);
    blobs["camera"].bytes = camera;
    EXPECT_EQ(decodeCaptureFrame(rows, blobs, "frame.rdc", 7).scene.camera.projection, ProjectionKind::ReversedZ);
    // Read as column-major, the transposed matrix is no projection: said so.
    EXPECT_NE(decodeError(d, blobs).find("neither perspective"), std::string::npos) << decodeError(d, blobs);
}

TEST(CaptureFrame, WorldSpaceLightsAreMovedIntoViewSpaceBySpotAxisToo) {
    CaptureDescription d = parseCaptureDescription(kDescription, "desc.json");
    d.lightsInViewSpace = false;
    // The camera 10 units up the +X axis looking down -X: view = lookAt.
    Camera world = lensCamera(ProjectionKind::Perspective, 0.1, 100.0);
    world.position = {10, 0, 0};
    world.target = {0, 0, 0};
    const glm::dmat4 view = world.viewFromWorld();
    const CaptureFrame f = decodeCaptureFrame(d, frameBlobs(world, view), "frame.rdc", 7);
    ASSERT_EQ(f.scene.lights.size(), 2u);
    const glm::dvec3 expect = glm::dvec3(view * glm::dvec4(1.0, 2.0, -10.0, 1.0));
    EXPECT_NEAR(glm::length(f.scene.lights[0].position - expect), 0.0, 1e-5);
    EXPECT_DOUBLE_EQ(f.scene.lights[0].explicitRadius, 3.0);
    EXPECT_FALSE(f.scene.lights[0].isSpot());
    ASSERT_TRUE(f.scene.lights[1].isSpot());
    EXPECT_NEAR(f.scene.lights[1].outerAngleDeg, 30.0, 1e-4);
    const glm::dvec3 axis = glm::dmat3(view) * glm::dvec3(0, 0, -1);
    EXPECT_NEAR(glm::length(f.scene.lights[1].direction - axis), 0.0, 1e-6);
    // The echo names what was read, so a wrong description shows.
    std::string echo;
    for (const auto& l : f.echo) echo += l + "\n";
    EXPECT_NE(echo.find("lights: 2 (the binding's 64 bytes / stride 32), stride 32, world space"), std::string::npos)
        << echo;
    // As the buffer holds them (what RenderDoc's buffer view shows), the
    // view-space position beside.
    EXPECT_NE(echo.find("light 0: position (1, 2, -10) (view ("), std::string::npos) << echo;
    EXPECT_NE(echo.find("spot axis (0, 0, -1) outer 30"), std::string::npos) << echo;
    // World-space lights without a view matrix cannot be placed.
    d.view.reset();
    EXPECT_THROW(decodeCaptureFrame(d, frameBlobs(world, view), "frame.rdc", 7), InputError);
}

TEST(CaptureFrame, DepthFormatsAndRowOrder) {
    const CaptureDescription d = parseCaptureDescription(kDescription, "desc.json");
    const Camera cam = lensCamera(ProjectionKind::Perspective, 0.1, 100.0);
    auto blobs = frameBlobs(cam);
    // D16: 2 bytes a pixel, 0..65535.
    CaptureBlob d16 = depthImage(64, 32, {});
    d16.binding.format = "D16";
    d16.binding.componentBytes = 2;
    d16.bytes.assign(64 * 32 * 2, '\xff');
    put(d16.bytes, 0, std::uint16_t(32768));
    blobs["depth"] = d16;
    CaptureFrame f = decodeCaptureFrame(d, blobs, "frame.rdc", 7);
    EXPECT_FLOAT_EQ(f.depth.at(0, 0), 32768.0f / 65535.0f);
    EXPECT_FLOAT_EQ(f.depth.at(1, 0), 1.0f);
    // D24S8: depth in the low 24 bits, stencil above.
    CaptureBlob d24 = depthImage(64, 32, {});
    d24.binding.format = "D24S8";
    d24.bytes.assign(64 * 32 * 4, '\0');
    for (std::size_t i = 0; i < 64 * 32; ++i) put(d24.bytes, 4 * i, 0xAB000000u | 0xFFFFFFu);
    put(d24.bytes, 4 * (31 * 64 + 5), 0x7F000000u | 0x800000u);
    blobs["depth"] = d24;
    f = decodeCaptureFrame(d, blobs, "frame.rdc", 7);
    EXPECT_NEAR(f.depth.at(5, 31), 0x800000 / double(0xFFFFFF), 1e-7);
    EXPECT_FLOAT_EQ(f.depth.at(0, 0), 1.0f);
    // Bottom-up rows: the last row of the bytes is row 0.
    CaptureDescription up = d;
    up.bottomUp = true;
    f = decodeCaptureFrame(up, blobs, "frame.rdc", 7);
    EXPECT_NEAR(f.depth.at(5, 0), 0x800000 / double(0xFFFFFF), 1e-7);
    // A value that is no window depth names the pixel.
    std::vector<float> px(64 * 32, 1.0f);
    px[3 * 64 + 2] = 1.5f;
    blobs["depth"] = depthImage(64, 32, px);
    EXPECT_NE(decodeError(d, blobs).find("pixel 2,3 holds 1.5"), std::string::npos) << decodeError(d, blobs);
    // A buffer shorter than the image names the binding and the sizes.
    blobs["depth"] = depthImage(64, 32, std::vector<float>(100, 1.0f));
    const std::string shortDepth = decodeError(d, blobs);
    EXPECT_NE(shortDepth.find("depth at set 0 binding 1 (res1)"), std::string::npos) << shortDepth;
    EXPECT_NE(shortDepth.find("needs 8192 bytes, but the binding holds 400"), std::string::npos) << shortDepth;
    // An unknown format is named.
    CaptureBlob bgra = depthImage(64, 32, std::vector<float>(64 * 32, 1.0f), "B8G8R8A8_UNORM");
    bgra.binding.componentBytes = 1;
    bgra.binding.componentType = "UNorm";
    blobs["depth"] = bgra;
    EXPECT_NE(decodeError(d, blobs).find("format B8G8R8A8_UNORM"), std::string::npos) << decodeError(d, blobs);
}

TEST(CaptureFrame, LightsBufferTooSmallOrBadLightNamesTheLight) {
    CaptureDescription d = parseCaptureDescription(kDescription, "desc.json");
    const Camera cam = lensCamera(ProjectionKind::Perspective, 0.1, 100.0);
    auto blobs = frameBlobs(cam);
    d.lightCount = 3;
    const std::string tooFew = decodeError(d, blobs);
    EXPECT_NE(tooFew.find("lights at set 0 binding 3 (res3): 3 lights of 32 bytes"), std::string::npos) << tooFew;
    EXPECT_NE(tooFew.find("needs 96 bytes, but the binding holds 64"), std::string::npos) << tooFew;
    d.lightCount.reset();
    put(blobs["lights"].bytes, 32 + 12, -1.0f);
    EXPECT_NE(decodeError(d, blobs).find("light 1: radius -1 is not a positive number"), std::string::npos)
        << decodeError(d, blobs);
}

// The same lists in each layout engines use decode to the same CullResult.
TEST(CaptureFrame, EveryListLayoutDecodesToTheSameLists) {
    const Camera cam = lensCamera(ProjectionKind::Perspective, 0.1, 100.0);
    const std::vector<std::vector<std::uint32_t>> lists{{1}, {0, 1}, {}, {0}, {}, {1}, {0, 1}, {}};
    std::vector<CullResult> results;
    for (const char* layout : {"fixed", "counts+indices", "ranges", "pairs", "ranges-with-counts"}) {
        SCOPED_TRACE(layout);
        CaptureDescription d = parseCaptureDescription(kDescription, "desc.json");
        auto blobs = frameBlobs(cam);
        std::string counts, indices, offsets, ranges, fixed;
        std::uint32_t at = 0;
        for (std::size_t l = 0; l < lists.size(); ++l) {
            put(fixed, 4 * (9 * l), std::uint32_t(lists[l].size()));
            put(counts, 4 * l, std::uint32_t(lists[l].size()));
            put(offsets, 4 * l, at);
            put(ranges, 8 * l, at), put(ranges, 8 * l + 4, std::uint32_t(lists[l].size()));
            for (std::size_t k = 0; k < lists[l].size(); ++k) {
                put(fixed, 4 * (9 * l + 1 + k), lists[l][k]);
                put(indices, 4 * std::size_t(at++), lists[l][k]);
            }
        }
        put(offsets, 4 * lists.size(), at);
        fixed.resize(4 * 9 * lists.size(), '\0');
        const std::string name = layout;
        if (name == "fixed") {
            blobs["lists"] = blob("buffer", fixed, 4);
        } else if (name == "counts+indices") {
            d.listKind = CaptureDescription::Lists::CountsIndices;
            d.layout = LayoutSpec{ListLayout::Fixed, 2};
            std::string strided;
            for (std::size_t l = 0; l < lists.size(); ++l)
                for (std::size_t k = 0; k < lists[l].size(); ++k) put(strided, 4 * (2 * l + k), lists[l][k]);
            strided.resize(4 * 2 * lists.size(), '\0');
            blobs["counts"] = blob("buffer", counts, 5);
            blobs["indices"] = blob("buffer", strided, 6);
        } else if (name == "pairs") {
            d.listKind = CaptureDescription::Lists::Pairs;
            blobs["ranges"] = blob("buffer", ranges, 5);
            blobs["indices"] = blob("buffer", indices, 6);
        } else {
            d.listKind = CaptureDescription::Lists::Ranges;
            blobs["offsets"] = blob("buffer", offsets, 5);
            if (name == "ranges-with-counts") {
                d.counts = "0.7";
                blobs["counts"] = blob("buffer", counts, 7);
            }
            blobs["indices"] = blob("buffer", indices, 6);
        }
        const CaptureFrame f = decodeCaptureFrame(d, blobs, "frame.rdc", 7);
        CustomCullReport report;
        RunOptions o;
        o.truthOptions.imageError = false;
        const RunOutput run = checkCaptureFrame(f, o, report);
        ASSERT_EQ(run.result.listCount.size(), lists.size());
        for (std::size_t l = 0; l < lists.size(); ++l) {
            const std::vector<std::uint32_t> got(run.result.lightIndices.begin() + run.result.listOffset[l],
                                                 run.result.lightIndices.begin() + run.result.listOffset[l] +
                                                     run.result.listCount[l]);
            EXPECT_EQ(got, lists[l]) << "list " << l;
        }
        EXPECT_EQ(run.depthFrom, "capture frame.rdc event 7");
    }
}

TEST(CaptureFrame, ListBuffersShorterThanTheGridNeedsAreRefused) {
    CaptureDescription d = parseCaptureDescription(kDescription, "desc.json");
    const Camera cam = lensCamera(ProjectionKind::Perspective, 0.1, 100.0);
    auto blobs = frameBlobs(cam);
    d.listKind = CaptureDescription::Lists::Ranges;
    blobs["offsets"] = blob("buffer", std::string(4 * 4, '\0'), 5);
    blobs["indices"] = blob("buffer", "", 6);
    const std::string e = decodeError(d, blobs);
    EXPECT_NE(e.find("list offsets at set 0 binding 5 (res5)"), std::string::npos) << e;
    EXPECT_NE(e.find("9 offsets"), std::string::npos) << e;
    // A fixed layout with the wrong N: decoded as told, with a warning that
    // names the N the buffer's size suggests.
    d = parseCaptureDescription(kDescription, "desc.json");
    blobs = frameBlobs(cam);
    blobs["lists"].bytes.resize(4 * 17 * 8, '\0');
    const CaptureFrame f = decodeCaptureFrame(d, blobs, "frame.rdc", 7);
    ASSERT_EQ(f.warnings.size(), 1u);
    EXPECT_NE(f.warnings[0].find("fixed:16 rather than fixed:8"), std::string::npos) << f.warnings[0];

    // counts+indices: an indices buffer for another N, a counts buffer for
    // another grid (tile size), each named in a warning.
    d = parseCaptureDescription(kDescription, "desc.json");
    d.listKind = CaptureDescription::Lists::CountsIndices;
    d.layout = LayoutSpec{ListLayout::Fixed, 8};
    blobs = frameBlobs(cam);
    blobs["counts"] = blob("buffer", std::string(4 * 8, '\0'), 5);
    blobs["indices"] = blob("buffer", std::string(4 * 8 * 16, '\0'), 6);
    const CaptureFrame n = decodeCaptureFrame(d, blobs, "frame.rdc", 7);
    ASSERT_EQ(n.warnings.size(), 1u);
    EXPECT_NE(n.warnings[0].find("counts+indices:16 rather than counts+indices:8"), std::string::npos) << n.warnings[0];
    blobs["counts"] = blob("buffer", std::string(4 * 32, '\0'), 5); // a grid of 8-pixel tiles
    const CaptureFrame t = decodeCaptureFrame(d, blobs, "frame.rdc", 7);
    ASSERT_EQ(t.warnings.size(), 1u);
    EXPECT_NE(t.warnings[0].find("32 counts, the grid 8 lists (tile 16"), std::string::npos) << t.warnings[0];

    // Every light the same radius: the offset of a constant (a colour's alpha).
    blobs = frameBlobs(cam);
    std::string& lights = blobs["lights"].bytes;
    put(lights, 12, 1.0f), put(lights, 32 + 12, 1.0f);
    const CaptureFrame r = decodeCaptureFrame(parseCaptureDescription(kDescription, "desc.json"), blobs, "frame.rdc", 7);
    ASSERT_EQ(r.warnings.size(), 1u);
    EXPECT_NE(r.warnings[0].find("all 2 lights read radius 1"), std::string::npos) << r.warnings[0];
}

// Z-binning as an engine stores it (lists.layout "zbin"): a light mask per
// tile by sorted position, a 16-bit lo/hi pair per depth bin, and the sorted
// order. The built-in zbin's own result, written in that form, reads back as
// the same masks and bins and is judged by the same rule: no misses. Bins cut
// short (their last light dropped) miss exactly the lights ground truth says.
TEST(CaptureZBin, TheBuiltinZBinWrittenAsAnEngineDoesIsJudgedTheSame) {
    Scene scene = makeBuiltinScene("atrium");
    std::erase_if(scene.lights, [](const PointLight& l) { return l.isSpot(); });
    scene.camera.width = 160;
    scene.camera.height = 96;
    CullSettings settings;
    settings.algorithm = Algorithm::ZBin;
    settings.bins = 64;
    const auto cpu = makeBackend("cpu");
    RunOptions opts;
    opts.truthOptions.imageError = false;
    const RunOutput run = runPipeline(scene, settings, *cpu, opts);
    const CullResult& z = run.result;
    ASSERT_EQ(z.algorithm, Algorithm::ZBin);
    ASSERT_EQ(run.truth.metrics.falseNegatives, 0u);
    const auto lights = std::uint32_t(run.lights.size());
    ASSERT_GT(lights, 32u); // masks of more than one word

    std::map<std::string, CaptureBlob> blobs;
    std::string camera;
    putMatrix(camera, 0, Projection(scene.camera).clipFromView());
    blobs["camera"] = blob("buffer", camera, 0);
    std::string lightBytes;
    for (std::uint32_t l = 0; l < lights; ++l) {
        const glm::dvec3 c = run.lights.centers[l];
        put(lightBytes, 16 * l, float(c.x)), put(lightBytes, 16 * l + 4, float(c.y));
        put(lightBytes, 16 * l + 8, float(c.z)), put(lightBytes, 16 * l + 12, float(run.lights.radii[l]));
    }
    blobs["lights"] = blob("buffer", lightBytes, 3);
    blobs["depth"] = depthImage(run.depth.width, run.depth.height, run.depth.depth);
    const std::uint32_t perTile = (lights + 31) / 32;
    std::string masks(4 * std::size_t(z.grid.tileCount()) * perTile, '\0');
    for (std::uint32_t t = 0; t < z.grid.tileCount(); ++t) {
        for (std::uint32_t w = 0; w < perTile; ++w) {
            std::uint32_t bits = 0;
            for (std::uint32_t i = 0; i < z.listCount[t]; ++i) {
                const std::uint32_t k = z.zbinRank[z.lightIndices[z.listOffset[t] + i]];
                if (k / 32 == w) bits |= 1u << (k % 32);
            }
            put(masks, 4 * (std::size_t(t) * perTile + w), bits);
        }
    }
    blobs["masks"] = blob("buffer", masks, 4);
    auto binsOf = [&](bool cut) {
        std::string bins;
        for (std::size_t b = 0; b < z.zbinLo.size(); ++b) {
            std::uint32_t lo = z.zbinLo[b], hi = z.zbinHi[b];
            if (lo > hi) lo = 0xffff, hi = 0; // empty
            else if (cut && hi > lo) --hi;
            put(bins, 4 * b, lo | hi << 16);
        }
        return bins;
    };
    blobs["bins"] = blob("buffer", binsOf(false), 5);
    std::string order;
    for (std::uint32_t k = 0; k < lights; ++k) put(order, 4 * k, z.zbinOrder[k]);
    blobs["order"] = blob("buffer", order, 6);

    char text[600];
    std::snprintf(text, sizeof text, R"({"lights": {"binding": "0.3", "stride": 16, "position": 0, "radius": 12},
      "camera": {"binding": "0.0", "projection": 0}, "depth": {"binding": "0.1"},
      "lists": {"layout": "zbin", "masks": "0.4", "bins": "0.5", "order": "0.6", "bin_format": "u16pair",
                "bin_near": %.17g, "bin_far": %.17g}})",
                  z.zbinNear, z.zbinFar);
    const CaptureDescription d = parseCaptureDescription(text, "zbin.json");
    EXPECT_EQ(captureBindingsNeeded(d).count("order"), 1u);
    const CaptureFrame f = decodeCaptureFrame(d, blobs, "frame.rdc", 9);
    ASSERT_TRUE(f.zbin);
    EXPECT_EQ(f.layoutName, "zbin");
    EXPECT_EQ(f.zbin->order, z.zbinOrder);
    EXPECT_EQ(f.zbin->lo.size(), 64u);
    bool echoed = false;
    for (const std::string& e : f.echo) echoed = echoed || e.rfind("lists: zbin, 60 tile masks of ", 0) == 0;
    EXPECT_TRUE(echoed);

    CustomCullReport report;
    const RunOutput judged = checkCaptureFrame(f, opts, report);
    EXPECT_EQ(judged.result.algorithm, Algorithm::ZBin);
    EXPECT_EQ(judged.result.listCount, z.listCount); // the tile masks' lights
    EXPECT_EQ(judged.result.lightIndices, z.lightIndices);
    ASSERT_EQ(judged.result.zbinLo.size(), z.zbinLo.size());
    for (std::size_t b = 0; b < z.zbinLo.size(); ++b) {
        const bool empty = z.zbinLo[b] > z.zbinHi[b];
        EXPECT_EQ(judged.result.zbinLo[b] > judged.result.zbinHi[b], empty) << "bin " << b;
        if (!empty) {
            EXPECT_EQ(judged.result.zbinLo[b], z.zbinLo[b]);
            EXPECT_EQ(judged.result.zbinHi[b], z.zbinHi[b]);
        }
    }
    EXPECT_EQ(judged.truth.metrics.falseNegatives, 0u);
    EXPECT_EQ(report.layout, "zbin");

    // Each non-empty bin loses its farthest sorted light: misses, located in
    // per-(tile, bin) lists that lack the light.
    blobs["bins"] = blob("buffer", binsOf(true), 5);
    const CaptureFrame cut = decodeCaptureFrame(d, blobs, "frame.rdc", 9);
    CustomCullReport cutReport;
    const RunOutput missed = checkCaptureFrame(cut, opts, cutReport);
    EXPECT_GT(missed.truth.metrics.falseNegatives, 0u);

    // Bad bins and orders: one line naming the binding.
    std::string badBins = binsOf(false);
    put(badBins, 0, 0u | (lights + 5) << 16);
    blobs["bins"] = blob("buffer", badBins, 5);
    EXPECT_NE(decodeError(d, blobs).find("bin 0 reaches sorted position " + std::to_string(lights + 5)),
              std::string::npos)
        << decodeError(d, blobs);
    blobs["bins"] = blob("buffer", binsOf(false), 5);
    std::string twice = order;
    put(twice, 4, z.zbinOrder[0]);
    blobs["order"] = blob("buffer", twice, 6);
    EXPECT_NE(decodeError(d, blobs).find("names light " + std::to_string(z.zbinOrder[0]) + " twice"),
              std::string::npos)
        << decodeError(d, blobs);
    // A zbin description must say the rule is per tile.
    EXPECT_NE(descriptionError(R"({"lights": {"binding": "0.3", "stride": 16, "position": 0, "radius": 12},
      "camera": {"binding": "0.0", "projection": 0}, "depth": {"binding": "0.1"},
      "lists": {"layout": "zbin", "masks": "0.4", "bins": "0.5", "rule": "halfz"}})")
                  .find("lists.rule"),
              std::string::npos);
}
