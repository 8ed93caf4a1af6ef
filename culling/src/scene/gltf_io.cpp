#include "culling/scene/gltf_io.hpp"

#include "culling/core/errors.hpp"
#include "culling/core/file_io.hpp"
#include "scene/gltf_internal.hpp"
#include "scene/json_nesting.hpp"

#include <tiny_gltf.h>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

namespace lc {

// asset.generator of the glTF files this tool writes.
constexpr const char* kGltfGenerator = "LightCull Studio";


namespace fs = std::filesystem;

namespace {

constexpr double kPi = 3.14159265358979323846;
// Files past this are refused before reading (GLB lengths are 32-bit anyway).
constexpr std::uint64_t kMaxFileBytes = std::uint64_t(2) << 30;

std::string idx(const char* array, std::size_t i) { return std::string(array) + "[" + std::to_string(i) + "]"; }
std::string withCommas(std::uint64_t v) {
    const std::string digits = std::to_string(v);
    std::string s;
    for (std::size_t i = 0; i < digits.size(); ++i) {
        if (i > 0 && (digits.size() - i) % 3 == 0) s += ',';
        s += digits[i];
    }
    return s;
}
// A loader's message as one line of reasonable length: the first line, each
// data: URI in it cut to its head (tinygltf quotes the whole URI, megabytes
// of base64), and at most 300 characters.
std::string firstLine(std::string s) {
    while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
    const auto nl = s.find('\n');
    if (nl != std::string::npos) s = s.substr(0, nl) + " (and more)";
    for (std::size_t at = s.find("data:"); at != std::string::npos; at = s.find("data:", at + 1)) {
        const std::size_t comma = s.find(',', at), end = s.find_first_of(" '\"", at);
        const std::size_t stop = end == std::string::npos ? s.size() : end;
        if (comma == std::string::npos || comma >= stop || stop - comma <= 24) continue;
        s.replace(comma + 1, stop - comma - 1, "... (" + withCommas(stop - comma - 1) + " characters)");
    }
    if (s.size() > 300) s = s.substr(0, 300) + "...";
    return s;
}

std::string shortNumber(double v) {
    std::ostringstream o;
    o << v;
    return o.str();
}

std::string lowerExt(const std::string& path) {
    std::string e = fs::path(path).extension().string();
    std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return e;
}

std::uint32_t readU32(const std::string& b, std::size_t at) {
    return std::uint32_t(std::uint8_t(b[at])) | std::uint32_t(std::uint8_t(b[at + 1])) << 8 |
           std::uint32_t(std::uint8_t(b[at + 2])) << 16 | std::uint32_t(std::uint8_t(b[at + 3])) << 24;
}

// Reads the file, refusing what is not a regular file or is too large.
std::string readWholeFile(const std::string& path, const std::string& reportAs) {
    std::error_code ec;
    const fs::file_status st = fs::status(path, ec);
    if (ec || !fs::exists(st)) throw InputError(reportAs, "", 0, "file not found");
    if (fs::is_directory(st)) throw InputError(reportAs, "", 0, "is a folder, not a glTF file");
    if (!fs::is_regular_file(st)) throw InputError(reportAs, "", 0, "is not a regular file");
    const std::uint64_t size = fs::file_size(path, ec);
    if (ec) throw InputError(reportAs, "", 0, "cannot read file: " + ec.message());
    if (size == 0) throw InputError(reportAs, "", 0, "empty file");
    if (size > kMaxFileBytes)
        throw InputError(reportAs, "", 0, "file of " + withCommas(size) + " bytes is larger than the 2 GiB this reader takes");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(reportAs, "", 0, "cannot open file for reading");
    std::string bytes(std::size_t(size), '\0');
    in.read(bytes.data(), std::streamsize(size));
    if (std::uint64_t(in.gcount()) != size) throw InputError(reportAs, "", 0, "read error (file shrank while reading?)");
    return bytes;
}

// The GLB container checked before tinygltf sees it, so each defect gets its
// own message (tinygltf says "Invalid glTF binary." for most of them).
void checkGlbHeader(const std::string& file, const std::string& b) {
    if (b.size() < 12) throw InputError(file, "header", 0, "truncated: " + std::to_string(b.size()) + " bytes, a GLB header is 12");
    if (b.compare(0, 4, "glTF") != 0) throw InputError(file, "header.magic", 0, "not 'glTF': not a GLB file");
    const std::uint32_t version = readU32(b, 4), length = readU32(b, 8);
    if (version != 2) throw InputError(file, "header.version", 0, "GLB version " + std::to_string(version) + " (only 2 is read)");
    if (length > b.size())
        throw InputError(file, "header.length", 0, withCommas(length) + " bytes, but the file has " + withCommas(b.size()) + " (truncated?)");
    if (length < 20) throw InputError(file, "header.length", 0, std::to_string(length) + " bytes leave no room for the JSON chunk");
    const std::uint32_t jsonLength = readU32(b, 12), jsonType = readU32(b, 16);
    if (jsonType != 0x4E4F534Au) throw InputError(file, "chunks[0].type", 0, "the first chunk must be JSON");
    if (jsonLength == 0) throw InputError(file, "chunks[0].length", 0, "empty JSON chunk");
    if (20ull + jsonLength > length)
        throw InputError(file, "chunks[0].length", 0, withCommas(jsonLength) + " bytes run past the end of the file (" + withCommas(length) + " bytes)");
    const std::uint64_t binAt = 20ull + jsonLength;
    if (binAt < length) {
        if (binAt + 8 > length) throw InputError(file, "chunks[1]", 0, "truncated chunk header");
        const std::uint32_t binLength = readU32(b, std::size_t(binAt)), binType = readU32(b, std::size_t(binAt + 4));
        if (binType != 0x004E4942u) throw InputError(file, "chunks[1].type", 0, "the second chunk must be BIN");
        if (binAt + 8 + binLength > length)
            throw InputError(file, "chunks[1].length", 0, withCommas(binLength) + " bytes run past the end of the file (" + withCommas(length) + " bytes)");
    }
}

// File access for tinygltf: external buffers only (images are never
// loaded), regular files only, each read bounded by its own size.
tinygltf::FsCallbacks fileCallbacks() {
    tinygltf::FsCallbacks cb;
    cb.FileExists = [](const std::string& p, void*) {
        std::error_code ec;
        return fs::is_regular_file(p, ec);
    };
    cb.ExpandFilePath = [](const std::string& p, void*) { return p; };
    cb.ReadWholeFile = [](std::vector<unsigned char>* out, std::string* err, const std::string& p, void*) {
        try {
            const std::string bytes = readWholeFile(p, p);
            out->assign(bytes.begin(), bytes.end());
            return true;
        } catch (const InputError& e) {
            if (err) *err += e.what();
            return false;
        }
    };
    cb.WriteWholeFile = [](std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
        if (err) *err += "writing through the reader is not supported";
        return false;
    };
    return cb;
}

bool ignoreImage(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int, void*) {
    return true; // images are never decoded: culling needs no texels
}

// ---------------------------------------------------------------- reading

class GltfReader {
public:
    GltfReader(std::string file, const tinygltf::Model& m, GltfReadReport& rep, const CancelToken* cancel)
        : file_(std::move(file)), m_(m), rep_(rep), cancel_(cancel) {}

    [[noreturn]] void fail(const std::string& field, const std::string& what) const {
        throw InputError(file_, field, 0, what);
    }
    void warn(const std::string& what) { rep_.warnings.push_back(file_ + ": " + what); }

