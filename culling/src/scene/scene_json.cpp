// The scene JSON format (docs/FORMATS.md): reading with field paths and line
// numbers in every error, lossless writing, atomic saving.
//
// nlohmann's DOM does not remember where a value was, so the text is parsed
// with a SAX handler that builds the DOM (through nlohmann's own DOM builder)
// and, on the side, records the line of every value by its field path
// ("lights[3].intensity"). The line comes from the input iterator: it tracks
// the line of the last non-whitespace character the lexer consumed, which is
// the last character of the token just reported (the lexer's one-character
// look-ahead after a number is whitespace or punctuation on the same line, and
// whitespace does not move the mark).

#include "culling/core/errors.hpp"
#include "culling/scene/scene_io.hpp"
#include "culling/scene/gltf_io.hpp"
#include "culling/core/file_io.hpp"
#include "scene/json_nesting.hpp"
#include "scene/scene_json_reader.hpp"

#include <nlohmann/json.hpp>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

namespace lc {

namespace fs = std::filesystem;

namespace scene_json {
namespace {

// ------------------------------------------------------------ line tracking

struct LineState {
    int nextLine = 1;   // line of the next character to be read
    int tokenLine = 1;  // line of the last non-whitespace character read
};

// A forward iterator over the text that updates LineState as the lexer reads.
// nlohmann's iterator adapter dereferences each position exactly once.
class LineCountingIterator {
public:
    using iterator_category = std::forward_iterator_tag;
    using value_type = char;
    using difference_type = std::ptrdiff_t;
    using pointer = const char*;
    using reference = const char&;

    LineCountingIterator() = default;
    LineCountingIterator(const char* p, LineState* s) : p_(p), s_(s) {}
    reference operator*() const {
        const char c = *p_;
        if (c == '\n') {
            ++s_->nextLine;
        } else if (c != ' ' && c != '\t' && c != '\r') {
            s_->tokenLine = s_->nextLine;
        }
        return *p_;
    }
    LineCountingIterator& operator++() {
        ++p_;
        return *this;
    }
    LineCountingIterator operator++(int) {
        auto t = *this;
        ++p_;
        return t;
    }
    bool operator==(const LineCountingIterator& o) const { return p_ == o.p_; }
    bool operator!=(const LineCountingIterator& o) const { return p_ != o.p_; }

private:
    const char* p_ = nullptr;
    LineState* s_ = nullptr;
};

// Builds the DOM through nlohmann's DOM parser and records the line of every
// value. Duplicate keys are an error (nlohmann would silently keep the last).
class LineSax {
public:
    LineSax(json& root, LineState& ls, LineMap& lines, const std::string& file)
        : dom_(root, true), ls_(ls), lines_(lines), file_(file) {}

    bool null() { return value() && dom_.null(); }
    bool boolean(bool v) { return value() && dom_.boolean(v); }
    bool number_integer(json::number_integer_t v) { return value() && dom_.number_integer(v); }
    bool number_unsigned(json::number_unsigned_t v) { return value() && dom_.number_unsigned(v); }
    bool number_float(json::number_float_t v, const std::string& s) {
        return value() && dom_.number_float(v, s);
    }
    bool string(std::string& v) { return value() && dom_.string(v); }
    bool binary(json::binary_t& v) { return value() && dom_.binary(v); }

