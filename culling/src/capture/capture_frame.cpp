#include "culling/capture/capture_frame.hpp"

#include "culling/core/errors.hpp"
#include "culling/core/pipeline.hpp"
#include "culling/math/projection.hpp"
#include "culling/math/tile_math.hpp"

#include <nlohmann/json.hpp>

#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>

using nlohmann::json;

namespace lc {

namespace {

constexpr double kPi = 3.14159265358979323846;

// ---------------------------------------------------------------------------
// The description

class Reader {
public:
    explicit Reader(std::string file) : file_(std::move(file)) {}
    [[noreturn]] void fail(const std::string& path, const std::string& what) const {
        throw InputError(file_, path, 0, what);
    }
    const json* child(const json& parent, const std::string& path, const char* key, bool required) const {
        const auto it = parent.find(key);
        if (it == parent.end() || it->is_null()) {
            if (required) fail(join(path, key), "missing");
            return nullptr;
        }
        return &*it;
    }
    std::string string(const json& parent, const std::string& path, const char* key, bool required,
                       std::string fallback = {}) const {
        const json* j = child(parent, path, key, required);
        if (!j) return fallback;
        if (!j->is_string() || j->get<std::string>().empty()) fail(join(path, key), "must be a non-empty string");
        return j->get<std::string>();
    }
    // A binding: "SET.BINDING" or a name; numbers are refused (ambiguous).
    std::string binding(const json& parent, const std::string& path, const char* key, bool required) const {
        return string(parent, path, key, required);
    }
    std::uint32_t uint(const json& parent, const std::string& path, const char* key, bool required,
                       std::uint32_t fallback, std::uint32_t lo, std::uint32_t hi) const {
        const json* j = child(parent, path, key, required);
        if (!j) return fallback;
        if (!j->is_number_integer() || j->get<std::int64_t>() < lo || j->get<std::int64_t>() > hi)
            fail(join(path, key), "must be an integer in " + std::to_string(lo) + ".." + std::to_string(hi));
        return std::uint32_t(j->get<std::int64_t>());
    }
    std::optional<double> number(const json& parent, const std::string& path, const char* key) const {
        const json* j = child(parent, path, key, false);
        if (!j) return std::nullopt;
        if (j->is_string() && j->get<std::string>() == "infinite") return std::numeric_limits<double>::infinity();
        if (!j->is_number() || !std::isfinite(j->get<double>())) fail(join(path, key), "must be a finite number");
        return j->get<double>();
    }
    bool boolean(const json& parent, const std::string& path, const char* key, bool fallback) const {
        const json* j = child(parent, path, key, false);
        if (!j) return fallback;
        if (!j->is_boolean()) fail(join(path, key), "must be true or false");
        return j->get<bool>();
    }
    std::string choice(const json& parent, const std::string& path, const char* key,
                       const std::vector<std::string>& options, const std::string& fallback) const {
        const std::string v = string(parent, path, key, false, fallback);
        for (const std::string& o : options)
            if (v == o) return v;
        std::string known;
        for (const std::string& o : options) known += (known.empty() ? "" : ", ") + o;
        fail(join(path, key), "'" + v + "' is not one of " + known);
    }
    static std::string join(const std::string& path, const char* key) { return path.empty() ? key : path + "." + key; }
    // A key the reader does not know is a typo, not a comment: an optional
    // field misspelt ("spot_angel") would otherwise be left out silently.
    void known(const json& j, const std::string& path, std::initializer_list<const char*> keys,
               const std::string& who = {}) const {
        for (const auto& [key, value] : j.items()) {
            bool ok = key == "comment";
            for (const char* k : keys) ok = ok || key == k;
            if (ok) continue;
            std::string list;
            for (const char* k : keys) list += (list.empty() ? "" : ", ") + std::string(k);
            fail(join(path, key.c_str()), "unknown field (" + (who.empty() ? path : who) + " takes " + list + ")");
        }
    }

private:
    std::string file_;
};

constexpr std::uint32_t kMaxOffset = 1u << 20; // a struct or block larger than 1 MiB is a mistake
constexpr std::uint32_t kMaxLights = 1000000;  // as the generator's limit
constexpr std::uint32_t kMaxBins = 16384;      // as CullSettings::bins

void parseLights(const Reader& r, const json& j, CaptureDescription& d) {
    const std::string p = "lights";
    if (!j.is_object()) r.fail(p, "must be an object");
    r.known(j, p, {"binding", "stride", "count", "position", "radius", "space", "spot_axis", "spot_angle",
                   "spot_angle_unit"});
    d.lights = r.binding(j, p, "binding", true);
    d.lightStride = r.uint(j, p, "stride", true, 16, 4, kMaxOffset);
    if (const json* c = r.child(j, p, "count", false)) {
        if (c->is_object()) {
            r.known(*c, p + ".count", {"binding", "offset"});
            d.lightCountField = CaptureField{r.binding(*c, p + ".count", "binding", true),
                                             r.uint(*c, p + ".count", "offset", true, 0, 0, kMaxOffset)};
        } else {
            d.lightCount = r.uint(j, p, "count", true, 0, 0, kMaxLights);
        }
    }
    d.positionOffset = r.uint(j, p, "position", true, 0, 0, kMaxOffset);
    d.radiusOffset = r.uint(j, p, "radius", true, 12, 0, kMaxOffset);
    d.lightsInViewSpace = r.choice(j, p, "space", {"view", "world"}, "view") == "view";
    if (r.child(j, p, "spot_axis", false) || r.child(j, p, "spot_angle", false)) {
        d.spotAxisOffset = r.uint(j, p, "spot_axis", true, 0, 0, kMaxOffset);
        d.spotAngleOffset = r.uint(j, p, "spot_angle", true, 0, 0, kMaxOffset);
        const std::string unit = r.choice(j, p, "spot_angle_unit", {"radians", "degrees", "cos"}, "radians");
        d.spotAngleUnit = unit == "radians"   ? CaptureDescription::AngleUnit::Radians
                          : unit == "degrees" ? CaptureDescription::AngleUnit::Degrees
                                              : CaptureDescription::AngleUnit::Cosine;
    }
    // The fields must lie inside the struct and not overlap.
    struct Span {
        const char* name;
        std::uint32_t offset, size;
    };
    std::vector<Span> spans{{"position", d.positionOffset, 12}, {"radius", d.radiusOffset, 4}};
    if (d.spotAxisOffset) spans.push_back({"spot_axis", *d.spotAxisOffset, 12});
    if (d.spotAngleOffset) spans.push_back({"spot_angle", *d.spotAngleOffset, 4});
    for (const Span& s : spans) {
        if (s.offset % 4) r.fail(p + "." + s.name, "offset " + std::to_string(s.offset) + " is not a multiple of 4");
        if (std::uint64_t(s.offset) + s.size > d.lightStride)
            r.fail(p + "." + s.name, "bytes " + std::to_string(s.offset) + ".." + std::to_string(s.offset + s.size - 1) +
                                         " lie outside the " + std::to_string(d.lightStride) + "-byte stride");
    }
    for (std::size_t a = 0; a < spans.size(); ++a)
        for (std::size_t b = a + 1; b < spans.size(); ++b)
            if (spans[a].offset < spans[b].offset + spans[b].size && spans[b].offset < spans[a].offset + spans[a].size)
                r.fail(p + "." + spans[b].name, std::string("overlaps ") + spans[a].name + " (bytes " +
                                                    std::to_string(spans[a].offset) + ".." +
                                                    std::to_string(spans[a].offset + spans[a].size - 1) + ")");
}

void parseCamera(const Reader& r, const json& j, CaptureDescription& d) {
    const std::string p = "camera";
    if (!j.is_object()) r.fail(p, "must be an object");
    r.known(j, p, {"binding", "projection", "view", "order", "fov_y_deg", "near", "far", "reversed"});
    if (r.child(j, p, "projection", false)) {
        for (const char* lens : {"fov_y_deg", "near", "far", "reversed"})
            if (r.child(j, p, lens, false))
                r.fail(Reader::join(p, lens), "not read: the projection matrix gives the lens and depth convention");
        const std::string b = r.binding(j, p, "binding", true);
        d.projection = CaptureField{b, r.uint(j, p, "projection", true, 0, 0, kMaxOffset)};
        if (r.child(j, p, "view", false)) d.view = CaptureField{b, r.uint(j, p, "view", true, 0, 0, kMaxOffset)};
        d.rowMajor = r.choice(j, p, "order", {"column-major", "row-major"}, "column-major") == "row-major";
        for (const auto* f : {&d.projection, &d.view})
            if (*f && (*f)->offset % 4) r.fail(p, "matrix offsets must be multiples of 4");
        if (d.projection && d.view && d.projection->offset < d.view->offset + 64 &&
            d.view->offset < d.projection->offset + 64)
            r.fail(p + ".view", "overlaps the projection matrix");
        return;
    }
    d.fovYDeg = r.number(j, p, "fov_y_deg");
    d.nearPlane = r.number(j, p, "near");
    d.farPlane = r.number(j, p, "far");
    d.reversed = r.boolean(j, p, "reversed", false);
    if (!d.fovYDeg) r.fail(p, "give a projection matrix (binding and projection offset) or fov_y_deg, near and far");
    if (!(*d.fovYDeg > 0 && *d.fovYDeg < 180)) r.fail(p + ".fov_y_deg", "must be in (0, 180)");
    if (!d.nearPlane || !(*d.nearPlane > 0) || std::isinf(*d.nearPlane)) r.fail(p + ".near", "must be a number > 0");
    if (!d.farPlane || !(*d.farPlane > *d.nearPlane)) r.fail(p + ".far", "must be greater than near (or \"infinite\")");
    if (std::isinf(*d.farPlane) && !d.reversed) r.fail(p + ".far", "an infinite far plane needs reversed: true");
}

void parseDepth(const Reader& r, const json& j, CaptureDescription& d) {
    const std::string p = "depth";
    if (!j.is_object()) r.fail(p, "must be an object");
    r.known(j, p, {"binding", "rows", "width", "height"});
    d.depth = r.binding(j, p, "binding", true);
    d.bottomUp = r.choice(j, p, "rows", {"top-down", "bottom-up"}, "top-down") == "bottom-up";
    d.depthWidth = r.uint(j, p, "width", false, 0, 1, 16384);
    d.depthHeight = r.uint(j, p, "height", false, 0, 1, 16384);
    if ((d.depthWidth == 0) != (d.depthHeight == 0)) r.fail(p, "give both width and height (a depth buffer's size)");
}

void parseLists(const Reader& r, const json& j, CaptureDescription& d) {
    const std::string p = "lists";
    if (!j.is_object()) r.fail(p, "must be an object");

    const std::string layout = r.string(j, p, "layout", true);
    try {
        d.rule = parseListSpec(r.string(j, p, "rule", false, "tile"));
    } catch (const SettingsError& e) {
        r.fail(p + ".rule", e.what());
    }
    d.tileSize = r.uint(j, p, "tile", false, 16, 1, 1024);
    const std::string head = layout.substr(0, layout.find(':'));
    if (head == "counts+indices") {
        d.listKind = CaptureDescription::Lists::CountsIndices;
        const std::string n = layout.size() > head.size() ? layout.substr(head.size() + 1) : "";
        if (n.empty() || n.find_first_not_of("0123456789") != std::string::npos || n.size() > 6 || std::stoul(n) == 0)
            r.fail(p + ".layout", "counts+indices needs the indices per list: counts+indices:N");
        d.layout = LayoutSpec{ListLayout::Fixed, std::uint32_t(std::stoul(n))};
        r.known(j, p, {"layout", "rule", "tile", "counts", "indices"}, "lists with layout " + layout);
        d.counts = r.binding(j, p, "counts", true);
        d.indices = r.binding(j, p, "indices", true);
    } else if (layout == "ranges") {
        r.known(j, p, {"layout", "rule", "tile", "offsets", "counts", "indices"}, "lists with layout " + layout);
        d.listKind = CaptureDescription::Lists::Ranges;
        d.offsets = r.binding(j, p, "offsets", true);
        d.counts = r.binding(j, p, "counts", false);
        d.indices = r.binding(j, p, "indices", true);
    } else if (layout == "zbin") {
        d.listKind = CaptureDescription::Lists::ZBin;
        if (d.rule.kind != ListKind::Tile) r.fail(p + ".rule", "zbin's masks are per tile: the rule is tile");
        d.layout = LayoutSpec{ListLayout::Bitmask, 0};
        r.known(j, p, {"layout", "rule", "tile", "masks", "bins", "order", "bin_format", "bin_count", "bin_near",
                       "bin_far"}, "lists with layout " + layout);
        d.masks = r.binding(j, p, "masks", true);
        d.bins = r.binding(j, p, "bins", true);
        d.order = r.binding(j, p, "order", false);
        d.binsU16 = r.choice(j, p, "bin_format", {"u32pair", "u16pair"}, "u32pair") == "u16pair";
        if (r.child(j, p, "bin_count", false)) d.binCount = r.uint(j, p, "bin_count", true, 0, 1, kMaxBins);
        d.binNear = r.number(j, p, "bin_near");
        d.binFar = r.number(j, p, "bin_far");
        if (d.binFar && !std::isfinite(*d.binFar)) r.fail(p + ".bin_far", "must be a finite number");
        if (d.binNear && d.binFar && !(*d.binFar > *d.binNear))
            r.fail(p + ".bin_far", "must be greater than bin_near");
    } else if (layout == "pairs") {
        d.listKind = CaptureDescription::Lists::Pairs;
        r.known(j, p, {"layout", "rule", "tile", "ranges", "indices"}, "lists with layout " + layout);
        d.ranges = r.binding(j, p, "ranges", true);
        d.indices = r.binding(j, p, "indices", true);
    } else {
        d.listKind = CaptureDescription::Lists::Contract;
        try {
            d.layout = parseLayout(layout);
        } catch (const SettingsError& e) {
            r.fail(p + ".layout", std::string(e.what()) + "; or counts+indices:N, ranges, pairs, zbin");
        }
        r.known(j, p, {"layout", "rule", "tile", "binding"}, "lists with layout " + layout);
        d.listBuffer = r.binding(j, p, "binding", true);
    }
}

// ---------------------------------------------------------------------------
// Decoding

struct Bytes {
    const CaptureBlob* blob;
    std::string capture;
    std::string what; // "lights"