    void checkExtensions() {
        for (std::size_t i = 0; i < m_.extensionsRequired.size(); ++i) {
            const std::string& e = m_.extensionsRequired[i];
            if (e == "KHR_lights_punctual" || e == "KHR_mesh_quantization") continue;
            if (e == "KHR_draco_mesh_compression" || e == "EXT_meshopt_compression" || e == "KHR_meshopt_compression")
                fail(idx("extensionsRequired", i), "'" + e + "' compressed geometry is not supported; export the file "
                                                   "without mesh compression");
            // Material and texture extensions change how surfaces look, not
            // where they are: the geometry is read all the same.
            if (e.rfind("KHR_materials_", 0) == 0 || e.rfind("KHR_texture_", 0) == 0 || e == "EXT_texture_webp") {
                warn("extension '" + e + "' is required but only affects materials; ignored");
                continue;
            }
            fail(idx("extensionsRequired", i), "extension '" + e + "' is required but not supported (LightCull reads "
                                               "KHR_lights_punctual and KHR_mesh_quantization)");
        }
    }

    // Nodes of the scene in pre-order (the "scene's node order"), each with
    // its world matrix. glTF nodes form trees: a node reached twice (a cycle,
    // or two parents) is an error, which also bounds the walk by the node count.
    using Placed = GltfPlacedNode;
    std::vector<Placed> walkScene() {
        std::vector<int> roots;
        if (!m_.scenes.empty()) {
            std::size_t s = 0;
            if (m_.defaultScene >= 0) {
                if (std::size_t(m_.defaultScene) >= m_.scenes.size())
                    fail("scene", std::to_string(m_.defaultScene) + " is not an index into scenes (" +
                                      std::to_string(m_.scenes.size()) + ")");
                s = std::size_t(m_.defaultScene);
            }
            roots = m_.scenes[s].nodes;
            for (std::size_t k = 0; k < roots.size(); ++k) checkNodeIndex(roots[k], idx("scenes", s) + "." + idx("nodes", k));
        } else {
            // No scene: every node that is nobody's child.
            std::vector<char> isChild(m_.nodes.size(), 0);
            for (std::size_t n = 0; n < m_.nodes.size(); ++n)
                for (std::size_t k = 0; k < m_.nodes[n].children.size(); ++k) {
                    const int c = m_.nodes[n].children[k];
                    checkNodeIndex(c, idx("nodes", n) + "." + idx("children", k));
                    isChild[std::size_t(c)] = 1;
                }
            for (std::size_t n = 0; n < m_.nodes.size(); ++n)
                if (!isChild[n]) roots.push_back(int(n));
        }
        std::vector<char> seen(m_.nodes.size(), 0);
        std::vector<Placed> out;
        std::vector<Placed> stack;
        for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.push_back({*it, glm::dmat4(1.0)});
        while (!stack.empty()) {
            const Placed p = stack.back();
            stack.pop_back();
            const std::size_t n = std::size_t(p.node);
            if (seen[n]) fail(idx("nodes", n), "reached twice from the scene (a node cycle, or a node with two parents); glTF nodes must form trees");
            seen[n] = 1;
            const glm::dmat4 world = p.world * localMatrix(n);
            out.push_back({p.node, world});
            const auto& children = m_.nodes[n].children;
            for (std::size_t k = children.size(); k-- > 0;) {
                checkNodeIndex(children[k], idx("nodes", n) + "." + idx("children", k));
                stack.push_back({children[k], world});
            }
            if (cancel_ && (out.size() & 0xFFF) == 0) cancel_->throwIfCancelled();
        }
        return out;
    }

    // Every triangle of one glTF mesh in its own model space. Each primitive's
    // positions are appended; strips and fans become triangle lists.
    struct ModelGeometry {
        std::vector<float> positions;
        std::vector<std::uint32_t> indices;
        bool decoded = false;
    };
    const ModelGeometry& meshGeometry(int meshIndex) {
        if (geometry_.size() != m_.meshes.size()) geometry_.resize(m_.meshes.size());
        ModelGeometry& g = geometry_[std::size_t(meshIndex)];
        if (g.decoded) return g;
        g.decoded = true;
        const tinygltf::Mesh& mesh = m_.meshes[std::size_t(meshIndex)];
        const std::string mp = idx("meshes", std::size_t(meshIndex));
        const std::string meshName = mesh.name.empty() ? mp : "'" + mesh.name + "' (" + mp + ")";
        for (std::size_t k = 0; k < mesh.primitives.size(); ++k) {
            const tinygltf::Primitive& prim = mesh.primitives[k];
            const std::string pp = mp + "." + idx("primitives", k);
            const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
            if (mode >= TINYGLTF_MODE_POINTS && mode <= TINYGLTF_MODE_LINE_STRIP) {
                warn("mesh " + meshName + " primitive " + std::to_string(k) + ": " +
                     (mode == TINYGLTF_MODE_POINTS ? "points" : "lines") + " skipped (only triangles occlude)");
                continue;
            }
            if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN)
                fail(pp + ".mode", std::to_string(mode) + " is not a glTF primitive mode (0..6)");
            if (!prim.targets.empty() && !warnedMorph_) {
                warnedMorph_ = true;
                warn("morph targets ignored: geometry is read in its base shape");
            }
            const auto pos = prim.attributes.find("POSITION");
            if (pos == prim.attributes.end()) {
                warn("mesh " + meshName + " primitive " + std::to_string(k) + " has no POSITION; skipped");
                continue;
            }
            const std::size_t base = g.positions.size() / 3;
            const std::size_t nv = readPositions(pos->second, pp + ".attributes.POSITION", g.positions);
            std::vector<std::uint32_t> corners;
            if (prim.indices >= 0) {
                readIndices(prim.indices, pp + ".indices", nv, corners);
            } else {
                corners.resize(nv);
                for (std::size_t v = 0; v < nv; ++v) corners[v] = std::uint32_t(v);
            }
            appendTriangles(mode, corners, base, g);
        }
        return g;
    }

    std::size_t dropped() const { return dropped_; }
    // Vertices after a TRIANGLES primitive's last whole triangle.
    std::size_t trailing() const { return trailing_; }

    const tinygltf::Accessor& accessor(int i, const std::string& field) const {
        if (i < 0 || std::size_t(i) >= m_.accessors.size())
            fail(field, std::to_string(i) + " is not an index into accessors (" + std::to_string(m_.accessors.size()) + ")");
        return m_.accessors[std::size_t(i)];
    }

    glm::dmat4 localMatrix(std::size_t n) const {
        const tinygltf::Node& node = m_.nodes[n];
        const std::string np = idx("nodes", n);
        auto finite = [&](const std::vector<double>& v, const char* key) {
            for (double d : v)
                if (!std::isfinite(d)) fail(np + "." + key, "must be finite");
        };
        if (!node.matrix.empty()) {
            if (node.matrix.size() != 16) fail(np + ".matrix", "must have 16 numbers, has " + std::to_string(node.matrix.size()));
            finite(node.matrix, "matrix");
            glm::dmat4 m;
            for (int k = 0; k < 16; ++k) m[k / 4][k % 4] = node.matrix[std::size_t(k)]; // column-major, as glTF
            if (m[0][3] != 0.0 || m[1][3] != 0.0 || m[2][3] != 0.0 || m[3][3] != 1.0)
                fail(np + ".matrix", "is not affine: its last row must be 0, 0, 0, 1 (elements 3, 7, 11, 15)");
            return m;
        }
        glm::dmat4 t(1.0), r(1.0), s(1.0);
        if (!node.translation.empty()) {
            if (node.translation.size() != 3) fail(np + ".translation", "must have 3 numbers");
            finite(node.translation, "translation");
            t = glm::translate(glm::dmat4(1.0), glm::dvec3(node.translation[0], node.translation[1], node.translation[2]));
        }
        if (!node.rotation.empty()) {
            if (node.rotation.size() != 4) fail(np + ".rotation", "must have 4 numbers (a quaternion x, y, z, w)");
            finite(node.rotation, "rotation");
            glm::dquat q(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);
            const double len = glm::length(q);
            if (!(len > 1e-12)) fail(np + ".rotation", "is a zero quaternion");
            r = glm::mat4_cast(q / len);
        }
        if (!node.scale.empty()) {
            if (node.scale.size() != 3) fail(np + ".scale", "must have 3 numbers");
            finite(node.scale, "scale");
            s = glm::scale(glm::dmat4(1.0), glm::dvec3(node.scale[0], node.scale[1], node.scale[2]));
        }
        return t * r * s;
    }

