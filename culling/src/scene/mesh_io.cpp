// Mesh loading: the project's own readers for OBJ (parseObj below), PLY
// (mesh_ply.cpp) and OFF (mesh_off.cpp), and OpenMesh's readers for STL and
// OM, all feeding a flat importer. We do not read into an OpenMesh
// TriMesh/PolyMesh: their halfedge kernel rejects or splits non-manifold faces
// ("complex edge", duplicated vertices) and silently drops repeated-index
// faces, which would lose triangles a depth pre-pass must draw. The flat
// importer keeps every face as written, and we triangulate, validate and drop
// degenerates ourselves so that every dropped face is counted.
//
// OBJ has its own parser: OpenMesh 9's OBJ reader cannot read through a
// non-seekable stream, parses with iostreams that reject "nan"/"inf" (so a
// NaN vertex silently shifts every later index instead of being reported),
// and cannot say which line was bad. The parser below uses std::from_chars,
// reports the line of every error, and reads buildings.obj (13 MB, 400k
// faces) in a fraction of a second (see the test's printed timing).
//
// PLY and OFF have their own readers because OpenMesh 9's loop forever, crash
// or allocate gigabytes on malformed input (docs/TESTING.md lists the fuzz
// findings); hand-written checks run before them kept missing cases.

#include "scene/mesh_readers.hpp"

#include "culling/core/errors.hpp"
#include "culling/scene/gltf_io.hpp"
#include "culling/scene/scene_io.hpp"

#include <OpenMesh/Core/IO/IOManager.hh>
#include <OpenMesh/Core/IO/importer/BaseImporter.hh>
#include <OpenMesh/Core/System/omstream.hh>

#include <algorithm>
#include <charconv>
#include <cstring>
#include <limits>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>

namespace lc {

namespace {

namespace OM = OpenMesh;

// Collects vertices and polygons as written. Everything else a reader offers
// (normals, colours, texture coordinates) is ignored: depth and culling need
// positions only.
class FlatImporter final : public OM::IO::BaseImporter, public meshio::FlatMesh {
public:
    // Set for OpenMesh reads: checked every 64k faces. Progress needs the face
    // count that OM announces through reserve(); STL reports none.
    const CancelToken* cancel = nullptr;
    const Progress* progress = nullptr;
    std::size_t expectedFaces = 0;

    OM::VertexHandle add_vertex(const OM::Vec3f& p) override {
        positions.insert(positions.end(), {p[0], p[1], p[2]});
        return OM::VertexHandle(int(positions.size() / 3 - 1));
    }
    OM::VertexHandle add_vertex(const OM::Vec3d& p) override {
        return add_vertex(OM::Vec3f(float(p[0]), float(p[1]), float(p[2])));
    }
    OM::VertexHandle add_vertex() override { return add_vertex(OM::Vec3f(0.f, 0.f, 0.f)); }
    OM::HalfedgeHandle add_edge(OM::VertexHandle, OM::VertexHandle) override { return OM::HalfedgeHandle(); }
    OM::FaceHandle add_face(const VHandles& vs) override {
        polyStart.push_back(std::uint32_t(polyIndices.size()));
        for (const auto& v : vs) polyIndices.push_back(v.idx());
        if ((polyStart.size() & 0xFFFF) == 0) {
            // Throwing through OpenMesh's reader is safe: it is plain C++
            // with RAII streams; the caller drops the partial importer.
            if (cancel) cancel->throwIfCancelled();
            if (progress && *progress && expectedFaces > 0)
                (*progress)(0.9 * std::min(1.0, double(polyStart.size()) / double(expectedFaces)));
        }
        return OM::FaceHandle(int(polyStart.size() - 1));
    }
    OM::FaceHandle add_face(OM::HalfedgeHandle) override { return OM::FaceHandle(); }