    bool start_object(std::size_t n) {
        std::string path = currentPath();  // before value() advances an array index
        value();
        frames_.push_back({std::move(path), true, {}, 0, {}});
        return dom_.start_object(n);
    }
    bool key(std::string& k) {
        Frame& f = frames_.back();
        if (!f.keys.insert(k).second) {
            const std::string p = join(f.path, k);
            throw InputError(file_, p, ls_.tokenLine, "duplicate field '" + k + "'");
        }
        f.key = k;
        return dom_.key(k);
    }
    bool end_object() {
        frames_.pop_back();
        return dom_.end_object();
    }
    bool start_array(std::size_t n) {
        std::string path = currentPath();
        value();
        frames_.push_back({std::move(path), false, {}, 0, {}});
        return dom_.start_array(n);
    }
    bool end_array() {
        frames_.pop_back();
        return dom_.end_array();
    }
    bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception& ex) {
        std::string msg = ex.what();
        // "[json.exception.parse_error.101] parse error at line 3, column 5: x"
        // -> "JSON syntax error: x" (the line goes into the InputError).
        if (auto c = msg.find(": "); c != std::string::npos && msg.rfind("[json.exception", 0) == 0)
            msg = msg.substr(c + 2);
        throw InputError(file_, "", ls_.tokenLine, "JSON syntax error: " + msg);
    }

private:
    struct Frame {
        std::string path;
        bool isObject;
        std::string key;
        std::size_t nextIndex;
        std::set<std::string> keys;
    };

    static std::string join(const std::string& base, const std::string& key) {
        return base.empty() ? key : base + "." + key;
    }
    // Path of the value about to be reported.
    std::string currentPath() const {
        if (frames_.empty()) return "";
        const Frame& f = frames_.back();
        if (f.isObject) return join(f.path, f.key);
        return f.path + "[" + std::to_string(f.nextIndex) + "]";
    }
    // Records the line of the value being reported; advances array indices.
    bool value() {
        if (frames_.empty()) {
            lines_.set("", ls_.tokenLine);
        } else if (frames_.back().isObject) {
            lines_.set(currentPath(), ls_.tokenLine);
        } else {
            Frame& f = frames_.back();
            lines_.setElement(f.path, f.nextIndex, ls_.tokenLine);
            ++f.nextIndex;
        }
        return true;
    }