    std::uint64_t size() const { return blob->bytes.size(); }
    [[noreturn]] void fail(const std::string& msg) const {
        throw InputError(capture, "", 0, what + " at " + blob->binding.where() + ": " + msg);
    }
    void need(std::uint64_t offset, std::uint64_t n, const std::string& field) const {
        if (offset + n > size())
            fail(field + " at byte " + std::to_string(offset) + " needs " + std::to_string(offset + n) +
                 " bytes, but the binding holds " + std::to_string(size()));
    }
    float f32(std::uint64_t offset) const {
        float v;
        std::memcpy(&v, blob->bytes.data() + offset, 4);
        return v;
    }
    std::uint32_t u32(std::uint64_t offset) const {
        std::uint32_t v;
        std::memcpy(&v, blob->bytes.data() + offset, 4);
        return v;
    }
    std::vector<std::uint32_t> words() const {
        std::vector<std::uint32_t> w(size() / 4);
        if (!w.empty()) std::memcpy(w.data(), blob->bytes.data(), w.size() * 4);
        return w;
    }
};

std::string fmt(double v) {
    std::ostringstream s;
    s.precision(6);
    s << v;
    return s.str();
}
std::string fmt(const glm::dvec3& v) { return "(" + fmt(v.x) + ", " + fmt(v.y) + ", " + fmt(v.z) + ")"; }

glm::dmat4 readMatrix(const Bytes& b, std::uint32_t offset, bool rowMajor, const std::string& field) {
    b.need(offset, 64, field);
    glm::dmat4 m(1.0);
    for (int i = 0; i < 16; ++i) {
        const double v = b.f32(offset + 4u * std::uint32_t(i));
        if (!std::isfinite(v)) b.fail(field + " element " + std::to_string(i) + " is not finite");
        // Column-major: word i is column i / 4, row i % 4.
        if (rowMajor)
            m[i % 4][i / 4] = v;
        else
            m[i / 4][i % 4] = v;
    }
    return m;
}

// The camera from a Vulkan projection matrix (view -> clip, depth 0..1, y up
// or down): perspective or orthographic, standard or reversed depth.
Camera cameraFromProjection(const glm::dmat4& P, const Bytes& b, std::vector<std::string>& echo,
                            std::vector<std::string>& warnings) {
    Camera c;
    const double p00 = P[0][0], p11 = P[1][1], p22 = P[2][2], p32 = P[3][2], p23 = P[2][3], p33 = P[3][3];
    const bool perspective = std::abs(p23 + 1.0) < 1e-6 && std::abs(p33) < 1e-6;
    const bool ortho = std::abs(p23) < 1e-6 && std::abs(p33 - 1.0) < 1e-6;
    if (!perspective && !ortho)
        b.fail("the projection's last row is (" + fmt(P[0][3]) + ", " + fmt(P[1][3]) + ", " + fmt(p23) + ", " +
               fmt(p33) + "): neither perspective (0, 0, -1, 0) nor orthographic (0, 0, 0, 1); check the offset "
               "and the order (column-major or row-major)");
    if (p00 == 0 || p11 == 0) b.fail("the projection scales x or y by 0");
    if (std::abs(P[2][0]) > 1e-6 || std::abs(P[2][1]) > 1e-6)
        warnings.push_back("the projection is off-centre (x " + fmt(P[2][0]) + ", y " + fmt(P[2][1]) +
                           ": a jittered or asymmetric frustum); it is judged as the centred one");
    if (perspective) {
        // Window depth d = A + B / t at view depth t = -z (t > 0 in front).
        const double A = -p22, B = p32;
        c.fovYDeg = 2.0 * std::atan(1.0 / std::abs(p11)) * 180.0 / kPi;
        if (B > 0) { // reversed: near -> 1, far -> 0
            c.projection = ProjectionKind::ReversedZ;
            c.nearPlane = B / (1.0 - A);
            c.farPlane = std::abs(A) < 1e-12 ? std::numeric_limits<double>::infinity() : -B / A;
        } else if (B < 0) {
            c.projection = ProjectionKind::Perspective;
            c.nearPlane = -B / A;
            if (std::abs(1.0 - A) < 1e-12) b.fail("an infinite far plane with standard depth (only reversed-Z may be infinite)");
            c.farPlane = B / (1.0 - A);
        } else {
            b.fail("the projection maps every depth to " + fmt(A) + " (element [3][2] is 0)");
        }
    } else {
        // d = A + B t
        const double A = p32, B = -p22;
        if (B <= 0)
            b.fail("a reversed orthographic projection (only perspective may be reversed here): is "
                   "camera.projection the projection matrix's offset, and camera.order right?");
        c.projection = ProjectionKind::Orthographic;
        c.orthoHeight = 2.0 / std::abs(p11);
        c.nearPlane = -A / B;
        c.farPlane = (1.0 - A) / B;
        if (c.nearPlane <= 0) b.fail("the orthographic near plane is at " + fmt(c.nearPlane) + " (must be > 0)");
    }
    echo.push_back("camera: " + std::string(toString(c.projection)) +
                   (perspective ? ", fov y " + fmt(c.fovYDeg) + " deg" : ", height " + fmt(c.orthoHeight)) +
                   ", near " + fmt(c.nearPlane) + ", far " + fmt(c.farPlane) + ", aspect " +
                   fmt(std::abs(p11 / p00)) + " (from " + b.blob->binding.where() + ")");
    return c;
}

const CaptureBlob& blobOf(const std::map<std::string, CaptureBlob>& blobs, const std::string& key) {
    const auto it = blobs.find(key);
    if (it == blobs.end()) throw Error("internal: capture binding '" + key + "' was not read");
    return it->second;
}

DepthImage decodeDepth(const CaptureDescription& d, const Bytes& b, std::vector<std::string>& echo) {
    const CaptureBinding& bind = b.blob->binding;
    DepthImage img;
    std::size_t bytesPerPixel = 4;
    enum { F32, UNorm16, UNorm24 } kind = F32;
    if (bind.kind == "image") {
        if (bind.samples > 1) b.fail("a multisampled image (" + std::to_string(bind.samples) + " samples); give the resolved depth");
        img.width = bind.width;
        img.height = bind.height;
        const std::string& f = bind.format;
        if (f == "D16" || f == "D16S8" || (bind.componentBytes == 2 && bind.componentType == "UNorm")) {
            kind = UNorm16;
            bytesPerPixel = f == "D16S8" ? 4 : 2;
        } else if (f == "D24S8" || f == "D24") {
            kind = UNorm24;
            bytesPerPixel = 4;
        } else if (f == "D32" || f == "R32_FLOAT" || (bind.componentBytes == 4 && bind.componentType == "Float")) {
            bytesPerPixel = 4 * std::max<std::uint32_t>(bind.components, 1);
        } else if (f == "D32S8") {
            bytesPerPixel = 8;
        } else {
            b.fail("format " + f + " is not a depth lightcull reads (D16, D24S8, D32, D32S8, R32_FLOAT, R16_UNORM)");
        }
        if (d.depthWidth && (d.depthWidth != img.width || d.depthHeight != img.height))
            b.fail("the image is " + std::to_string(img.width) + "x" + std::to_string(img.height) +
                   ", the description says " + std::to_string(d.depthWidth) + "x" + std::to_string(d.depthHeight));
    } else if (bind.kind == "buffer") {
        if (!d.depthWidth) b.fail("a buffer: give depth.width and depth.height");
        img.width = d.depthWidth;
        img.height = d.depthHeight;
    } else {
        b.fail("neither an image nor a buffer");
    }
    const std::size_t n = std::size_t(img.width) * img.height;
    if (n == 0) b.fail("an empty image");
    b.need(0, n * bytesPerPixel, "depth of " + std::to_string(img.width) + "x" + std::to_string(img.height) + " pixels");
    img.depth.resize(n);
    for (std::uint32_t y = 0; y < img.height; ++y) {
        const std::uint32_t srcY = d.bottomUp ? img.height - 1 - y : y;
        for (std::uint32_t x = 0; x < img.width; ++x) {
            const std::size_t at = (std::size_t(srcY) * img.width + x) * bytesPerPixel;
            float v;
            if (kind == UNorm16) {
                std::uint16_t u;
                std::memcpy(&u, b.blob->bytes.data() + at, 2);
                v = float(u) / 65535.0f;
            } else if (kind == UNorm24) {
                v = float(b.u32(at) & 0xFFFFFFu) / 16777215.0f;
            } else {
                v = b.f32(at);
            }
            if (!std::isfinite(v) || v < 0.0f || v > 1.0f)
                b.fail("pixel " + std::to_string(x) + "," + std::to_string(y) + " holds " + fmt(v) +
                       ", not a window depth in 0..1");
            img.depth[std::size_t(y) * img.width + x] = v;
        }
    }
    echo.push_back("depth: " + std::to_string(img.width) + "x" + std::to_string(img.height) + " " +
                   (bind.kind == "image" ? bind.format : std::string("float32 buffer")) + ", rows " +
                   (d.bottomUp ? "bottom-up" : "top-down") + " (" + bind.where() + ")");
    return img;
}

std::vector<Light> decodeLights(const CaptureDescription& d, const std::map<std::string, CaptureBlob>& blobs,
                                const std::string& capture, const glm::dmat4& viewFromWorld,
                                std::vector<std::string>& echo) {
    const Bytes b{&blobOf(blobs, "lights"), capture, "lights"};
    std::uint64_t count = 0;
    std::string countFrom;
    if (d.lightCount) {
        count = *d.lightCount;
        countFrom = "given";
    } else if (d.lightCountField) {
        const Bytes c{&blobOf(blobs, "light_count"), capture, "light count"};
        c.need(d.lightCountField->offset, 4, "the count");
        count = c.u32(d.lightCountField->offset);
        countFrom = "read at byte " + std::to_string(d.lightCountField->offset) + " of " + c.blob->binding.where();
        if (count > kMaxLights) c.fail(std::to_string(count) + " lights, more than lightcull reads (" +
                                       std::to_string(kMaxLights) + ")");
    } else {
        count = b.size() / d.lightStride;
        countFrom = "the binding's " + std::to_string(b.size()) + " bytes / stride " + std::to_string(d.lightStride);
        if (count > kMaxLights) count = kMaxLights;
    }
    b.need(0, count * d.lightStride, std::to_string(count) + " lights of " + std::to_string(d.lightStride) + " bytes");
    const glm::dmat3 rot(viewFromWorld);
    std::vector<Light> lights(count);
    // The first lights' position and spot axis as the buffer holds them (a
    // user compares these with their engine's values).
    std::vector<std::pair<glm::dvec3, glm::dvec3>> asRead;
    for (std::uint64_t i = 0; i < count; ++i) {
        const std::uint64_t base = i * d.lightStride;
        Light& L = lights[i];
        L.name = "light_" + std::to_string(i); // as generated lights are named
        glm::dvec3 pos(b.f32(base + d.positionOffset), b.f32(base + d.positionOffset + 4),
                       b.f32(base + d.positionOffset + 8));
        const double radius = b.f32(base + d.radiusOffset);
        if (!std::isfinite(pos.x) || !std::isfinite(pos.y) || !std::isfinite(pos.z))
            b.fail("light " + std::to_string(i) + ": position " + fmt(pos) + " is not finite");
        if (!(radius > 0) || !std::isfinite(radius))
            b.fail("light " + std::to_string(i) + ": radius " + fmt(radius) + " is not a positive number");
        if (i < 3) asRead.emplace_back(pos, glm::dvec3(0.0));
        if (!d.lightsInViewSpace) pos = glm::dvec3(viewFromWorld * glm::dvec4(pos, 1.0));
        L.position = pos;
        L.explicitRadius = radius;
        if (d.spotAxisOffset) {
            const std::uint64_t a = base + *d.spotAxisOffset;
            glm::dvec3 axis(b.f32(a), b.f32(a + 4), b.f32(a + 8));
            if (i < 3) asRead.back().second = axis;
            double angle = b.f32(base + *d.spotAngleOffset);
            if (d.spotAngleUnit == CaptureDescription::AngleUnit::Radians) angle *= 180.0 / kPi;
            if (d.spotAngleUnit == CaptureDescription::AngleUnit::Cosine)
                angle = std::acos(std::clamp(angle, -1.0, 1.0)) * 180.0 / kPi;
            // A spot field of a point light: angle 0 (the contract's) or a
            // cone of 180 degrees or more lights the whole sphere.
            if (angle > 0 && angle < 90.0 + 1e-9 && glm::length(axis) > 0) {
                if (!d.lightsInViewSpace) axis = rot * axis;
                L.kind = LightKind::Spot;
                L.direction = axis;
                L.outerAngleDeg = std::min(angle, 90.0);
            }
        }
        if (const std::string bad = L.validate(); !bad.empty()) b.fail("light " + std::to_string(i) + ": " + bad);
    }
    std::string line = "lights: " + std::to_string(count) + " (" + countFrom + "), stride " +
                       std::to_string(d.lightStride) + ", " + (d.lightsInViewSpace ? "view" : "world") + " space (" +
                       b.blob->binding.where() + ")";
    // As read; world-space lights also as the view matrix places them.
    for (std::size_t i = 0; i < lights.size() && i < 3; ++i)
        line += "; light " + std::to_string(i) + ": position " + fmt(asRead[i].first) +
                (d.lightsInViewSpace ? "" : " (view " + fmt(lights[i].position) + ")") + " radius " +
                fmt(lights[i].explicitRadius) +
                (lights[i].isSpot() ? " spot axis " + fmt(asRead[i].second) + " outer " +
                                          fmt(lights[i].outerAngleDeg) + " deg"
                                    : "");
    echo.push_back(line);
    return lights;
}

// The lists as words of a layout decodeLists reads.
std::vector<std::uint32_t> decodeListWords(const CaptureDescription& d, const std::map<std::string, CaptureBlob>& blobs,
                                           const std::string& capture, std::uint64_t listCount, LayoutSpec& layout,
                                           std::vector<std::string>& echo, std::vector<std::string>& warnings) {
    using K = CaptureDescription::Lists;
    layout = d.layout;
    if (d.listKind == K::Contract) {
        const Bytes b{&blobOf(blobs, "lists"), capture, "lists"};
        // A fixed layout whose buffer holds a whole number of larger lists:
        // most likely the description's N is not the renderer's.
        const std::uint64_t words = b.size() / 4;
        if (d.layout.kind == ListLayout::Fixed && listCount && words % listCount == 0 &&
            words / listCount != std::uint64_t(d.layout.capacity) + 1 && words / listCount > 1)
            warnings.push_back("the lists' binding holds " + std::to_string(words) + " words, " +
                               std::to_string(listCount) + " lists of " + std::to_string(words / listCount) +
                               " words: is the layout fixed:" + std::to_string(words / listCount - 1) +
                               " rather than " + toString(d.layout) + "?");
        echo.push_back("lists: " + toString(d.layout) + ", rule " + toString(d.rule) + ", tile size " +
                       std::to_string(d.tileSize) + ", " + std::to_string(listCount) + " lists (" +
                       b.blob->binding.where() + ", " + std::to_string(b.size()) + " bytes)");
        return b.words();
    }
    const Bytes idx{&blobOf(blobs, "indices"), capture, "light indices"};
    const std::vector<std::uint32_t> indices = idx.words();
    std::vector<std::uint32_t> words;
    if (d.listKind == K::CountsIndices) {
        const Bytes cnt{&blobOf(blobs, "counts"), capture, "list counts"};
        const std::uint32_t n = d.layout.capacity;
        cnt.need(0, listCount * 4, std::to_string(listCount) + " counts");
        idx.need(0, listCount * n * 4, std::to_string(listCount) + " lists of " + std::to_string(n) + " indices");
        // Buffers sized for another grid or another N: most likely the
        // description's tile (or rule) or N is not the renderer's.
        const std::uint64_t countWords = cnt.size() / 4, indexWords = idx.size() / 4;
        if (countWords > listCount)
            warnings.push_back("the counts' binding holds " + std::to_string(countWords) + " counts, the grid " +
                               std::to_string(listCount) + " lists (tile " + std::to_string(d.tileSize) + ", " +
                               toString(d.rule) + "): is lists.tile (or lists.rule) the renderer's?");
        else if (indexWords % listCount == 0 && indexWords / listCount != n)
            warnings.push_back("the indices' binding holds " + std::to_string(indexWords) + " indices, " +
                               std::to_string(listCount) + " lists of " + std::to_string(indexWords / listCount) +
                               ": is the layout counts+indices:" + std::to_string(indexWords / listCount) +
                               " rather than counts+indices:" + std::to_string(n) + "?");
        words.reserve(listCount * (n + 1));
        for (std::uint64_t l = 0; l < listCount; ++l) {
            words.push_back(cnt.u32(l * 4));
            words.insert(words.end(), indices.begin() + std::ptrdiff_t(l * n), indices.begin() + std::ptrdiff_t((l + 1) * n));
        }
        echo.push_back("lists: counts+indices:" + std::to_string(n) + ", rule " + toString(d.rule) + ", tile size " +
                       std::to_string(d.tileSize) + ", " + std::to_string(listCount) + " lists (counts " +
                       cnt.blob->binding.where() + ", indices " + idx.blob->binding.where() + ")");
        return words;
    }
    // Offset and count per list into the index array: as the compact layout
    // (word 0 entries, then pairs, then the index array).
    std::vector<std::uint32_t> offsets(listCount), counts(listCount);
    std::string from;
    if (d.listKind == K::Pairs) {
        const Bytes r{&blobOf(blobs, "ranges"), capture, "list ranges"};
        r.need(0, listCount * 8, std::to_string(listCount) + " offset and count pairs");
        for (std::uint64_t l = 0; l < listCount; ++l) offsets[l] = r.u32(l * 8), counts[l] = r.u32(l * 8 + 4);
        from = "pairs " + r.blob->binding.where();
    } else {
        const Bytes o{&blobOf(blobs, "offsets"), capture, "list offsets"};
        const bool haveCounts = !d.counts.empty();
        o.need(0, (listCount + (haveCounts ? 0 : 1)) * 4,
               std::to_string(listCount + (haveCounts ? 0 : 1)) + " offsets" + (haveCounts ? "" : " (one past the last list: no counts given)"));
        for (std::uint64_t l = 0; l < listCount; ++l) offsets[l] = o.u32(l * 4);
        from = "offsets " + o.blob->binding.where();
        if (haveCounts) {
            const Bytes c{&blobOf(blobs, "counts"), capture, "list counts"};
            c.need(0, listCount * 4, std::to_string(listCount) + " counts");
            for (std::uint64_t l = 0; l < listCount; ++l) counts[l] = c.u32(l * 4);
            from += ", counts " + c.blob->binding.where();
        } else {
            for (std::uint64_t l = 0; l < listCount; ++l) {
                const std::uint32_t next = o.u32((l + 1) * 4);
                if (next < offsets[l])
                    o.fail("offset of list " + std::to_string(l + 1) + " (" + std::to_string(next) +
                           ") is below list " + std::to_string(l) + "'s (" + std::to_string(offsets[l]) +
                           "): not prefix sums; give counts");
                counts[l] = next - offsets[l];
            }
        }
    }
    std::uint64_t entries = 0;
    for (std::uint64_t l = 0; l < listCount; ++l) entries = std::max<std::uint64_t>(entries, std::uint64_t(offsets[l]) + counts[l]);
    layout = LayoutSpec{ListLayout::Compact, std::uint32_t(indices.size())};
    words.reserve(1 + 2 * listCount + indices.size());
    words.push_back(std::uint32_t(std::min<std::uint64_t>(entries, 0xFFFFFFFFu)));
    for (std::uint64_t l = 0; l < listCount; ++l) words.push_back(offsets[l]), words.push_back(counts[l]);
    words.insert(words.end(), indices.begin(), indices.end());
    echo.push_back("lists: " + std::string(d.listKind == K::Pairs ? "pairs" : "ranges") + ", rule " + toString(d.rule) +
                   ", tile size " + std::to_string(d.tileSize) + ", " + std::to_string(listCount) + " lists, " +
                   std::to_string(indices.size()) + " index slots (" + from + ", indices " + idx.blob->binding.where() + ")");
    return words;
}

// Z-binning's tile masks and bin ranges (CaptureDescription::Lists::ZBin):
// the masks as the contract's bitmask words with bits by light index (the
// sorted positions mapped through `order`), and the bins as ranges of sorted
// positions.
std::vector<std::uint32_t> decodeZBin(const CaptureDescription& d, const std::map<std::string, CaptureBlob>& blobs,
                                      const std::string& capture, std::uint32_t tiles, std::uint32_t lights,
                                      double binNear, double binFar, CaptureZBin& z,
                                      std::vector<std::string>& echo) {
    z.near = binNear;
    z.far = binFar;
    // The light at each sorted position.
    z.order.resize(lights);
    std::string orderFrom = "the light buffer's order";
    if (!d.order.empty()) {
        const Bytes o{&blobOf(blobs, "order"), capture, "light order"};
        o.need(0, std::uint64_t(lights) * 4, std::to_string(lights) + " sorted light indices");
        std::vector<bool> seen(lights, false);
        for (std::uint32_t k = 0; k < lights; ++k) {
            const std::uint32_t l = o.u32(std::uint64_t(k) * 4);
            if (l >= lights || seen[l])
                o.fail("sorted position " + std::to_string(k) + " names light " + std::to_string(l) +
                       (l >= lights ? " of " + std::to_string(lights) : " twice") + ": not an order of the lights");
            seen[l] = true;
            z.order[k] = l;
        }
        orderFrom = "order " + o.blob->binding.where();
    } else {
        for (std::uint32_t k = 0; k < lights; ++k) z.order[k] = k;
    }
    // The bins.
    const Bytes b{&blobOf(blobs, "bins"), capture, "depth bins"};
    const std::uint64_t entry = d.binsU16 ? 4 : 8;
    const std::uint64_t count = d.binCount ? *d.binCount : b.size() / entry;
    if (count == 0) b.fail("holds no whole bin of " + std::to_string(entry) + " bytes");
    if (count > kMaxBins)
        b.fail("holds " + std::to_string(count) + " bins, more than the " + std::to_string(kMaxBins) +
               " the tool's zbin takes: give bin_count");
    b.need(0, count * entry, std::to_string(count) + " bins");
    z.lo.resize(count);
    z.hi.resize(count);
    for (std::uint64_t i = 0; i < count; ++i) {
        std::uint32_t lo = 0, hi = 0;
        if (d.binsU16) {
            const std::uint32_t w = b.u32(i * 4);
            lo = w & 0xffffu, hi = w >> 16;
            // A 16-bit range: 0xffff low half and 0 high half (or lo > hi) is empty.
        } else {
            lo = b.u32(i * 8), hi = b.u32(i * 8 + 4);
        }
        if (lo <= hi && hi >= lights)
            b.fail("bin " + std::to_string(i) + " reaches sorted position " + std::to_string(hi) + " of " +
                   std::to_string(lights) + " lights");
        z.lo[i] = lo, z.hi[i] = hi;
    }
    // The masks: words per tile for the lights, bits by sorted position.
    const Bytes m{&blobOf(blobs, "masks"), capture, "tile masks"};
    const std::uint32_t perTile = (lights + 31) / 32;
    m.need(0, std::uint64_t(tiles) * perTile * 4,
           std::to_string(tiles) + " tiles of " + std::to_string(perTile) + " mask words");
    std::vector<std::uint32_t> words(std::size_t(tiles) * perTile, 0u);
    for (std::uint64_t t = 0; t < tiles; ++t)
        for (std::uint32_t w = 0; w < perTile; ++w) {
            std::uint32_t bits = m.u32((t * perTile + w) * 4);
            while (bits) {
                const std::uint32_t k = w * 32 + std::uint32_t(__builtin_ctz(bits));
                bits &= bits - 1;
                if (k >= lights) continue; // the last word's unused bits
                const std::uint32_t l = z.order[k];
                words[t * perTile + l / 32] |= 1u << (l % 32);
            }
        }
    echo.push_back("lists: zbin, " + std::to_string(tiles) + " tile masks of " + std::to_string(perTile) +
                   " words (" + m.blob->binding.where() + "), " + std::to_string(count) + " bins (" +
                   (d.binsU16 ? "u16pair" : "u32pair") + ", " + b.blob->binding.where() + ") over view depth " +
                   fmt(binNear) + ".." + fmt(binFar) + ", sorted by " + orderFrom + ", tile size " +
                   std::to_string(d.tileSize));
    return words;
}

} // namespace

CaptureDescription parseCaptureDescription(const std::string& text, const std::string& file) {
    json j;
    try {
        j = json::parse(text);
    } catch (const json::exception& e) { // parse_error, and out_of_range for a number past a double
        throw InputError(file, "", 0, std::string("not JSON: ") + e.what());
    }
    const Reader r(file);
    if (!j.is_object()) r.fail("", "the description must be a JSON object with lights, camera, depth and lists");
    for (const auto& [key, value] : j.items())
        if (key != "lights" && key != "camera" && key != "depth" && key != "lists" && key != "comment")
            r.fail(key, "unknown field (lights, camera, depth, lists)");
    CaptureDescription d;
    d.file = file;
    parseLights(r, *r.child(j, "", "lights", true), d);
    parseCamera(r, *r.child(j, "", "camera", true), d);
    parseDepth(r, *r.child(j, "", "depth", true), d);
    parseLists(r, *r.child(j, "", "lists", true), d);
    return d;
}

CaptureDescription loadCaptureDescription(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::error_code ec;
    if (!in) throw InputError(path, "", 0, std::filesystem::exists(path, ec) ? "cannot read" : "no such file");
    // A description is a few hundred bytes: refuse to read a huge file whole.
    std::string text(64 * 1024 + 1, '\0');
    in.read(text.data(), std::streamsize(text.size()));
    text.resize(std::size_t(in.gcount()));
    if (text.size() > 64 * 1024) throw InputError(path, "", 0, "larger than 64 KiB: not a capture description");
    return parseCaptureDescription(text, path);
}

std::map<std::string, std::string> captureBindingsNeeded(const CaptureDescription& d) {
    std::map<std::string, std::string> m{{"lights", d.lights}, {"depth", d.depth}};
    if (d.lightCountField) m["light_count"] = d.lightCountField->binding;
    if (d.projection) m["camera"] = d.projection->binding;
    using K = CaptureDescription::Lists;
    if (d.listKind == K::Contract) m["lists"] = d.listBuffer;
    if (!d.masks.empty()) m["masks"] = d.masks;
    if (!d.bins.empty()) m["bins"] = d.bins;
    if (!d.order.empty()) m["order"] = d.order;
    if (!d.indices.empty()) m["indices"] = d.indices;
    if (!d.counts.empty()) m["counts"] = d.counts;
    if (!d.offsets.empty()) m["offsets"] = d.offsets;
    if (!d.ranges.empty()) m["ranges"] = d.ranges;
    return m;
}

CaptureFrame decodeCaptureFrame(const CaptureDescription& d, const std::map<std::string, CaptureBlob>& blobs,
                                const std::string& capture, std::uint32_t event) {
    CaptureFrame f;
    f.source = capture + " event " + std::to_string(event);
    f.rule = d.rule;
    f.depth = decodeDepth(d, Bytes{&blobOf(blobs, "depth"), capture, "depth"}, f.echo);

    Camera cam;
    glm::dmat4 viewFromWorld(1.0);
    if (d.projection) {
        const Bytes b{&blobOf(blobs, "camera"), capture, "camera"};
        cam = cameraFromProjection(readMatrix(b, d.projection->offset, d.rowMajor, "the projection matrix"), b, f.echo,
                                   f.warnings);
        if (d.view) viewFromWorld = readMatrix(b, d.view->offset, d.rowMajor, "the view matrix");
    } else {
        cam.projection = d.reversed ? ProjectionKind::ReversedZ : ProjectionKind::Perspective;
        cam.fovYDeg = *d.fovYDeg;
        cam.nearPlane = *d.nearPlane;
        cam.farPlane = *d.farPlane;
        f.echo.push_back("camera: " + std::string(toString(cam.projection)) + ", fov y " + fmt(cam.fovYDeg) +
                         " deg, near " + fmt(cam.nearPlane) + ", far " + fmt(cam.farPlane) + " (given)");
    }
    if (!d.lightsInViewSpace && !d.view)
        throw InputError(d.file, "camera.view", 0, "world-space lights need the view matrix's offset");
    // The frame in view space: the camera at the origin looking down -Z.
    cam.position = glm::dvec3(0.0);
    cam.target = glm::dvec3(0.0, 0.0, -1.0);
    cam.up = glm::dvec3(0.0, 1.0, 0.0);
    cam.width = f.depth.width;
    cam.height = f.depth.height;
    cam.tileSize = d.tileSize;
    if (const std::string bad = cam.validate(); !bad.empty()) throw InputError(capture, "", 0, bad);
    f.depth.clearDepth = float(Projection(cam).clearDepth());

    f.scene.name = std::filesystem::path(capture).stem().string();
    f.scene.camera = cam;
    f.scene.lights = decodeLights(d, blobs, capture, viewFromWorld, f.echo);
    // One radius for every light is what an offset into a constant field
    // reads (a colour's alpha of 1): the verdict would be about other spheres.
    if (f.scene.lights.size() > 1 &&
        std::all_of(f.scene.lights.begin(), f.scene.lights.end(), [&](const Light& l) {
            return l.explicitRadius == f.scene.lights.front().explicitRadius;
        }))
        f.warnings.push_back("all " + std::to_string(f.scene.lights.size()) + " lights read radius " +
                             fmt(f.scene.lights.front().explicitRadius) + ": is lights.radius (" +
                             std::to_string(d.radiusOffset) + ") the offset of the range in your struct?");

    const TileGrid grid = TileGrid::make(cam.width, cam.height, cam.tileSize);
    const std::uint32_t perTile = d.rule.kind == ListKind::Tile    ? 1
                                  : d.rule.kind == ListKind::HalfZ ? 2
                                                                   : d.rule.slices;
    const std::uint64_t listCount = std::uint64_t(grid.tileCount()) * perTile;
    using K = CaptureDescription::Lists;
    if (d.listKind == K::ZBin) {
        const double binNear = d.binNear.value_or(cam.nearPlane);
        const double binFar = d.binFar.value_or(cam.farPlane);
        if (!std::isfinite(binFar) || !(binFar > binNear))
            throw InputError(d.file, "lists.bin_far", 0,
                             "the camera's far plane is infinite: give the bins' far depth (bin_far)");
        f.zbin.emplace();
        f.words = decodeZBin(d, blobs, capture, grid.tileCount(), std::uint32_t(f.scene.lights.size()), binNear,
                             binFar, *f.zbin, f.echo);
        f.layout = d.layout;
        f.layoutName = "zbin";
        return f;
    }
    f.words = decodeListWords(d, blobs, capture, listCount, f.layout, f.echo, f.warnings);
    f.layoutName = d.listKind == K::Contract        ? toString(d.layout)
                   : d.listKind == K::CountsIndices ? "counts+indices:" + std::to_string(d.layout.capacity)
                   : d.listKind == K::Ranges        ? "ranges"
                                                    : "pairs";
    return f;
}

CaptureFrame loadCaptureFrame(const std::string& capture, const std::string& dispatch,
                              const CaptureDescription& description) {
    std::uint32_t event = 0;
    const auto blobs = readDispatchBindings(capture, dispatch, captureBindingsNeeded(description), event);
    return decodeCaptureFrame(description, blobs, capture, event);
}

namespace {

// A Z-binned frame's lists: its tile masks decoded as a dump, made a zbin
// result with its bins, which ground truth and shading walk per pixel
// (zbinPixelLists) as they do the built-in zbin's.
class ZBinCaptureLists final : public ListSource {
public:
    ZBinCaptureLists(DumpLists& masks, const CaptureFrame& frame) : masks_(masks), frame_(frame) {}
    CullResult makeLists(const Scene& scene, const DepthImage& depth, const Projection& proj, const TileGrid& grid,
                         const ViewLights& lights) override {
        CullResult r = masks_.makeLists(scene, depth, proj, grid, lights);
        const CaptureZBin& z = *frame_.zbin;
        if (z.order.size() != lights.size())
            throw InputError(frame_.source, "", 0,
                             "the capture's bins sort " + std::to_string(z.order.size()) + " lights, the scene has " +
                                 std::to_string(lights.size()) + " (a zbin capture's lights cannot be added or deleted)");
        r.algorithm = Algorithm::ZBin;
        r.settings.algorithm = Algorithm::ZBin;
        r.settings.bins = std::uint32_t(z.lo.size());
        r.zbinOrder = z.order;
        r.zbinRank.assign(z.order.size(), 0);
        for (std::uint32_t k = 0; k < z.order.size(); ++k) r.zbinRank[z.order[k]] = k;
        r.zbinLo = z.lo;
        r.zbinHi = z.hi;
        r.zbinNear = z.near;
        r.zbinFar = z.far;
        return r;
    }
    std::shared_ptr<const CustomCullReport> report() const override { return masks_.report(); }

private:
    DumpLists& masks_;
    const CaptureFrame& frame_;
};

} // namespace

std::string captureDepthSource(const CaptureFrame& frame) { return "capture " + frame.source; }

bool captureDepth(const RunOutput& run) { return run.depthFrom.rfind("capture ", 0) == 0; }

RunOutput checkCaptureFrame(const CaptureFrame& frame, const RunOptions& runOptions, CustomCullReport& report,
                            const Scene* scene) {
    if (scene && !(scene->camera == frame.scene.camera))
        throw InputError(frame.source, "camera", 0,
                         "the camera is not the capture's: its depth and lists are for the capture's camera");
    for (const std::string& w : frame.warnings) report.warnings.push_back(w);
    DumpLists lists(frame.source, frame.words, frame.layout, frame.rule, report);
    ZBinCaptureLists zbin(lists, frame);
    RunOptions o = runOptions;
    o.reuseDepth = &frame.depth;
    RunOutput out = runPipeline(scene ? *scene : frame.scene, frame.zbin ? static_cast<ListSource&>(zbin) : lists,
                                nullptr, o);
    out.depthFrom = captureDepthSource(frame);
    // The layout as the description named it (decoding went through the
    // contract's fixed or compact words).
    report.layout = frame.layoutName;
    if (out.custom) {
        auto named = std::make_shared<CustomCullReport>(*out.custom);
        named->layout = frame.layoutName;
        out.custom = named;
    }
    return out;
}

} // namespace lc