    void add_face_texcoords(OM::FaceHandle, OM::VertexHandle, const std::vector<OM::Vec2f>&) override {}
    void add_face_texcoords(OM::FaceHandle, OM::VertexHandle, const std::vector<OM::Vec3f>&) override {}
    void set_face_texindex(OM::FaceHandle, int) override {}
    void set_point(OM::VertexHandle vh, const OM::Vec3f& p) override {
        if (vh.idx() >= 0 && std::size_t(vh.idx()) < positions.size() / 3)
            std::copy(p.data(), p.data() + 3, positions.begin() + 3 * vh.idx());
    }
    void set_halfedge(OM::VertexHandle, OM::HalfedgeHandle) override {}
    void set_normal(OM::VertexHandle, const OM::Vec3f&) override {}
    void set_normal(OM::VertexHandle, const OM::Vec3d&) override {}
    void set_color(OM::VertexHandle, const OM::Vec3uc&) override {}
    void set_color(OM::VertexHandle, const OM::Vec4uc&) override {}
    void set_color(OM::VertexHandle, const OM::Vec3f&) override {}
    void set_color(OM::VertexHandle, const OM::Vec4f&) override {}
    void set_texcoord(OM::VertexHandle, const OM::Vec2f&) override {}
    void set_status(OM::VertexHandle, const OM::Attributes::StatusInfo&) override {}
    void set_next(OM::HalfedgeHandle, OM::HalfedgeHandle) override {}
    void set_face(OM::HalfedgeHandle, OM::FaceHandle) override {}
    void request_face_texcoords2D() override {}
    void set_texcoord(OM::HalfedgeHandle, const OM::Vec2f&) override {}
    void set_texcoord(OM::VertexHandle, const OM::Vec3f&) override {}
    void set_texcoord(OM::HalfedgeHandle, const OM::Vec3f&) override {}
    void set_status(OM::HalfedgeHandle, const OM::Attributes::StatusInfo&) override {}
    void set_color(OM::EdgeHandle, const OM::Vec3uc&) override {}
    void set_color(OM::EdgeHandle, const OM::Vec4uc&) override {}
    void set_color(OM::EdgeHandle, const OM::Vec3f&) override {}
    void set_color(OM::EdgeHandle, const OM::Vec4f&) override {}
    void set_status(OM::EdgeHandle, const OM::Attributes::StatusInfo&) override {}
    void set_normal(OM::FaceHandle, const OM::Vec3f&) override {}
    void set_normal(OM::FaceHandle, const OM::Vec3d&) override {}
    void set_color(OM::FaceHandle, const OM::Vec3uc&) override {}
    void set_color(OM::FaceHandle, const OM::Vec4uc&) override {}
    void set_color(OM::FaceHandle, const OM::Vec3f&) override {}
    void set_color(OM::FaceHandle, const OM::Vec4f&) override {}
    void set_status(OM::FaceHandle, const OM::Attributes::StatusInfo&) override {}
    void add_texture_information(int, std::string) override {}