    nlohmann::detail::json_sax_dom_parser<json> dom_;
    LineState& ls_;
    LineMap& lines_;
    const std::string& file_;
    std::vector<Frame> frames_;
};

} // namespace

void parseWithLines(const std::string& text, const std::string& file, json& root, LineMap& lines) {
    if (const int line = jsonNestingTooDeep(text))
        throw InputError(file, "", line, "arrays and objects nested more than " + std::to_string(kMaxJsonNesting) + " deep");
    LineState ls;
    LineSax sax(root, ls, lines, file);
    LineCountingIterator first(text.data(), &ls), last(text.data() + text.size(), &ls);
    json::sax_parse(first, last, &sax);
}

namespace {

// Model-space transform: either 16 numbers (column-major, as glm stores
// them: element k is column k/4, row k%4) or {"translate", "rotate_deg",
// "scale"} composed as M = T * Rz * Ry * Rx * S (scale first, then rotate
// about X, then Y, then Z, then translate).
glm::dmat4 readTransform(const SceneReader& r, const json& v, const std::string& path) {
    if (v.is_array()) {
        if (v.size() != 16) r.fail(path, "must be 16 numbers (column-major) or an object");
        glm::dmat4 m(1.0);
        for (int k = 0; k < 16; ++k) m[k / 4][k % 4] = r.number(v[k], SceneReader::at(path, k));
        return m;
    }
    r.requireObject(v, path);
    r.checkKeys(v, path, {"translate", "rotate_deg", "scale"});
    glm::dvec3 t(0.0), rot(0.0), s(1.0);
    if (const json* x = r.find(v, "translate")) t = r.vec3(*x, SceneReader::at(path, "translate"));
    if (const json* x = r.find(v, "rotate_deg")) rot = r.vec3(*x, SceneReader::at(path, "rotate_deg"));
    if (const json* x = r.find(v, "scale")) {
        const std::string sp = SceneReader::at(path, "scale");
        s = x->is_array() ? r.vec3(*x, sp) : glm::dvec3(r.number(*x, sp));
    }
    auto rotAxis = [](double deg, int axis) {
        const double a = deg * 3.14159265358979323846 / 180.0, c = std::cos(a), sn = std::sin(a);
        glm::dmat4 m(1.0);
        const int i = (axis + 1) % 3, j = (axis + 2) % 3;  // the plane rotated
        m[i][i] = c;
        m[i][j] = sn;
        m[j][i] = -sn;
        m[j][j] = c;
        return m;
    };
    glm::dmat4 T(1.0);
    T[3] = glm::dvec4(t, 1.0);
    glm::dmat4 S(1.0);
    S[0][0] = s.x;
    S[1][1] = s.y;
    S[2][2] = s.z;
    return T * rotAxis(rot.z, 2) * rotAxis(rot.y, 1) * rotAxis(rot.x, 0) * S;
}

} // namespace

Camera readCamera(const SceneReader& r, const json& v, const std::string& p, const Camera& base, bool requirePlacement,
                  const std::vector<const char*>& extraKeys) {
    r.requireObject(v, p);
    std::vector<const char*> known = {"position", "target", "up", "projection", "fov_y_deg", "ortho_height", "near",
                                      "far", "width", "height", "tile_size"};
    known.insert(known.end(), extraKeys.begin(), extraKeys.end());
    r.checkKeys(v, p, known);
    Camera c = base;
    auto sub = [&](const char* k) { return SceneReader::at(p, k); };
    if (requirePlacement) {
        c.position = r.vec3(r.require(v, p, "position"), sub("position"));
        c.target = r.vec3(r.require(v, p, "target"), sub("target"));
    } else {
        if (const json* x = r.find(v, "position")) c.position = r.vec3(*x, sub("position"));
        if (const json* x = r.find(v, "target")) c.target = r.vec3(*x, sub("target"));
    }
    if (const json* x = r.find(v, "up")) c.up = r.vec3(*x, sub("up"));
    if (const json* x = r.find(v, "projection")) {
        try {
            c.projection = projectionKindFromString(r.string(*x, sub("projection")));
        } catch (const SettingsError& e) {
            r.fail(sub("projection"), std::string(e.what()).substr(std::strlen("projection: ")));
        }
    }
    c.fovYDeg = r.numberOr(v, p, "fov_y_deg", c.fovYDeg);
    c.orthoHeight = r.numberOr(v, p, "ortho_height", c.orthoHeight);
    c.nearPlane = r.numberOr(v, p, "near", c.nearPlane);
    if (const json* x = r.find(v, "far")) {
        if (x->is_string()) {
            if (x->get<std::string>() != "inf") r.fail(sub("far"), "must be a number or the string \"inf\"");
            c.farPlane = std::numeric_limits<double>::infinity();
        } else {
            c.farPlane = r.number(*x, sub("far"));
        }
    }
    if (const json* x = r.find(v, "width")) c.width = r.uint(*x, sub("width"));
    if (const json* x = r.find(v, "height")) c.height = r.uint(*x, sub("height"));
    if (const json* x = r.find(v, "tile_size")) c.tileSize = r.uint(*x, sub("tile_size"));
    // validate() names the field as "camera.near": the same key under `p`.
    if (std::string e = c.validate(); !e.empty()) {
        const auto colon = e.find(':');
        const std::string field = e.substr(0, colon);
        const std::string key = field.rfind("camera.", 0) == 0 ? field.substr(7) : field;
        r.fail(SceneReader::at(p, key), e.substr(colon + 2));
    }
    return c;
}

namespace {

PointLight readLight(const SceneReader& r, const json& v, std::size_t i) {
    const std::string p = SceneReader::at("lights", i);
    r.requireObject(v, p);
    r.checkKeys(v, p, {"name", "type", "position", "color", "intensity", "min_intensity", "radius",
                       "direction", "outer_angle_deg", "inner_angle_deg"});
    PointLight l;
    l.name = "light_" + std::to_string(i);
    if (const json* x = r.find(v, "name")) l.name = r.string(*x, SceneReader::at(p, "name"));
    if (const json* x = r.find(v, "type")) {
        const std::string type = r.string(*x, SceneReader::at(p, "type"));
        if (type == "spot") l.kind = LightKind::Spot;
        else if (type != "point")
            r.fail(SceneReader::at(p, "type"),
                   "light '" + l.name + "': unknown light type '" + type + "' (valid: point, spot)");
    }
    // Spot fields on a point light are refused rather than ignored: a
    // forgotten "type": "spot" must not silently give a point light.
    for (const char* key : {"direction", "outer_angle_deg", "inner_angle_deg"})
        if (!l.isSpot() && r.find(v, key))
            r.fail(SceneReader::at(p, key), "light '" + l.name + "': only spot lights have '" +
                                                key + "' (add \"type\": \"spot\")");
    if (l.isSpot()) {
        l.direction = r.vec3(r.require(v, p, "direction"), SceneReader::at(p, "direction"));
        l.outerAngleDeg = r.number(r.require(v, p, "outer_angle_deg"), SceneReader::at(p, "outer_angle_deg"));
        l.innerAngleDeg = r.numberOr(v, p, "inner_angle_deg", 0.0);
    }
    l.position = r.vec3(r.require(v, p, "position"), SceneReader::at(p, "position"));
    if (const json* x = r.find(v, "color")) l.color = r.vec3(*x, SceneReader::at(p, "color"));
    l.intensity = r.numberOr(v, p, "intensity", l.intensity);
    l.minIntensity = r.numberOr(v, p, "min_intensity", l.minIntensity);
    l.explicitRadius = r.numberOr(v, p, "radius", 0.0);
    // validate() names the JSON key first ("intensity: ...").
    if (std::string e = l.validate(); !e.empty()) {
        const auto colon = e.find(':');
        r.fail(SceneReader::at(p, e.substr(0, colon)), "light '" + l.name + "': " + e.substr(colon + 2));
    }
    return l;
}

Mesh readMesh(const SceneReader& r, const json& v, std::size_t i, const fs::path& baseDir,
              const CancelToken* cancel, std::vector<std::string>* warnings) {
    const std::string p = SceneReader::at("meshes", i);
    r.requireObject(v, p);
    r.checkKeys(v, p, {"name", "path", "positions", "indices", "transform"});
    const json* path = r.find(v, "path");
    const json* pos = r.find(v, "positions");
    const json* idx = r.find(v, "indices");
    Mesh m;
    if (path) {
        if (pos || idx) r.fail(p, "give either \"path\" or inline \"positions\"/\"indices\", not both");
        const std::string rel = r.string(*path, SceneReader::at(p, "path"));
        if (rel.empty()) r.fail(SceneReader::at(p, "path"), "must not be empty");
        const fs::path full = fs::path(rel).is_absolute() ? fs::path(rel) : baseDir / rel;
        MeshLoadReport report;
        try {
            m = loadMesh(full.string(), &report, cancel);
        } catch (const InputError& e) {
            r.fail(SceneReader::at(p, "path"), std::string("cannot load mesh: ") + e.what());
        }
        if (warnings && !report.warning.empty()) {
            std::istringstream lines(report.warning);
            for (std::string line; std::getline(lines, line);)
                if (!line.empty()) warnings->push_back(line);
        }
        m.sourcePath = rel;
        m.name = fs::path(rel).stem().string();
    } else {
        if (!pos || !idx) r.fail(p, "needs \"path\", or both \"positions\" and \"indices\"");
        const std::string pp = SceneReader::at(p, "positions"), ip = SceneReader::at(p, "indices");
        if (!pos->is_array() || pos->size() % 3 != 0) r.fail(pp, "must be an array of 3n numbers");
        if (!idx->is_array() || idx->size() % 3 != 0) r.fail(ip, "must be an array of 3n vertex indices");
        m.positions.reserve(pos->size());
        for (std::size_t k = 0; k < pos->size(); ++k) {
            const double d = r.number((*pos)[k], SceneReader::at(pp, k));
            if (!std::isfinite(float(d))) r.fail(SceneReader::at(pp, k), "coordinate out of float range");
            m.positions.push_back(float(d));
        }
        m.indices.reserve(idx->size());
        const std::size_t nv = m.positions.size() / 3;
        for (std::size_t k = 0; k < idx->size(); ++k) {
            const std::uint32_t x = r.uint((*idx)[k], SceneReader::at(ip, k));
            if (x >= nv)
                r.fail(SceneReader::at(ip, k), "vertex index " + std::to_string(x) + " out of range (" +
                                                   std::to_string(nv) + " vertices)");
            m.indices.push_back(x);
        }
        m.name = "mesh_" + std::to_string(i);
    }
    if (const json* x = r.find(v, "name")) m.name = r.string(*x, SceneReader::at(p, "name"));
    if (const json* x = r.find(v, "transform")) m.transform = readTransform(r, *x, SceneReader::at(p, "transform"));
    for (int c = 0; c < 4; ++c)
        for (int k = 0; k < 4; ++k)
            if (!std::isfinite(m.transform[c][k])) r.fail(SceneReader::at(p, "transform"), "must be finite");
    return m;
}

Scene parseSceneImpl(const std::string& text, const std::string& file, const CancelToken* cancel,
                     const Progress& progress, std::vector<std::string>* warnings) {
    json root;
    LineMap lines;
    parseWithLines(text, file, root, lines);
    if (progress) progress(0.1);
    SceneReader r(file, lines);
    if (!root.is_object()) r.fail("", "a scene file must hold a JSON object");
    r.checkKeys(root, "", {"format", "version", "name", "camera", "meshes", "lights"});
    if (r.string(r.require(root, "", "format"), "format") != "lightcull-scene")
        r.fail("format", "must be \"lightcull-scene\"");
    const std::uint32_t ver = r.uint(r.require(root, "", "version"), "version");
    if (ver != std::uint32_t(kSceneFormatVersion))
        r.fail("version", "this build reads version " + std::to_string(kSceneFormatVersion) + ", not " +
                              std::to_string(ver));

    Scene s;
    s.name = fs::path(file).stem().string();
    if (const json* x = r.find(root, "name")) s.name = r.string(*x, "name");
    if (const json* x = r.find(root, "camera")) s.camera = readCamera(r, *x, "camera", Camera{}, true);
    if (const json* x = r.find(root, "lights")) {
        if (!x->is_array()) r.fail("lights", "must be an array");
        for (std::size_t i = 0; i < x->size(); ++i) s.lights.push_back(readLight(r, (*x)[i], i));
    }
    if (const json* x = r.find(root, "meshes")) {
        if (!x->is_array()) r.fail("meshes", "must be an array");
        const fs::path base = fs::path(file).parent_path();
        for (std::size_t i = 0; i < x->size(); ++i) {
            if (cancel) cancel->throwIfCancelled();
            s.meshes.push_back(readMesh(r, (*x)[i], i, base, cancel, warnings));
            if (progress) progress(0.1 + 0.9 * double(i + 1) / double(x->size()));
        }
    }
    if (!r.find(root, "camera") && s.triangleCount() > 0) {
        // No camera: one that frames the meshes, as a glTF without a camera
        // gets (the fixed default looked at the origin from 5 m, inside or
        // away from most scenes: an empty view that scored as perfect).
        const auto [lo, hi] = s.bounds();
        if (std::isfinite(lo.x + lo.y + lo.z + hi.x + hi.y + hi.z)) s.camera = frameBounds(lo, hi, s.camera);
    }
    if (progress) progress(1.0);
    return s;
}

} // namespace
} // namespace scene_json

