// An engine's depth buffer read from a file (lc::loadDepthFile, for `run
// --depth` and `check --depth`): raw float32 and 16-bit greyscale PNG, in
// the camera's depth convention; wrong sizes and values outside [0, 1] are
// one-line errors naming the file.
#include "cli_support.hpp"

#include "culling/custom/custom_cull.hpp"
#include "culling/core/errors.hpp"

#include <gtest/gtest.h>
#include <png.h>

#include <tuple>

#include <fstream>

using namespace lc;

namespace {

Camera camera(std::uint32_t w, std::uint32_t h, ProjectionKind k = ProjectionKind::Perspective) {
    Camera c;
    c.width = w;
    c.height = h;
    c.projection = k;
    return c;
}

void writePng16(const std::filesystem::path& p, std::uint32_t w, std::uint32_t h, const std::vector<std::uint16_t>& grey) {
    png_image img{};
    img.version = PNG_IMAGE_VERSION;
    img.width = w;
    img.height = h;
    img.format = PNG_FORMAT_LINEAR_Y; // 16-bit linear grey
    ASSERT_TRUE(png_image_write_to_file(&img, p.string().c_str(), 0, grey.data(), 0, nullptr)) << img.message;
}

std::string errorOf(const std::string& path, const Projection& proj) {
    try {
        loadDepthFile(path, proj);
    } catch (const InputError& e) {
        return e.what();
    }
    return "(no error)";
}

} // namespace

TEST(DepthFile, RawFloat32RoundTripsBitForBit) {
    lc_test::ScratchDir d;
    const Projection proj(camera(5, 3));
    std::vector<float> v = {0.0f, 0.25f, 0.5f, 0.75f, 1.0f, 0.1f, 0.2f, 0.3f, 0.4f, 0.6f, 0.7f, 0.8f, 0.9f, 0.95f, 1.0f};
    std::ofstream(d.path / "d.f32", std::ios::binary).write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size() * 4));
    const DepthImage img = loadDepthFile((d.path / "d.f32").string(), proj);
    EXPECT_EQ(img.width, 5u);
    EXPECT_EQ(img.height, 3u);
    EXPECT_EQ(img.depth, v);
    EXPECT_EQ(img.clearDepth, 1.0f); // perspective [0,1]: far is the clear value
    EXPECT_EQ(loadDepthFile((d.path / "d.f32").string(), Projection(camera(5, 3, ProjectionKind::ReversedZ))).clearDepth,
              0.0f);
}

TEST(DepthFile, SixteenBitPngMapsToUnitDepth) {
    lc_test::ScratchDir d;
    const Projection proj(camera(4, 2));
    const std::vector<std::uint16_t> grey = {0, 65535, 32768, 1000, 65535, 65535, 1, 50000};
    writePng16(d.path / "d.png", 4, 2, grey);
    const DepthImage img = loadDepthFile((d.path / "d.png").string(), proj);
    ASSERT_EQ(img.depth.size(), grey.size());
    for (std::size_t i = 0; i < grey.size(); ++i) EXPECT_FLOAT_EQ(img.depth[i], float(grey[i]) / 65535.0f) << i;
    EXPECT_TRUE(img.hasGeometry(0, 0));
    EXPECT_FALSE(img.hasGeometry(1, 0)); // 65535 -> 1.0: the clear value
}

TEST(DepthFile, BadFilesAreOneLineErrors) {
    lc_test::ScratchDir d;
    const Projection proj(camera(4, 2));
    std::ofstream(d.path / "short.f32", std::ios::binary) << "abcdefgh";
    EXPECT_NE(errorOf((d.path / "short.f32").string(), proj).find("8 bytes, but raw float32 depth of a 4x2 camera is 32"),
              std::string::npos);
    std::vector<float> bad(8, 0.5f);
    bad[5] = 1.5f;
    std::ofstream(d.path / "range.f32", std::ios::binary).write(reinterpret_cast<const char*>(bad.data()), 32);
    EXPECT_NE(errorOf((d.path / "range.f32").string(), proj).find("pixel 1,1 has window depth 1.5"), std::string::npos)
        << errorOf((d.path / "range.f32").string(), proj);
    writePng16(d.path / "big.png", 8, 2, std::vector<std::uint16_t>(16, 0));
    EXPECT_NE(errorOf((d.path / "big.png").string(), proj).find("8x2 pixels, but the camera is 4x2"), std::string::npos);
    // 8-bit grey (libpng would gamma-decode it) and colour: refused.
    {
        for (const auto& [format, name, expect] :
             {std::tuple<png_uint_32, const char*, const char*>{PNG_FORMAT_GRAY, "grey8.png", "an 8-bit PNG"},
              {PNG_FORMAT_LINEAR_RGB, "rgb16.png", "a colour PNG"}}) {
            png_image img{};
            img.version = PNG_IMAGE_VERSION;
            img.width = 4;
            img.height = 2;
            img.format = format;
            const std::vector<std::uint16_t> px(4 * 2 * 3, 1000);
            ASSERT_TRUE(png_image_write_to_file(&img, (d.path / name).string().c_str(), 0, px.data(), 0, nullptr));
            EXPECT_NE(errorOf((d.path / name).string(), proj).find(expect), std::string::npos) << name;
        }
    }
    std::ofstream(d.path / "not.png") << "not a png";
    EXPECT_NE(errorOf((d.path / "not.png").string(), proj).find("not a readable PNG"), std::string::npos);
}