    // The counts come from the file's header, unchecked: a 31-byte file can
    // announce billions of elements. Every vertex and face takes at least
    // 4 bytes of the file (binary or ASCII), so reservations stop there.
    std::uint64_t fileSize = 0;
    void reserve(unsigned nV, unsigned, unsigned nF) override {
        const std::uint64_t most = fileSize / 4 + 1;
        positions.reserve(std::size_t(std::min<std::uint64_t>(nV, most)) * 3);
        polyStart.reserve(std::size_t(std::min<std::uint64_t>(nF, most)));
        polyIndices.reserve(std::size_t(std::min<std::uint64_t>(nF, most)) * 3);
        expectedFaces = nF;
    }
    std::size_t n_vertices() const override { return positions.size() / 3; }
    std::size_t n_faces() const override { return polyStart.size(); }
    std::size_t n_edges() const override { return 0; }
};

// OpenMesh writes diagnostics to its global omerr/omlog streams (connected to
// std::cerr/std::clog). While a read runs we route them into a string so the
// text can go into the exception; the mutex serialises reads because those
// streams are process-wide.
std::mutex gOpenMeshMutex;

class CaptureOpenMeshLog {
public:
    CaptureOpenMeshLog() {
        errToCerr_ = ::omerr().disconnect(std::cerr);
        logToClog_ = ::omlog().disconnect(std::clog);
        outToCout_ = ::omout().disconnect(std::cout);
        ::omerr().connect(text_);
        ::omlog().connect(sink_);
        ::omout().connect(sink_);
    }
    ~CaptureOpenMeshLog() {
        ::omerr().flush();
        ::omerr().disconnect(text_);
        ::omlog().disconnect(sink_);
        ::omout().disconnect(sink_);
        if (errToCerr_) ::omerr().connect(std::cerr);
        if (logToClog_) ::omlog().connect(std::clog);
        if (outToCout_) ::omout().connect(std::cout);
    }
    std::string text() {
        ::omerr().flush();
        std::string s = text_.str();
        while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
        return s;
    }

private:
    std::ostringstream text_, sink_;
    bool errToCerr_ = false, logToClog_ = false, outToCout_ = false;
};

std::string lowerExtension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    if (!ext.empty() && ext[0] == '.') ext.erase(0, 1);
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

// Parses Wavefront OBJ: "v x y z [w]" and "f i j k ..." (each corner "v",
// "v/t", "v//n" or "v/t/n"; negative indices count back from the latest
// vertex). Every other statement (vn, vt, o, g, s, usemtl, mtllib, l, p,
// comments) is ignored. Errors carry the 1-based line. The file is read in
// 1 MiB chunks; progress and cancellation are checked between chunks.
void parseObj(const std::string& path, std::uint64_t size, FlatImporter& out,
              const CancelToken* cancel, const Progress& progress) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path, "", 0, "cannot open file for reading");
    std::string carry;
    std::vector<char> chunk(1 << 20);
    std::uint64_t consumed = 0;
    int line = 0;

    auto skipSpace = [](const char*& p, const char* e) {
        while (p < e && (*p == ' ' || *p == '\t' || *p == '\r')) ++p;
    };
    auto parseLine = [&](const char* p, const char* e) {
        ++line;
        skipSpace(p, e);
        if (p + 1 >= e) return;
        if (p[0] == 'v' && (p[1] == ' ' || p[1] == '\t')) {
            p += 2;
            double xyz[3];
            for (int k = 0; k < 3; ++k) {
                skipSpace(p, e);
                if (p < e && *p == '+') ++p;  // from_chars rejects a leading '+'
                auto r = std::from_chars(p, e, xyz[k]);
                if (r.ec == std::errc::result_out_of_range) {
                    throw InputError(path, "", line, "vertex coordinate out of range");
                }
                if (r.ec != std::errc()) {
                    throw InputError(path, "", line,
                                     "vertex needs three numeric coordinates");
                }
                p = r.ptr;
                if (!std::isfinite(xyz[k]) || std::abs(xyz[k]) > std::numeric_limits<float>::max())
                    throw InputError(path, "", line,
                                     "vertex " + std::to_string(out.n_vertices()) +
                                         " has a non-finite coordinate");
            }
            out.positions.insert(out.positions.end(), {float(xyz[0]), float(xyz[1]), float(xyz[2])});
        } else if (p[0] == 'f' && (p[1] == ' ' || p[1] == '\t')) {
            p += 2;
            out.polyStart.push_back(std::uint32_t(out.polyIndices.size()));
            const auto nv = std::int64_t(out.n_vertices());
            while (true) {
                skipSpace(p, e);
                if (p >= e) break;
                std::int64_t v = 0;
                auto r = std::from_chars(p, e, v);
                if (r.ec != std::errc())
                    throw InputError(path, "", line, "face corner is not a vertex index");
                p = r.ptr;
                while (p < e && *p != ' ' && *p != '\t' && *p != '\r') ++p;  // skip /t/n
                // OBJ indices are 1-based; negative ones are relative to the
                // vertices read so far. Index 0 is invalid.
                const std::int64_t idx = v > 0 ? v - 1 : nv + v;
                if (v == 0 || idx < 0 || idx >= nv)
                    throw InputError(path, "", line,
                                     "face refers to vertex " + std::to_string(v) + " but only " +
                                         std::to_string(nv) + " vertices are defined before it");
                out.polyIndices.push_back(idx);
            }
        }
    };