    // Bytes [offset, offset + elemSize + stride * (count - 1)) of one
    // bufferView, checked against the view and the view against its buffer.
    struct Span {
        const unsigned char* data;
        std::size_t stride;
    };
    Span viewSpan(int viewIndex, std::uint64_t offset, std::uint64_t count, std::size_t elemSize, std::size_t defaultStride,
                  const std::string& field, const std::string& what) const {
        if (viewIndex < 0 || std::size_t(viewIndex) >= m_.bufferViews.size())
            fail(field + ".bufferView", std::to_string(viewIndex) + " is not an index into bufferViews (" +
                                            std::to_string(m_.bufferViews.size()) + ")");
        const tinygltf::BufferView& bv = m_.bufferViews[std::size_t(viewIndex)];
        const std::string bvp = idx("bufferViews", std::size_t(viewIndex));
        if (bv.buffer < 0 || std::size_t(bv.buffer) >= m_.buffers.size())
            fail(bvp + ".buffer", std::to_string(bv.buffer) + " is not an index into buffers (" + std::to_string(m_.buffers.size()) + ")");
        const std::uint64_t bufBytes = m_.buffers[std::size_t(bv.buffer)].data.size();
        if (std::uint64_t(bv.byteOffset) > bufBytes || std::uint64_t(bv.byteLength) > bufBytes - std::uint64_t(bv.byteOffset))
            fail(bvp, "bytes " + withCommas(bv.byteOffset) + ".." + withCommas(std::uint64_t(bv.byteOffset) + bv.byteLength) +
                          " run past the end of " + idx("buffers", std::size_t(bv.buffer)) + " (" + withCommas(bufBytes) + " bytes)");
        const std::size_t stride = bv.byteStride == 0 ? defaultStride : bv.byteStride;
        if (stride < elemSize) fail(bvp + ".byteStride", std::to_string(stride) + " is smaller than one element (" + std::to_string(elemSize) + " bytes)");
        // Needed bytes without overflow: count <= view bytes is checked first.
        const std::uint64_t viewBytes = bv.byteLength;
        bool fits = offset <= viewBytes && count <= viewBytes;
        if (fits && count > 0) {
            const std::uint64_t need = offset + std::uint64_t(stride) * (count - 1) + elemSize;
            fits = need <= viewBytes;
        }
        if (!fits)
            fail(field + ".count", withCommas(count) + " " + what + " do not fit " + bvp + " (" + withCommas(viewBytes) + " bytes)");
        return {m_.buffers[std::size_t(bv.buffer)].data.data() + bv.byteOffset + offset, stride};
    }

private:
    void checkNodeIndex(int n, const std::string& field) const {
        if (n < 0 || std::size_t(n) >= m_.nodes.size())
            fail(field, std::to_string(n) + " is not an index into nodes (" + std::to_string(m_.nodes.size()) + ")");
    }

    static std::size_t componentBytes(int type) {
        switch (type) {
        case TINYGLTF_COMPONENT_TYPE_BYTE:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
        case TINYGLTF_COMPONENT_TYPE_SHORT:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
        case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
        default: return 0;
        }
    }

