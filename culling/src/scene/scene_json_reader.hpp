// The scene JSON reader's typed reading (scene_json.cpp), shared with the
// camera-path reader (camera_path.cpp): JSON parsed with the line of every
// value recorded by its field path, and a reader whose every error is an
// InputError naming the file, the field path and its line.
#pragma once

#include "culling/core/errors.hpp"
#include "culling/scene/scene.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <map>
#include <string>
#include <vector>

namespace lc::scene_json {

using json = nlohmann::json;

// Lines of values by field path. Elements of arrays are kept per array in a
// vector (an inline mesh has millions of numbers; a string key each would cost
// far more than the mesh).
class LineMap {
public:
    void set(const std::string& path, int line) { lines_.emplace(path, line); }
    void setElement(const std::string& arrayPath, std::size_t index, int line) {
        auto& v = elements_[arrayPath];
        if (v.size() <= index) v.resize(index + 1, 0);
        v[index] = line;
    }
    // Line of `path`; 0 when unknown.
    int line(const std::string& path) const {
        if (auto it = lines_.find(path); it != lines_.end()) return it->second;
        if (!path.empty() && path.back() == ']') {
            const auto open = path.rfind('[');
            const std::string arr = path.substr(0, open);
            const std::size_t idx = std::stoul(path.substr(open + 1));
            if (auto it = elements_.find(arr); it != elements_.end() && idx < it->second.size())
                return it->second[idx];
        }
        return 0;
    }

private:
    std::map<std::string, int> lines_;
    std::map<std::string, std::vector<int>> elements_;
};

// Parses `text` into `root`, recording every value's line in `lines`. Syntax
// errors, duplicate keys and nesting past kMaxJsonNesting are InputErrors
// naming `file` and the line.
void parseWithLines(const std::string& text, const std::string& file, json& root, LineMap& lines);

// Typed reading of the parsed DOM: every failure is an InputError naming the
// file, the field path and its line (a missing field: its object's line).
class SceneReader {
public:
    SceneReader(const std::string& file, const LineMap& lines) : file_(file), lines_(lines) {}

    [[noreturn]] void fail(const std::string& path, const std::string& what) const {
        int line = lines_.line(path);
        // A missing field has no line: use the enclosing object's.
        for (std::string p = path; line == 0 && !p.empty();) {
            const auto cut = p.find_last_of(".[");
            p = cut == std::string::npos ? std::string() : p.substr(0, cut);
            line = lines_.line(p);
        }
        throw InputError(file_, path, line, what);
    }

    static std::string at(const std::string& base, const std::string& key) {
        return base.empty() ? key : base + "." + key;
    }
    static std::string at(const std::string& base, std::size_t i) {
        return base + "[" + std::to_string(i) + "]";
    }

    static const char* typeName(const json& v) { return v.type_name(); }

    void requireObject(const json& v, const std::string& path) const {
        if (!v.is_object()) fail(path, std::string("must be an object, not ") + typeName(v));
    }
    void checkKeys(const json& obj, const std::string& path, const std::vector<const char*>& known) const {
        for (auto it = obj.begin(); it != obj.end(); ++it) {
            bool ok = false;
            for (const char* k : known) ok = ok || it.key() == k;
            if (!ok) {
                std::string list;
                for (const char* k : known) list += std::string(list.empty() ? "" : ", ") + k;
                fail(at(path, it.key()), "unknown field '" + it.key() + "' (known here: " + list + ")");
            }
        }
    }
    const json* find(const json& obj, const char* key) const {
        auto it = obj.find(key);
        return it == obj.end() ? nullptr : &*it;
    }
    const json& require(const json& obj, const std::string& path, const char* key) const {
        const json* v = find(obj, key);
        if (!v) fail(at(path, key), "missing required field");
        return *v;
    }
    double number(const json& v, const std::string& path) const {
        if (!v.is_number()) fail(path, std::string("must be a number, not ") + typeName(v));
        return v.get<double>();
    }
    std::string string(const json& v, const std::string& path) const {
        if (!v.is_string()) fail(path, std::string("must be a string, not ") + typeName(v));
        return v.get<std::string>();
    }
    std::uint32_t uint(const json& v, const std::string& path) const {
        // 640.0 is a whole number too (Python's json writes floats so).
        if (v.is_number_float()) {
            const double d = v.get<double>();
            if (!(std::floor(d) == d)) fail(path, "must be a whole number, not " + v.dump());
            if (!(d >= 0 && d <= 4294967295.0)) fail(path, "must be in [0, 4294967295]");
            return std::uint32_t(d);
        }
        if (!v.is_number_integer()) fail(path, std::string("must be a whole number, not ") + typeName(v));
        if (v.is_number_unsigned() ? v.get<std::uint64_t>() > 0xFFFFFFFFull : v.get<std::int64_t>() < 0)
            fail(path, "must be in [0, 4294967295]");
        return v.get<std::uint32_t>();
    }
    glm::dvec3 vec3(const json& v, const std::string& path) const {
        if (!v.is_array() || v.size() != 3) fail(path, "must be an array of 3 numbers");
        return {number(v[0], at(path, 0)), number(v[1], at(path, 1)), number(v[2], at(path, 2))};
    }
    double numberOr(const json& obj, const std::string& path, const char* key, double def) const {
        const json* v = find(obj, key);
        return v ? number(*v, at(path, key)) : def;
    }

private:
    const std::string& file_;
    const LineMap& lines_;
};

// Reads the camera object `v` at field path `path` ("camera", "cameras[3]"):
// the keys of the scene JSON's "camera" (docs/FORMATS.md); keys left out keep
// `base`'s values, except that "position" and "target" are required when
// `requirePlacement`. `extraKeys` are allowed too and left to the caller. The
// result is validated; an invalid camera fails at the field validate() names.
Camera readCamera(const SceneReader& r, const json& v, const std::string& path, const Camera& base,
                  bool requirePlacement, const std::vector<const char*>& extraKeys = {});

} // namespace lc::scene_json