    while (in) {
        if (cancel) cancel->throwIfCancelled();
        in.read(chunk.data(), std::streamsize(chunk.size()));
        const std::streamsize n = in.gcount();
        if (n <= 0) break;
        consumed += std::uint64_t(n);
        const char* b = chunk.data();
        const char* e = b + n;
        const char* nl;
        while ((nl = static_cast<const char*>(std::memchr(b, '\n', std::size_t(e - b))))) {
            if (!carry.empty()) {
                carry.append(b, nl);
                parseLine(carry.data(), carry.data() + carry.size());
                carry.clear();
            } else {
                parseLine(b, nl);
            }
            b = nl + 1;
        }
        carry.append(b, e);
        if (progress && size > 0) progress(0.9 * double(consumed) / double(size));
    }
    if (!carry.empty()) parseLine(carry.data(), carry.data() + carry.size());
}

// Twice the triangle's area, computed in double from the float positions.
// A face is zero-area when this is exactly 0: the three points are collinear
// in float (or two coincide). A tolerance would drop legitimate slivers that
// still cover pixels at some zoom.
double doubleArea(const std::vector<float>& p, std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    const glm::dvec3 A(p[3 * a], p[3 * a + 1], p[3 * a + 2]);
    const glm::dvec3 B(p[3 * b], p[3 * b + 1], p[3 * b + 2]);
    const glm::dvec3 C(p[3 * c], p[3 * c + 1], p[3 * c + 2]);
    return glm::length(glm::cross(B - A, C - A));
}

// OpenMesh parses ASCII numbers with iostreams, which reject "nan" and "inf":
// the stream fails and later values come out shifted or zero, so the damage
// shows up as a misleading error (or none). ASCII STL is therefore scanned
// first for such tokens, to name the real problem and line.
bool isAsciiForNonFiniteScan(const std::string& ext, const std::string& head, std::uint64_t size) {
    if (ext == "stl") {
        // Binary STL: 80-byte header, uint32 count, 50 bytes per triangle.
        if (head.size() >= 84) {
            std::uint32_t n;
            std::memcpy(&n, head.data() + 80, 4);
            if (84 + 50 * std::uint64_t(n) == size) return false;
        }
        return head.rfind("solid", 0) == 0;
    }
    return false;
}

void scanAsciiForNonFinite(const std::string& path, const std::string& ext, std::uint64_t size) {
    std::ifstream in(path, std::ios::binary);
    std::string head(512, '\0');
    in.read(head.data(), std::streamsize(head.size()));
    head.resize(std::size_t(in.gcount()));
    if (!isAsciiForNonFiniteScan(ext, head, size)) return;
    in.clear();
    in.seekg(0);
    std::string text;
    int line = 0;
    while (std::getline(in, text)) {
        ++line;
        std::istringstream tokens(text);
        std::string t;
        while (tokens >> t) {
            std::string low;
            for (char c : t)
                if (c != '+' && c != '-') low += char(std::tolower(static_cast<unsigned char>(c)));
            if (low == "nan" || low == "inf" || low == "infinity" || low.rfind("nan(", 0) == 0)
                throw InputError(path, "", line, "non-finite coordinate '" + t + "'");
        }
    }
}

// STL and OM through OpenMesh's readers into the flat importer.
void readWithOpenMesh(const std::string& path, const std::string& ext, std::uint64_t size,
                      FlatImporter& imp, const CancelToken* cancel, const Progress& progress) {
    scanAsciiForNonFinite(path, ext, size);
    imp.fileSize = size;
    imp.cancel = cancel;
    imp.progress = &progress;
    bool ok = false;
    std::string omText;
    {
        std::lock_guard<std::mutex> lock(gOpenMeshMutex);
        CaptureOpenMeshLog capture;
        OM::IO::Options opt;  // the readers detect binary/ASCII from the file
        try {
            ok = OM::IO::IOManager().read(path, imp, opt);
        } catch (const Cancelled&) {
            throw;
        } catch (const std::bad_alloc&) {
            // A corrupt header announcing billions of elements.
            ok = false;
            omText = "element counts in the header are impossible";
        } catch (const std::exception& e) {
            ok = false;
            omText = e.what();
        }
        if (omText.empty()) omText = capture.text();
    }
    if (!ok) {
        throw InputError(path, "", 0,
                         "OpenMesh could not read the " + ext + " file" +
                             (omText.empty() ? std::string() : " (" + omText + ")"));
    }
}

} // namespace