    // One component as a float, normalised integers mapped to [-1, 1] / [0, 1]
    // as glTF (and KHR_mesh_quantization) define them.
    static float component(const unsigned char* p, int type, bool normalized) {
        switch (type) {
        case TINYGLTF_COMPONENT_TYPE_FLOAT: {
            float f;
            std::memcpy(&f, p, 4);
            return f;
        }
        case TINYGLTF_COMPONENT_TYPE_BYTE: {
            const auto v = std::int8_t(*p);
            return normalized ? std::max(float(v) / 127.0f, -1.0f) : float(v);
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? float(*p) / 255.0f : float(*p);
        case TINYGLTF_COMPONENT_TYPE_SHORT: {
            std::int16_t v;
            std::memcpy(&v, p, 2);
            return normalized ? std::max(float(v) / 32767.0f, -1.0f) : float(v);
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
            std::uint16_t v;
            std::memcpy(&v, p, 2);
            return normalized ? float(v) / 65535.0f : float(v);
        }
        default: return 0.0f;
        }
    }

    static std::uint32_t indexValue(const unsigned char* p, int type) {
        if (type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) return *p;
        if (type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) {
            std::uint16_t v;
            std::memcpy(&v, p, 2);
            return v;
        }
        std::uint32_t v;
        std::memcpy(&v, p, 4);
        return v;
    }

    // Appends the accessor's VEC3 positions (sparse substitution applied);
    // returns the vertex count.
    std::size_t readPositions(int accessorIndex, const std::string& field, std::vector<float>& out) {
        const tinygltf::Accessor& a = accessor(accessorIndex, field);
        const std::string ap = idx("accessors", std::size_t(accessorIndex));
        if (a.type != TINYGLTF_TYPE_VEC3) fail(ap + ".type", "POSITION must be VEC3");
        const std::size_t cb = componentBytes(a.componentType);
        if (cb == 0 || a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
            fail(ap + ".componentType", std::to_string(a.componentType) + " is not a position component type");
        const std::uint64_t count = a.count;
        if (count == 0) return 0;
        const std::size_t elem = 3 * cb;
        const std::size_t before = out.size();
        if (a.bufferView >= 0) {
            const Span s = viewSpan(a.bufferView, a.byteOffset, count, elem, elem, ap, "VEC3 elements");
            out.resize(before + 3 * std::size_t(count));
            for (std::size_t v = 0; v < count; ++v)
                for (int c = 0; c < 3; ++c)
                    out[before + 3 * v + std::size_t(c)] = component(s.data + v * s.stride + std::size_t(c) * cb, a.componentType, a.normalized);
        } else {
            if (!a.sparse.isSparse) fail(ap + ".bufferView", "missing (and no sparse values): no data for POSITION");
            // Zeros plus sparse values: the zeros are not in the file, so a
            // few bytes could ask for any count. Allow one per buffer byte.
            std::uint64_t bytes = 4096;
            for (const auto& b : m_.buffers) bytes += b.data.size();
            if (count > bytes)
                fail(ap + ".count", withCommas(count) + " vertices without data (no bufferView) is more than the file's " +
                                        withCommas(bytes) + " bytes justify");
            out.resize(before + 3 * std::size_t(count), 0.0f);
        }
        if (a.sparse.isSparse) {
            const std::string sp = ap + ".sparse";
            if (a.sparse.count < 0 || std::uint64_t(a.sparse.count) > count)
                fail(sp + ".count", std::to_string(a.sparse.count) + " is not in 0.." + withCommas(count));
            const std::size_t n = std::size_t(a.sparse.count);
            const int it = a.sparse.indices.componentType;
            if (it != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && it != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
                it != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
                fail(sp + ".indices.componentType", std::to_string(it) + " is not an index component type");
            if (a.sparse.indices.byteOffset < 0) fail(sp + ".indices.byteOffset", "must be >= 0");
            if (a.sparse.values.byteOffset < 0) fail(sp + ".values.byteOffset", "must be >= 0");
            const std::size_t ib = componentBytes(it);
            const Span is = viewSpan(a.sparse.indices.bufferView, std::uint64_t(a.sparse.indices.byteOffset), n, ib, ib,
                                     sp + ".indices", "sparse indices");
            const Span vs = viewSpan(a.sparse.values.bufferView, std::uint64_t(a.sparse.values.byteOffset), n, elem, elem,
                                     sp + ".values", "sparse values");
            for (std::size_t k = 0; k < n; ++k) {
                const std::uint32_t target = indexValue(is.data + k * is.stride, it);
                if (target >= count)
                    fail(sp + ".indices", "element " + std::to_string(k) + " is " + std::to_string(target) +
                                              ", outside 0.." + withCommas(count - 1));
                if (k > 0 && target <= indexValue(is.data + (k - 1) * is.stride, it))
                    fail(sp + ".indices", "element " + std::to_string(k) + " (" + std::to_string(target) +
                                              ") is not greater than the one before: glTF's sparse indices increase strictly");
                for (int c = 0; c < 3; ++c)
                    out[before + 3 * target + std::size_t(c)] = component(vs.data + k * vs.stride + std::size_t(c) * cb, a.componentType, a.normalized);
            }
        }
        for (std::size_t i = before; i < out.size(); ++i)
            if (!std::isfinite(out[i]))
                fail(ap, "element " + std::to_string((i - before) / 3) + " has a non-finite coordinate");
        return std::size_t(count);
    }

    void readIndices(int accessorIndex, const std::string& field, std::size_t vertexCount, std::vector<std::uint32_t>& out) {
        const tinygltf::Accessor& a = accessor(accessorIndex, field);
        const std::string ap = idx("accessors", std::size_t(accessorIndex));
        if (a.type != TINYGLTF_TYPE_SCALAR) fail(ap + ".type", "indices must be SCALAR");
        const int t = a.componentType;
        if (t != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && t != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT && t != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
            fail(ap + ".componentType", std::to_string(t) + " is not an index component type (5121, 5123, 5125)");
        if (a.sparse.isSparse) fail(ap + ".sparse", "sparse index accessors are not supported");
        if (a.bufferView < 0) fail(ap + ".bufferView", "missing: indices need data");
        const std::size_t ib = componentBytes(t);
        const Span s = viewSpan(a.bufferView, a.byteOffset, a.count, ib, ib, ap, "indices");
        out.resize(std::size_t(a.count));
        for (std::size_t k = 0; k < out.size(); ++k) {
            const std::uint32_t v = indexValue(s.data + k * s.stride, t);
            if (v >= vertexCount)
                fail(field, "index " + std::to_string(v) + " at element " + std::to_string(k) + " is outside the " +
                                withCommas(vertexCount) + " vertices of the primitive");
            out[k] = v;
        }
    }

    void appendTriangles(int mode, const std::vector<std::uint32_t>& c, std::size_t base, ModelGeometry& g) {
        auto add = [&](std::uint32_t a, std::uint32_t b, std::uint32_t d) {
            if (a == b || b == d || a == d) {
                ++dropped_; // strips use repeated corners to restart; nothing to draw
                return;
            }
            g.indices.insert(g.indices.end(), {std::uint32_t(base + a), std::uint32_t(base + b), std::uint32_t(base + d)});
        };
        if (mode == TINYGLTF_MODE_TRIANGLES) {
            for (std::size_t k = 0; k + 2 < c.size(); k += 3) add(c[k], c[k + 1], c[k + 2]);
            trailing_ += c.size() % 3;
        } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
            // Winding alternates; culling draws both faces, the order is kept
            // as the specification gives it anyway.
            for (std::size_t k = 0; k + 2 < c.size(); ++k) {
                if (k % 2 == 0) add(c[k], c[k + 1], c[k + 2]);
                else add(c[k + 1], c[k], c[k + 2]);
            }
        } else {
            for (std::size_t k = 1; k + 1 < c.size(); ++k) add(c[0], c[k], c[k + 1]);
        }
    }

    std::string file_;
    const tinygltf::Model& m_;
    GltfReadReport& rep_;
    const CancelToken* cancel_;
    std::vector<ModelGeometry> geometry_;
    std::size_t dropped_ = 0, trailing_ = 0;
    bool warnedMorph_ = false;
};

tinygltf::Model parseModel(const std::string& path, GltfReadReport& rep) {
    const std::string bytes = readWholeFile(path, path);
    const bool binary = bytes.size() >= 4 && bytes.compare(0, 4, "glTF") == 0;
    if (lowerExt(path) == ".glb" || binary) checkGlbHeader(path, bytes);
    // The JSON (a GLB's first chunk, checked above) before tinygltf recurses into it.
    const std::string_view json =
        binary ? std::string_view(bytes).substr(20, readU32(bytes, 12)) : std::string_view(bytes);
    if (const int line = jsonNestingTooDeep(json))
        throw InputError(path, "", binary ? 0 : line,
                         "arrays and objects nested more than " + std::to_string(kMaxJsonNesting) + " deep");
    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(ignoreImage, nullptr);
    loader.SetFsCallbacks(fileCallbacks());
    tinygltf::Model model;
    std::string err, warn;
    fs::path dir = fs::path(path).parent_path();
    const std::string baseDir = dir.empty() ? std::string(".") : dir.string();
    bool ok = false;
    try {
        ok = binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, reinterpret_cast<const unsigned char*>(bytes.data()),
                                                  unsigned(bytes.size()), baseDir)
                    : loader.LoadASCIIFromString(&model, &err, &warn, bytes.data(), unsigned(bytes.size()), baseDir);
    } catch (const std::exception& e) {
        // nlohmann's parse or type errors escape tinygltf on some inputs.
        throw InputError(path, "", 0, std::string("not valid glTF JSON: ") + firstLine(e.what()));
    }
    if (!ok) {
        std::string why = firstLine(err.empty() ? std::string("unreadable") : err);
        if (why.find("Failed to decode 'uri'") != std::string::npos)
            why += " (a buffer's data: URI that is not base64 of its byteLength bytes)";
        if (why.find("Spot light description not found") != std::string::npos)
            why += " (a KHR_lights_punctual light of type spot without its \"spot\" object)";
        throw InputError(path, "", 0, "not valid glTF: " + why);
    }
    if (!warn.empty()) rep.warnings.push_back(path + ": " + firstLine(warn));
    if (model.asset.version.rfind("2.", 0) != 0)
        throw InputError(path, "asset.version", 0, "'" + model.asset.version + "': this reads glTF 2.x");
    return model;
}

struct Loaded {
    Mesh mesh;
    std::vector<GltfReader::Placed> placed;
};

Loaded readGeometry(const std::string& path, const tinygltf::Model& model, GltfReader& r, GltfReadReport& rep,
                    const CancelToken* cancel, const Progress& progress) {
    r.checkExtensions();
    Loaded out;
    out.placed = r.walkScene();
    // Count before allocating: instancing multiplies triangles.
    std::uint64_t tris = 0, verts = 0;
    for (const auto& p : out.placed) {
        const int mi = model.nodes[std::size_t(p.node)].mesh;
        if (mi < 0) continue;
        if (std::size_t(mi) >= model.meshes.size())
            r.fail(idx("nodes", std::size_t(p.node)) + ".mesh", std::to_string(mi) + " is not an index into meshes (" +
                                                             std::to_string(model.meshes.size()) + ")");
        const auto& g = r.meshGeometry(mi);
        tris += g.indices.size() / 3;
        verts += g.positions.size() / 3;
        if (tris > kGltfMaxTriangles)
            r.fail(idx("nodes", std::size_t(p.node)) + ".mesh", "the scene places more than " + withCommas(kGltfMaxTriangles) +
                                                                 " triangles, more than this reader takes");
        if (cancel) cancel->throwIfCancelled();
    }
    if (progress) progress(0.5);
    Mesh& mesh = out.mesh;
    mesh.name = fs::path(path).stem().string();
    mesh.sourcePath = path;
    mesh.resolvedPath = fs::absolute(fs::path(path)).lexically_normal().string();
    mesh.positions.reserve(std::size_t(3 * verts));
    mesh.indices.reserve(std::size_t(3 * tris));
    for (const auto& p : out.placed) {
        const int mi = model.nodes[std::size_t(p.node)].mesh;
        if (mi < 0) continue;
        const auto& g = r.meshGeometry(mi);
        if (g.indices.empty()) continue;
        const auto base = std::uint32_t(mesh.positions.size() / 3);
        for (std::size_t v = 0; v < g.positions.size(); v += 3) {
            const glm::dvec4 w = p.world * glm::dvec4(g.positions[v], g.positions[v + 1], g.positions[v + 2], 1.0);
            for (int c = 0; c < 3; ++c) {
                const float f = float(w[c]);
                if (!std::isfinite(f))
                    r.fail(idx("nodes", std::size_t(p.node)), "its transform takes a vertex of " + idx("meshes", std::size_t(mi)) +
                                                                 " out of float range");
                mesh.positions.push_back(f);
            }
        }
        for (std::uint32_t i : g.indices) mesh.indices.push_back(base + i);
        if (cancel) cancel->throwIfCancelled();
    }
    rep.degenerateTrianglesDropped = r.dropped();
    if (r.dropped() > 0)
        rep.warnings.push_back(path + ": dropped " + std::to_string(r.dropped()) + " degenerate triangle(s) (repeated corner)");
    if (r.trailing() > 0)
        rep.warnings.push_back(path + ": " + std::to_string(r.trailing()) +
                               " vertex(es) after the last whole triangle of TRIANGLES primitives ignored (count not a "
                               "multiple of 3)");
    if (progress) progress(0.9);
    return out;
}

// extras.lightcull of a camera or light, when present and an object.
const tinygltf::Value* lightcullExtras(const tinygltf::Value& extras) {
    if (!extras.IsObject() || !extras.Has("lightcull")) return nullptr;
    const tinygltf::Value& v = extras.Get("lightcull");
    return v.IsObject() ? &v : nullptr;
}
bool extraNumber(const tinygltf::Value* x, const char* key, double& out) {
    if (!x || !x->Has(key)) return false;
    const tinygltf::Value& v = x->Get(key);
    if (!v.IsNumber()) return false;
    out = v.GetNumberAsDouble();
    return std::isfinite(out);
}

glm::dvec3 columnDir(const glm::dmat4& m, const glm::dvec3& local) { return glm::dvec3(m * glm::dvec4(local, 0.0)); }

// The camera node GltfReadOptions::camera picks (see gltf_internal.hpp,
// chooseGltfCamera); null when the scene places none.
const GltfReader::Placed* chooseCamera(const std::string& path, const tinygltf::Model& model,
                                       const std::vector<GltfReader::Placed>& placed, const std::string& want) {
    std::vector<const GltfReader::Placed*> cams;
    for (const auto& p : placed) {
        const int c = model.nodes[std::size_t(p.node)].camera;
        if (c < 0) continue;
        if (std::size_t(c) >= model.cameras.size())
            throw InputError(path, idx("nodes", std::size_t(p.node)) + ".camera", 0,
                             std::to_string(c) + " is not an index into cameras (" + std::to_string(model.cameras.size()) + ")");
        cams.push_back(&p);
    }
    const GltfReader::Placed* chosen = nullptr;
    if (!want.empty()) {
        const bool numeric = want.find_first_not_of("0123456789") == std::string::npos && want.size() < 10;
        // By name, every placement that answers to it: more than one is a
        // question only the user can settle (by index), not the first.
        std::string matches;
        int matched = 0;
        for (const auto* p : cams) {
            const int c = model.nodes[std::size_t(p->node)].camera;
            if (numeric ? c == std::stoi(want)
                        : (model.cameras[std::size_t(c)].name == want || model.nodes[std::size_t(p->node)].name == want)) {
                if (!chosen) chosen = p;
                if (numeric) break;
                matches += std::string(matched++ ? ", " : "") + idx("cameras", std::size_t(c)) + " on " +
                           idx("nodes", std::size_t(p->node));
            }
        }
        if (matched > 1)
            throw SettingsError("camera", "'" + want + "' names more than one camera in " + path + " (" + matches +
                                              "): give the camera's index");
        if (!chosen) {
            std::string have;
            for (const auto* p : cams) {
                const int c = model.nodes[std::size_t(p->node)].camera;
                have += (have.empty() ? "" : ", ") + std::to_string(c);
                if (!model.cameras[std::size_t(c)].name.empty()) have += " '" + model.cameras[std::size_t(c)].name + "'";
            }
            throw SettingsError("camera", "no camera '" + want + "' in the scene of " + path +
                                              (have.empty() ? " (it has none)" : " (it has: " + have + ")"));
        }
    } else if (!cams.empty()) {
        chosen = cams.front();
    }
    return chosen;
}

Camera readCamera(const std::string& path, const tinygltf::Model& model, const std::vector<GltfReader::Placed>& placed,
                  const GltfReadOptions& options, const Mesh& geometry, GltfReadReport& rep) {
    auto bounds = [&] {
        glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
        for (std::size_t v = 0; v < geometry.positions.size(); v += 3) {
            const glm::dvec3 p(geometry.positions[v], geometry.positions[v + 1], geometry.positions[v + 2]);
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
        if (geometry.positions.empty()) lo = hi = glm::dvec3(0.0);
        return std::pair{lo, hi};
    };
    const GltfReader::Placed* chosen = chooseCamera(path, model, placed, options.camera);

    Camera cam;
    if (!chosen) {
        const auto [lo, hi] = bounds();
        rep.camera = "no camera in the file: framed the scene's bounds";
        return frameBounds(lo, hi, cam);
    }
    const int ci = model.nodes[std::size_t(chosen->node)].camera;
    const tinygltf::Camera& gc = model.cameras[std::size_t(ci)];
    const std::string cp = idx("cameras", std::size_t(ci));
    GltfCameraPose pose;
    if (!gltfCameraPose(chosen->world, pose))
        throw InputError(path, idx("nodes", std::size_t(chosen->node)), 0, "the camera node's transform is singular");
    cam.position = pose.position;
    const glm::dvec3 f = pose.forward;
    // The look-at target only sets the orbit distance in the studio: the
    // distance to the middle of the geometry along the view, at least 1.
    const auto [lo, hi] = bounds();
    const double along = glm::dot((lo + hi) * 0.5 - cam.position, f);
    cam.target = cam.position + f * std::max(1.0, std::isfinite(along) ? along : 1.0);
    cam.up = pose.up;
    double aspect = 0.0;
    if (gc.type == "perspective") {
        const auto& p = gc.perspective;
        cam.fovYDeg = p.yfov * 180.0 / kPi;
        cam.nearPlane = p.znear;
        if (p.zfar > 0.0) {
            cam.projection = ProjectionKind::Perspective;
            cam.farPlane = p.zfar;
        } else {
            // No zfar: an infinite far plane, which only reversed-Z keeps precise.
            cam.projection = ProjectionKind::ReversedZ;
            cam.farPlane = std::numeric_limits<double>::infinity();
        }
        aspect = p.aspectRatio;
    } else if (gc.type == "orthographic") {
        const auto& o = gc.orthographic;
        cam.projection = ProjectionKind::Orthographic;
        cam.orthoHeight = 2.0 * o.ymag;
        cam.nearPlane = std::max(o.znear, 0.0);
        cam.farPlane = o.zfar;
        if (o.ymag > 0.0 && o.xmag > 0.0) aspect = o.xmag / o.ymag;
        if (cam.nearPlane == 0.0) cam.nearPlane = std::max(1e-3 * o.zfar, 1e-6); // ours needs near > 0
    } else {
        throw InputError(path, cp + ".type", 0, "'" + gc.type + "' is not perspective or orthographic");
    }
    if (aspect > 0.0 && std::isfinite(aspect)) {
        const long h = std::lround(double(cam.width) / aspect);
        cam.height = std::uint32_t(std::clamp(h, 1L, 16384L));
        if (h < 1 || h > 16384)
            rep.warnings.push_back(path + ": " + cp + " aspect ratio " + shortNumber(aspect) + " at width " +
                                   std::to_string(cam.width) + " asks for a height of " + std::to_string(h) +
                                   ": " + std::to_string(cam.height) + " used");
    } else if (aspect < 0.0 || !std::isfinite(aspect)) {
        rep.warnings.push_back(path + ": " + cp + ".perspective.aspectRatio " + shortNumber(aspect) +
                               " is not > 0: ignored");
    }
    if (const tinygltf::Value* x = lightcullExtras(gc.extras)) {
        double v = 0;
        if (x->Has("projection") && x->Get("projection").IsString()) {
            try {
                cam.projection = projectionKindFromString(x->Get("projection").Get<std::string>());
            } catch (const SettingsError& e) {
                throw InputError(path, cp + ".extras.lightcull.projection", 0, e.what());
            }
        }
        if (extraNumber(x, "far", v)) cam.farPlane = v;
        if (x->Has("far") && x->Get("far").IsString() && x->Get("far").Get<std::string>() == "inf")
            cam.farPlane = std::numeric_limits<double>::infinity();
        auto dim = [&](const char* key, std::uint32_t& out) {
            if (extraNumber(x, key, v) && v >= 1 && v <= 16384) out = std::uint32_t(v);
        };
        dim("width", cam.width);
        dim("height", cam.height);
        dim("tile_size", cam.tileSize);
        if (extraNumber(x, "target_distance", v) && v > 0) cam.target = cam.position + f * v;
    }
    if (std::string e = cam.validate(); !e.empty()) {
        const std::string key = e.substr(0, e.find(':'));
        throw InputError(path, cp, 0, "gives an unusable culling camera (" + e + ")");
    }
    rep.camera = cp + (gc.name.empty() ? "" : " '" + gc.name + "'") + " on " + idx("nodes", std::size_t(chosen->node));
    return cam;
}

// Whether KHR_lights_punctual.lights[i] has a `range` key (tinygltf keeps
// the root extensions' JSON beside the parsed lights).
bool rangeGiven(const tinygltf::Model& model, std::size_t i) {
    const auto ext = model.extensions.find("KHR_lights_punctual");
    if (ext == model.extensions.end() || !ext->second.IsObject() || !ext->second.Has("lights")) return false;
    const tinygltf::Value& lights = ext->second.Get("lights");
    return lights.IsArray() && i < lights.ArrayLen() && lights.Get(int(i)).IsObject() &&
           lights.Get(int(i)).Has("range");
}

std::vector<PointLight> readLights(const std::string& path, const tinygltf::Model& model,
                                   const std::vector<GltfReader::Placed>& placed, const GltfReadOptions& options,
                                   GltfReadReport& rep) {
    std::vector<PointLight> lights;
    for (const auto& p : placed) {
        const tinygltf::Node& node = model.nodes[std::size_t(p.node)];
        const auto ext = node.extensions.find("KHR_lights_punctual");
        if (ext == node.extensions.end()) continue;
        const std::string np = idx("nodes", std::size_t(p.node)) + ".extensions.KHR_lights_punctual.light";
        if (!ext->second.IsObject() || !ext->second.Has("light") || !ext->second.Get("light").IsInt())
            throw InputError(path, np, 0, "must be a light index");
        const int li = ext->second.Get("light").Get<int>();
        if (li < 0 || std::size_t(li) >= model.lights.size())
            throw InputError(path, np, 0, std::to_string(li) + " is not an index into KHR_lights_punctual.lights (" +
                                              std::to_string(model.lights.size()) + ")");
        const tinygltf::Light& gl = model.lights[std::size_t(li)];
        const std::string lp = "extensions.KHR_lights_punctual." + idx("lights", std::size_t(li));
        const std::string name = !gl.name.empty() ? gl.name : !node.name.empty() ? node.name : "light_" + std::to_string(lights.size());
        if (gl.type == "directional") {
            rep.warnings.push_back(path + ": directional light '" + name + "' (" + lp + ") skipped: it reaches every tile, so it is not culled");
            continue;
        }
        if (gl.type != "point" && gl.type != "spot") {
            rep.warnings.push_back(path + ": light '" + name + "' (" + lp + ") of unknown type '" + gl.type + "' skipped");
            continue;
        }
        PointLight l;
        l.name = name;
        l.position = glm::dvec3(p.world * glm::dvec4(0, 0, 0, 1));
        if (!gl.color.empty()) {
            if (gl.color.size() != 3) throw InputError(path, lp + ".color", 0, "must have 3 numbers");
            l.color = glm::dvec3(gl.color[0], gl.color[1], gl.color[2]);
        }
        l.intensity = gl.intensity;
        l.minIntensity = options.minIntensity;
        if (gl.range > 0.0) {
            // KHR_lights_punctual: the node's scale moves the light but leaves
            // its properties (range, intensity) as they are.
            l.explicitRadius = gl.range;
        } else if (gl.range < 0.0 || rangeGiven(model, std::size_t(li))) {
            // tinygltf reads an absent range as 0; the raw extension tells a
            // written 0 (which KHR_lights_punctual forbids) from none.
            throw InputError(path, lp + ".range", 0, "must be > 0 (leave it out for an unbounded light)");
        }
        if (gl.type == "spot") {
            l.kind = LightKind::Spot;
            l.direction = columnDir(p.world, {0, 0, -1});
            if (glm::length(l.direction) > 0.0) l.direction = glm::normalize(l.direction);
            l.outerAngleDeg = gl.spot.outerConeAngle * 180.0 / kPi;
            l.innerAngleDeg = std::min(std::max(gl.spot.innerConeAngle, 0.0) * 180.0 / kPi, l.outerAngleDeg);
            if (gl.spot.innerConeAngle > gl.spot.outerConeAngle)
                rep.warnings.push_back(path + ": " + lp + ".spot.innerConeAngle of light '" + name +
                                       "' is past its outerConeAngle: taken as the outer angle");
        }
        if (const tinygltf::Value* x = lightcullExtras(gl.extras)) {
            // Written by serializeGltf: the light's own I_min, and whether its
            // radius was explicit or the inverse-square one.
            double v = 0;
            if (extraNumber(x, "min_intensity", v) && v > 0) l.minIntensity = v;
            if (x->Has("explicit_radius") && x->Get("explicit_radius").IsBool() && !x->Get("explicit_radius").Get<bool>())
                l.explicitRadius = 0.0;
        }
        if (std::string e = l.validate(); !e.empty()) {
            static const std::pair<const char*, const char*> keys[] = {
                {"color", ".color"}, {"intensity", ".intensity"}, {"radius", ".range"}, {"outer_angle_deg", ".spot.outerConeAngle"},
                {"inner_angle_deg", ".spot.innerConeAngle"}, {"position", ""}, {"direction", ""}, {"min_intensity", ""}};
            const std::string key = e.substr(0, e.find(':'));
            std::string field = lp;
            for (const auto& [k, suffix] : keys)
                if (key == k) field += suffix;
            if (key == "position" || key == "direction") field = idx("nodes", std::size_t(p.node));
            if (key == "direction")
                throw InputError(path, field, 0, "light '" + l.name + "': its direction, the node's -Z axis, is " +
                                                     (std::isfinite(l.direction.x + l.direction.y + l.direction.z) ? "zero (a zero scale?)" : "not finite"));
            if (key == "position")
                throw InputError(path, field, 0, "light '" + l.name + "': its position, from the node's transform, is not finite");
            if (key == "min_intensity")
                throw SettingsError("min-intensity", e.substr(e.find(':') + 2));
            throw InputError(path, field, 0, "light '" + l.name + "': " + e.substr(e.find(':') + 2));
        }
        lights.push_back(std::move(l));
    }
    return lights;
}

// ---------------------------------------------------------------- writing

template <typename T>
int appendView(tinygltf::Model& m, const std::vector<T>& data, int target) {
    auto& buf = m.buffers[0].data;
    while (buf.size() % 4) buf.push_back(0);
    tinygltf::BufferView bv;
    bv.buffer = 0;
    bv.byteOffset = buf.size();
    bv.byteLength = data.size() * sizeof(T);
    bv.target = target;
    const auto* bytes = reinterpret_cast<const unsigned char*>(data.data());
    buf.insert(buf.end(), bytes, bytes + bv.byteLength);
    m.bufferViews.push_back(bv);
    return int(m.bufferViews.size() - 1);
}

// A rotation taking the local -Z axis to `dir` (and local +Y towards `up`
// where it can), as a glTF quaternion x, y, z, w.
std::vector<double> lookRotation(const glm::dvec3& dir, glm::dvec3 up) {
    const glm::dvec3 f = glm::normalize(dir);
    if (glm::length(glm::cross(f, up)) < 1e-6 * glm::length(up)) up = std::abs(f.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
    const glm::dvec3 r = glm::normalize(glm::cross(f, up));
    const glm::dvec3 u = glm::cross(r, f);
    glm::dmat3 basis(r, u, -f); // columns: local x, y, z in world space
    const glm::dquat q = glm::quat_cast(basis);
    return {q.x, q.y, q.z, q.w};
}

} // namespace

// ---------------------------------------------------------------- shared with camera_path.cpp

tinygltf::Model parseGltfModel(const std::string& path, GltfReadReport& rep) { return parseModel(path, rep); }

std::vector<GltfPlacedNode> walkGltfScene(const std::string& path, const tinygltf::Model& model) {
    GltfReadReport rep;
    return GltfReader(path, model, rep, nullptr).walkScene();
}

glm::dmat4 gltfLocalMatrix(const std::string& path, const tinygltf::Model& model, std::size_t n) {
    GltfReadReport rep;
    return GltfReader(path, model, rep, nullptr).localMatrix(n);
}

int chooseGltfCamera(const std::string& path, const tinygltf::Model& model, const std::vector<GltfPlacedNode>& placed,
                     const std::string& camera) {
    const GltfPlacedNode* chosen = chooseCamera(path, model, placed, camera);
    return chosen ? int(chosen - placed.data()) : -1;
}

bool gltfCameraPose(const glm::dmat4& world, GltfCameraPose& pose) {
    pose.position = glm::dvec3(world * glm::dvec4(0, 0, 0, 1));
    const glm::dvec3 forward = columnDir(world, {0, 0, -1}), up = columnDir(world, {0, 1, 0});
    if (!(glm::length(forward) > 0.0) || !(glm::length(up) > 0.0)) return false;
    pose.forward = glm::normalize(forward);
    pose.up = glm::normalize(up);
    return true;
}

GltfByteSpan gltfViewSpan(const std::string& path, const tinygltf::Model& model, int view, std::uint64_t offset,
                          std::uint64_t count, std::size_t elemSize, const std::string& field, const std::string& what) {
    GltfReadReport rep;
    const auto span = GltfReader(path, model, rep, nullptr).viewSpan(view, offset, count, elemSize, elemSize, field, what);
    return {span.data, span.stride};
}

// ---------------------------------------------------------------- public

bool isGltfPath(const std::string& path) {
    const std::string e = lowerExt(path);
    return e == ".gltf" || e == ".glb";
}

Mesh loadGltfMesh(const std::string& path, GltfReadReport* report, const CancelToken* cancel, const Progress& progress) {
    GltfReadReport local;
    GltfReadReport& rep = report ? *report : local;
    const tinygltf::Model model = parseModel(path, rep);
    rep.generator = model.asset.generator;
    GltfReader r(path, model, rep, cancel);
    Loaded l = readGeometry(path, model, r, rep, cancel, progress);
    if (l.mesh.indices.empty()) throw InputError(path, "", 0, "no triangles in the scene");
    if (progress) progress(1.0);
    return std::move(l.mesh);
}

Scene loadGltfScene(const std::string& path, const GltfReadOptions& options, GltfReadReport* report,
                    const CancelToken* cancel, const Progress& progress) {
    if (!std::isfinite(options.minIntensity) || !(options.minIntensity > 0.0))
        throw SettingsError("min-intensity", "must be a finite number > 0");
    GltfReadReport local;
    GltfReadReport& rep = report ? *report : local;
    const tinygltf::Model model = parseModel(path, rep);
    GltfReader r(path, model, rep, cancel);
    Loaded l = readGeometry(path, model, r, rep, cancel, progress);
    Scene s;
    s.name = fs::path(path).stem().string();
    // The scene shown (walkScene's choice) names it, as serializeGltf writes it.
    if (!model.scenes.empty()) {
        const std::size_t shown = model.defaultScene >= 0 ? std::size_t(model.defaultScene) : 0;
        if (shown < model.scenes.size() && !model.scenes[shown].name.empty()) s.name = model.scenes[shown].name;
    }
    s.camera = readCamera(path, model, l.placed, options, l.mesh, rep);
    s.lights = readLights(path, model, l.placed, options, rep);
    if (!l.mesh.indices.empty()) s.meshes.push_back(std::move(l.mesh));
    else rep.warnings.push_back(path + ": the scene has no triangles");
    if (progress) progress(1.0);
    return s;
}

std::string serializeGltf(const Scene& scene, bool binary) {
    scene.validate();
    tinygltf::Model m;
    m.asset.version = "2.0";
    m.asset.generator = kGltfGenerator;
    m.buffers.emplace_back();
    tinygltf::Scene gs;
    gs.name = scene.name;

    for (const Mesh& mesh : scene.meshes) {
        if (mesh.indices.empty()) continue;
        tinygltf::Accessor pos;
        pos.bufferView = appendView(m, mesh.positions, TINYGLTF_TARGET_ARRAY_BUFFER);
        pos.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
        pos.type = TINYGLTF_TYPE_VEC3;
        pos.count = mesh.vertexCount();
        pos.minValues = {std::numeric_limits<double>::max(), std::numeric_limits<double>::max(), std::numeric_limits<double>::max()};
        pos.maxValues = {-std::numeric_limits<double>::max(), -std::numeric_limits<double>::max(), -std::numeric_limits<double>::max()};
        for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
            pos.minValues[v % 3] = std::min(pos.minValues[v % 3], double(mesh.positions[v]));
            pos.maxValues[v % 3] = std::max(pos.maxValues[v % 3], double(mesh.positions[v]));
        }
        m.accessors.push_back(pos);
        tinygltf::Accessor ind;
        ind.bufferView = appendView(m, mesh.indices, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
        ind.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
        ind.type = TINYGLTF_TYPE_SCALAR;
        ind.count = mesh.indices.size();
        m.accessors.push_back(ind);
        tinygltf::Primitive prim;
        prim.attributes["POSITION"] = int(m.accessors.size() - 2);
        prim.indices = int(m.accessors.size() - 1);
        prim.mode = TINYGLTF_MODE_TRIANGLES;
        tinygltf::Mesh gm;
        gm.name = mesh.name;
        gm.primitives.push_back(prim);
        m.meshes.push_back(gm);
        tinygltf::Node node;
        node.name = mesh.name;
        node.mesh = int(m.meshes.size() - 1);
        if (mesh.transform != glm::dmat4(1.0))
            for (int k = 0; k < 16; ++k) node.matrix.push_back(mesh.transform[k / 4][k % 4]);
        m.nodes.push_back(node);
        gs.nodes.push_back(int(m.nodes.size() - 1));
    }

    for (const PointLight& l : scene.lights) {
        tinygltf::Light gl;
        gl.name = l.name;
        gl.type = l.isSpot() ? "spot" : "point";
        gl.color = {l.color.r, l.color.g, l.color.b};
        gl.intensity = l.intensity;
        gl.range = l.radius();
        if (l.isSpot()) {
            gl.spot.outerConeAngle = l.outerAngleDeg * kPi / 180.0;
            gl.spot.innerConeAngle = std::min(l.innerAngleDeg, l.outerAngleDeg) * kPi / 180.0;
        }
        tinygltf::Value::Object x;
        x["min_intensity"] = tinygltf::Value(l.minIntensity);
        x["explicit_radius"] = tinygltf::Value(l.explicitRadius > 0.0);
        // KHR_lights_punctual asks for inner < outer: a hard-edged spot's inner
        // angle is written one double inside (read back within 1e-14 of it).
        if (l.isSpot() && gl.spot.innerConeAngle >= gl.spot.outerConeAngle)
            gl.spot.innerConeAngle = std::nextafter(gl.spot.outerConeAngle, 0.0);
        tinygltf::Value::Object extras;
        extras["lightcull"] = tinygltf::Value(x);
        gl.extras = tinygltf::Value(extras);
        m.lights.push_back(gl);
        tinygltf::Node node;
        node.name = l.name;
        node.translation = {l.position.x, l.position.y, l.position.z};
        if (l.isSpot()) node.rotation = lookRotation(l.direction, {0, 1, 0});
        tinygltf::Value::Object ref;
        ref["light"] = tinygltf::Value(int(m.lights.size() - 1));
        node.extensions["KHR_lights_punctual"] = tinygltf::Value(ref);
        m.nodes.push_back(node);
        gs.nodes.push_back(int(m.nodes.size() - 1));
    }
    if (!scene.lights.empty()) m.extensionsUsed.push_back("KHR_lights_punctual");

    const Camera& c = scene.camera;
    tinygltf::Camera gc;
    gc.name = "culling camera";
    if (isOrthographic(c.projection)) {
        gc.type = "orthographic";
        gc.orthographic.ymag = c.orthoHeight / 2.0;
        gc.orthographic.xmag = gc.orthographic.ymag * c.aspect();
        gc.orthographic.znear = c.nearPlane;
        gc.orthographic.zfar = c.farPlane;
    } else {
        gc.type = "perspective";
        gc.perspective.yfov = c.fovYDeg * kPi / 180.0;
        gc.perspective.znear = c.nearPlane;
        gc.perspective.zfar = std::isinf(c.farPlane) ? 0.0 : c.farPlane; // 0: tinygltf omits zfar (infinite)
        gc.perspective.aspectRatio = c.aspect();
    }
    tinygltf::Value::Object cx;
    cx["projection"] = tinygltf::Value(std::string(toString(c.projection)));
    cx["width"] = tinygltf::Value(int(c.width));
    cx["height"] = tinygltf::Value(int(c.height));
    cx["tile_size"] = tinygltf::Value(int(c.tileSize));
    cx["target_distance"] = tinygltf::Value(glm::length(c.target - c.position));
    if (std::isinf(c.farPlane)) cx["far"] = tinygltf::Value(std::string("inf"));
    else cx["far"] = tinygltf::Value(c.farPlane);
    tinygltf::Value::Object cextras;
    cextras["lightcull"] = tinygltf::Value(cx);
    gc.extras = tinygltf::Value(cextras);
    m.cameras.push_back(gc);
    tinygltf::Node camNode;
    camNode.name = "culling camera";
    camNode.camera = 0;
    camNode.translation = {c.position.x, c.position.y, c.position.z};
    camNode.rotation = lookRotation(c.target - c.position, c.up);
    m.nodes.push_back(camNode);
    gs.nodes.push_back(int(m.nodes.size() - 1));

    m.scenes.push_back(gs);
    m.defaultScene = 0;
    if (m.buffers[0].data.empty()) m.buffers.clear();
    else m.buffers[0].data.resize((m.buffers[0].data.size() + 3) / 4 * 4, 0);

    tinygltf::TinyGLTF writer;
    std::ostringstream out;
    if (!writer.WriteGltfSceneToStream(&m, out, !binary, binary))
        throw Error("cannot serialise the scene as glTF");
    return out.str();
}

void saveGltfScene(const Scene& scene, const std::string& path) {
    const std::string bytes = serializeGltf(scene, lowerExt(path) == ".glb");
    try {
        writeFileAtomic(path, bytes);
    } catch (const Error& e) {
        throw InputError(path, "", 0, e.what());
    }
}

Scene loadSceneAny(const std::string& path, const GltfReadOptions& options, GltfReadReport* report,
                   const CancelToken* cancel, const Progress& progress) {
    GltfReadReport local;
    GltfReadReport& rep = report ? *report : local;
    // A mesh file where a scene is asked for: say so, not a JSON syntax
    // error at its first line.
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    for (const char* mesh : {".obj", ".ply", ".off", ".stl", ".om"})
        if (ext == mesh)
            throw InputError(path, "", 0,
                             "a mesh (" + ext.substr(1) + "), not a scene: open a scene JSON, .gltf or .glb, and "
                             "import the mesh into it (the studio's File > Import mesh..., or the scene JSON's "
                             "\"meshes\")");
    Scene s = isGltfPath(path) ? loadGltfScene(path, options, &rep, cancel, progress)
                               : loadSceneFile(path, cancel, progress, &rep.warnings);
    s.origin = {};
    s.origin.file = std::filesystem::absolute(path).lexically_normal().string();
    s.origin.contentHash = fileHashFnv1a64(path);
    if (isGltfPath(path)) {
        s.origin.gltfCamera = rep.camera;
        s.origin.gltfMinIntensity = options.minIntensity;
        s.origin.foreignGltf = rep.generator != kGltfGenerator;
        if (std::string w = cutoffCoverageWarning(s); !w.empty()) rep.warnings.push_back(path + ": " + w);
    }
    return s;
}

std::vector<std::size_t> gltfCutoffLights(const Scene& scene) {
    std::vector<std::size_t> out;
    const double lux = scene.origin.gltfMinIntensity;
    if (!(lux > 0)) return out;
    for (std::size_t i = 0; i < scene.lights.size(); ++i)
        if (scene.lights[i].explicitRadius == 0.0 && scene.lights[i].minIntensity == lux) out.push_back(i);
    return out;
}

std::string cutoffCoverageWarning(const Scene& scene) {
    const std::vector<std::size_t> cut = gltfCutoffLights(scene);
    if (cut.empty() || scene.meshes.empty()) return {};
    const auto [lo, hi] = scene.bounds();
    const double across = glm::length(hi - lo);
    if (!(across > 0)) return {};
    std::size_t wide = 0;
    double largest = 0;
    for (std::size_t i : cut) {
        if (!scene.lights[i].validate().empty()) continue;
        const double r = scene.lights[i].radius();
        largest = std::max(largest, r);
        wide += r > across;
    }
    if (wide == 0) return {};
    char buf[512];
    std::snprintf(buf, sizeof buf,
                  "%zu of the %zu lights without a range reach farther than the scene is wide (radius up to %.3g at "
                  "I_min %g lux; the scene is %.3g across): each lands in every list near it; raise the cut-off "
                  "(--min-intensity, File > glTF light cut-off) or give the lights a range",
                  wide, cut.size(), largest, scene.origin.gltfMinIntensity, across);
    return buf;
}

void saveSceneAny(const Scene& scene, const std::string& path) {
    if (isGltfPath(path)) saveGltfScene(scene, path);
    else saveSceneFile(scene, path);
}

Camera frameBounds(const glm::dvec3& lo, const glm::dvec3& hi, const Camera& base) {
    Camera c = base;
    const glm::dvec3 centre = (lo + hi) * 0.5;
    // The camera's offset from the centre must survive rounding: far from the
    // origin (a mesh at 1e20) a small radius vanished in centre + offset and
    // the camera sat on its target, an invalid camera from a reader (found by
    // fuzz_scene_json and fuzz_gltf). 1e-9 of the centre's largest coordinate
    // keeps the offset ~1e6 ulps clear; nearer the origin it is below 1e-3.
    const double reach = std::max({std::abs(centre.x), std::abs(centre.y), std::abs(centre.z)});
    const double radius = std::max({0.5 * glm::length(hi - lo), 1e-3, 1e-9 * reach});
    // From the front (+Z), a little above, as a person first looks at a model.
    const glm::dvec3 dir = glm::normalize(glm::dvec3(0.0, 0.45, 1.0));
    double distance;
    if (isOrthographic(c.projection)) {
        c.orthoHeight = 2.2 * radius;
        distance = 2.0 * radius;
    } else {
        const double halfY = 0.5 * c.fovYDeg * kPi / 180.0;
        const double halfFov = std::min(halfY, std::atan(std::tan(halfY) * c.aspect())); // the narrower of the two
        distance = 1.1 * radius / std::sin(halfFov);
    }
    c.position = centre + dir * distance;
    c.target = centre;
    c.up = {0.0, 1.0, 0.0};
    c.nearPlane = std::max(distance - 1.5 * radius, 1e-3 * distance);
    if (!std::isinf(c.farPlane)) c.farPlane = distance + 1.5 * radius;
    return c;
}

} // namespace lc