Scene parseScene(const std::string& text, const std::string& path) {
    return scene_json::parseSceneImpl(text, path, nullptr, {}, nullptr);
}

Scene loadSceneFile(const std::string& path, const CancelToken* cancel, const Progress& progress,
                    std::vector<std::string>* warnings) {
    std::error_code ec;
    if (!fs::exists(path, ec)) throw InputError(path, "", 0, "file not found");
    if (fs::is_directory(path, ec)) throw InputError(path, "", 0, "is a folder, not a scene file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path, "", 0, "cannot open file for reading");
    std::ostringstream ss;
    ss << in.rdbuf();
    if (in.bad()) throw InputError(path, "", 0, "read error");
    const std::string text = ss.str();
    if (text.find_first_not_of(" \t\r\n") == std::string::npos) throw InputError(path, "", 0, "empty file");
    return scene_json::parseSceneImpl(text, path, cancel, progress, warnings);
}

namespace {
// The "path" written for a mesh loaded from a file: relative to the folder the
// scene is saved in, so the scene and its meshes can move together.
std::string meshPathFor(const Mesh& m, const std::string& baseDir) {
    if (baseDir.empty() || m.resolvedPath.empty()) return m.sourcePath;
    const fs::path base = fs::absolute(fs::path(baseDir)).lexically_normal();
    return fs::path(m.resolvedPath).lexically_proximate(base).generic_string();
}
} // namespace

std::string serializeScene(const Scene& scene, const std::string& baseDir) {
    using ojson = nlohmann::ordered_json;
    auto v3 = [](const glm::dvec3& v) { return ojson::array({v.x, v.y, v.z}); };
    ojson root;
    root["format"] = "lightcull-scene";
    root["version"] = kSceneFormatVersion;
    root["name"] = scene.name;

    const Camera& c = scene.camera;
    ojson cam;
    cam["position"] = v3(c.position);
    cam["target"] = v3(c.target);
    cam["up"] = v3(c.up);
    cam["projection"] = toString(c.projection);
    cam["fov_y_deg"] = c.fovYDeg;
    cam["ortho_height"] = c.orthoHeight;
    cam["near"] = c.nearPlane;
    if (std::isinf(c.farPlane)) cam["far"] = "inf";
    else cam["far"] = c.farPlane;
    cam["width"] = c.width;
    cam["height"] = c.height;
    cam["tile_size"] = c.tileSize;
    root["camera"] = std::move(cam);

    ojson meshes = ojson::array();
    for (const Mesh& m : scene.meshes) {
        ojson jm;
        jm["name"] = m.name;
        if (!m.sourcePath.empty()) {
            jm["path"] = meshPathFor(m, baseDir);
        } else {
            // float -> double is exact and nlohmann prints the shortest text
            // that reads back to the same double, so the floats survive.
            ojson pos = ojson::array();
            for (float f : m.positions) pos.push_back(double(f));
            jm["positions"] = std::move(pos);
            jm["indices"] = m.indices;
        }
        ojson t = ojson::array();
        for (int k = 0; k < 16; ++k) t.push_back(m.transform[k / 4][k % 4]);
        jm["transform"] = std::move(t);
        meshes.push_back(std::move(jm));
    }
    root["meshes"] = std::move(meshes);

    ojson lights = ojson::array();
    for (const PointLight& l : scene.lights) {
        ojson jl;
        jl["name"] = l.name;
        if (l.isSpot()) jl["type"] = "spot"; // point lights stay as version 1 always wrote them
        jl["position"] = v3(l.position);
        jl["color"] = v3(l.color);
        jl["intensity"] = l.intensity;
        jl["min_intensity"] = l.minIntensity;
        if (l.explicitRadius != 0.0) jl["radius"] = l.explicitRadius;
        if (l.isSpot()) {
            jl["direction"] = v3(l.direction);
            jl["outer_angle_deg"] = l.outerAngleDeg;
            if (l.innerAngleDeg != 0.0) jl["inner_angle_deg"] = l.innerAngleDeg;
        }
        lights.push_back(std::move(jl));
    }
    root["lights"] = std::move(lights);
    return root.dump(1) + "\n";
}

void saveSceneFile(const Scene& scene, const std::string& path) {
    fs::path dir = fs::path(path).parent_path();
    if (dir.empty()) dir = ".";
    const std::string text = serializeScene(scene, dir.string());
    try {
        writeFileAtomic(path, text);
    } catch (const Error& e) {
        throw InputError(path, "", 0, e.what());
    }
}

} // namespace lc