namespace meshio {

void ReadContext::tick(std::size_t offset, std::size_t size) const {
    if (cancel) cancel->throwIfCancelled();
    if (progress && *progress && size > 0) (*progress)(0.9 * double(offset) / double(size));
}

std::string readFileBytes(const std::string& path, std::uint64_t size, const CancelToken* cancel) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path, "", 0, "cannot open file for reading");
    // One allocation of the file's size (from stat); a file that shrank
    // since is cut to what was read, one that grew is read to that size.
    std::string bytes(std::size_t(size), '\0');
    std::size_t got = 0;
    while (got < bytes.size() && in) {
        if (cancel) cancel->throwIfCancelled();
        const std::size_t want = std::min<std::size_t>(bytes.size() - got, std::size_t(1) << 20);
        in.read(bytes.data() + got, std::streamsize(want));
        got += std::size_t(in.gcount());
    }
    if (in.bad()) throw InputError(path, "", 0, "read error");
    bytes.resize(got);
    return bytes;
}

namespace {
std::string_view withoutPlus(std::string_view t) {
    if (!t.empty() && t[0] == '+') t.remove_prefix(1);  // from_chars rejects a leading '+'
    return t;
}
} // namespace

bool parseNumber(std::string_view token, double& value) {
    const std::string_view t = withoutPlus(token);
    if (t.empty()) return false;
    const auto r = std::from_chars(t.data(), t.data() + t.size(), value);
    if (r.ptr != t.data() + t.size()) return false;
    if (r.ec == std::errc::result_out_of_range) {
        // Underflow (1e-400) reads as the nearest value, as strtod gives it;
        // overflow comes back as +-HUGE_VAL, which callers refuse as non-finite.
        value = std::strtod(std::string(t).c_str(), nullptr);
        return true;
    }
    return r.ec == std::errc();
}

bool parseFloat(std::string_view token, float& value) {
    const std::string_view t = withoutPlus(token);
    if (t.empty()) return false;
    const auto r = std::from_chars(t.data(), t.data() + t.size(), value);
    if (r.ptr != t.data() + t.size()) return false;
    if (r.ec == std::errc::result_out_of_range) {
        const double d = std::strtod(std::string(t).c_str(), nullptr);
        value = std::abs(d) > double(std::numeric_limits<float>::max()) ? std::copysign(HUGE_VALF, float(d))
                                                                       : float(d);
        return true;
    }
    return r.ec == std::errc();
}

bool parseInteger(std::string_view token, std::int64_t& value) {
    const std::string_view t = withoutPlus(token);
    if (t.empty()) return false;
    const auto r = std::from_chars(t.data(), t.data() + t.size(), value);
    return r.ec == std::errc() && r.ptr == t.data() + t.size();
}

std::string quoted(std::string_view text) {
    constexpr std::size_t kMost = 80;
    if (text.size() <= kMost) return "'" + std::string(text) + "'";
    return "'" + std::string(text.substr(0, kMost)) + "...'";
}

} // namespace meshio

Mesh loadMesh(const std::string& path, MeshLoadReport* report, const CancelToken* cancel,
              const Progress& progress) {
    namespace fs = std::filesystem;
    const std::string ext = lowerExtension(path);
    static const char* kFormats[] = {"obj", "ply", "off", "stl", "om", "gltf", "glb"};
    if (std::find(std::begin(kFormats), std::end(kFormats), ext) == std::end(kFormats))
        throw InputError(path, "", 0,
                         "unsupported mesh format '" + ext + "' (use obj, ply, off, stl, om, gltf or glb)");
    if (ext == "gltf" || ext == "glb") {
        // The geometry of the file's default scene, flattened to world space.
        GltfReadReport gr;
        Mesh m = loadGltfMesh(path, &gr, cancel, progress);
        if (report) {
            *report = MeshLoadReport{};
            report->degenerateFacesDropped = gr.degenerateTrianglesDropped;
            for (const std::string& w : gr.warnings) report->warning += (report->warning.empty() ? "" : "\n") + w;
        }
        return m;
    }

    std::error_code ec;
    if (!fs::exists(path, ec)) throw InputError(path, "", 0, "file not found");
    if (fs::is_directory(path, ec)) throw InputError(path, "", 0, "is a folder, not a mesh file");
    const std::uint64_t size = fs::file_size(path, ec);
    if (ec) throw InputError(path, "", 0, "cannot read file: " + ec.message());
    if (size == 0) throw InputError(path, "", 0, "empty file");

    FlatImporter imp;
    if (ext == "obj") {
        parseObj(path, size, imp, cancel, progress);
    } else if (ext == "ply" || ext == "off") {
        const std::string bytes = meshio::readFileBytes(path, size, cancel);
        const meshio::ReadContext ctx{path, cancel, &progress};
        if (ext == "ply") {
            meshio::readPly(bytes, ctx, imp);
        } else {
            meshio::readOff(bytes, ctx, imp);
        }
    } else {
        readWithOpenMesh(path, ext, size, imp, cancel, progress);
    }

    if (imp.positions.empty() || imp.polyStart.empty())
        throw InputError(path, "", 0, "no triangles in file (empty or not a mesh)");

    const std::size_t nv = imp.positions.size() / 3;
    for (std::size_t i = 0; i < imp.positions.size(); ++i) {
        if (!std::isfinite(imp.positions[i])) {
            throw InputError(path, "", 0,
                             "vertex " + std::to_string(i / 3) + " has a non-finite coordinate");
        }
    }
    if (cancel) cancel->throwIfCancelled();

    Mesh mesh;
    mesh.name = fs::path(path).stem().string();
    mesh.sourcePath = path;
    mesh.resolvedPath = fs::absolute(fs::path(path)).lexically_normal().string();
    mesh.positions = std::move(imp.positions);
    mesh.indices.reserve(imp.polyIndices.size());

    MeshLoadReport rep;
    const std::size_t nf = imp.polyStart.size();
    for (std::size_t f = 0; f < nf; ++f) {
        const std::size_t b = imp.polyStart[f];
        const std::size_t e = f + 1 < nf ? imp.polyStart[f + 1] : imp.polyIndices.size();
        for (std::size_t k = b; k < e; ++k) {
            const std::int64_t v = imp.polyIndices[k];
            if (v < 0 || std::size_t(v) >= nv) {
                throw InputError(path, "", 0,
                                 "face " + std::to_string(f) + " refers to vertex " +
                                     std::to_string(v) + ", outside 0.." + std::to_string(nv - 1));
            }
        }
        const std::size_t n = e - b;
        if (n < 3) {
            ++rep.degenerateFacesDropped;
            continue;
        }
        if (n > 3) ++rep.polygonsTriangulated;
        // Fan triangulation around the first corner (what OpenMesh's TriMesh
        // does); each fan triangle is checked on its own.
        for (std::size_t k = 1; k + 1 < n; ++k) {
            const auto a = std::uint32_t(imp.polyIndices[b]);
            const auto c1 = std::uint32_t(imp.polyIndices[b + k]);
            const auto c2 = std::uint32_t(imp.polyIndices[b + k + 1]);
            if (a == c1 || a == c2 || c1 == c2 || doubleArea(mesh.positions, a, c1, c2) == 0.0) {
                ++rep.degenerateFacesDropped;
                continue;
            }
            mesh.indices.insert(mesh.indices.end(), {a, c1, c2});
        }
        if (cancel && (f & 0xFFFF) == 0) cancel->throwIfCancelled();
    }
    if (mesh.indices.empty())
        throw InputError(path, "", 0, "every face is degenerate; nothing to draw");
    if (rep.degenerateFacesDropped > 0) {
        rep.warning = path + ": dropped " + std::to_string(rep.degenerateFacesDropped) +
                      " degenerate face(s) (zero area or repeated vertex)";
    }
    if (report) *report = rep;
    if (progress) progress(1.0);
    return mesh;
}

} // namespace lc
