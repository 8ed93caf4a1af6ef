// Camera paths (culling/scene/camera_path.hpp, docs/FORMATS.md "Camera paths").
// A JSON path goes through the scene JSON reader (field paths and lines in
// every error, the scene's "camera" keys); a glTF path through the glTF
// reader's parsing and scene walk, then its animation is sampled here.

#include "culling/scene/camera_path.hpp"

#include "culling/core/errors.hpp"
#include "culling/scene/gltf_io.hpp"
#include "scene/gltf_internal.hpp"
#include "scene/scene_json_reader.hpp"

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace lc {

namespace {

namespace fs = std::filesystem;
using scene_json::json;
using scene_json::SceneReader;

constexpr double kMaxFps = 1000;
// A JSON path of 100,000 cameras with every key is about 30 MB.
constexpr std::uint64_t kMaxJsonPathBytes = std::uint64_t(256) << 20;
// Key values (times and outputs, all channels on the camera's chain
// together) read from a glTF animation: 128 MiB of doubles. Accessors may
// share one buffer view, so the file's size alone does not bound this.
constexpr std::uint64_t kMaxKeyValues = std::uint64_t(1) << 24;
// Frames x (transform steps + channels) the sampling may take: a deep chain
// of animated nodes at many frames would otherwise run for minutes. A camera
// with a few animated parents at 100,000 frames is about 1e6.
constexpr double kMaxSampleWork = 2e7;

std::string idx(const char* array, std::size_t i) { return std::string(array) + "[" + std::to_string(i) + "]"; }

std::string num(double v) {
    std::ostringstream o;
    o << v;
    return o.str();
}

std::string fileName(const std::string& path) {
    const std::string n = fs::path(path).filename().string();
    return n.empty() ? path : n;
}

bool hasGlbMagic(const std::string& path) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) return false;
    std::ifstream in(path, std::ios::binary);
    char magic[4] = {};
    return in.read(magic, 4) && std::memcmp(magic, "glTF", 4) == 0;
}

// ---------------------------------------------------------------- JSON

std::string readJsonFile(const std::string& path) {
    std::error_code ec;
    const fs::file_status st = fs::status(path, ec);
    if (ec || !fs::exists(st)) throw InputError(path, "", 0, "file not found");
    if (fs::is_directory(st)) throw InputError(path, "", 0, "is a folder, not a camera path");
    if (!fs::is_regular_file(st)) throw InputError(path, "", 0, "is not a regular file");
    const std::uint64_t size = fs::file_size(path, ec);
    if (ec) throw InputError(path, "", 0, "cannot read file: " + ec.message());
    if (size > kMaxJsonPathBytes)
        throw InputError(path, "", 0, std::to_string(size) + " bytes is more than the " +
                                          std::to_string(kMaxJsonPathBytes >> 20) + " MiB a JSON camera path may hold");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path, "", 0, "cannot open file for reading");
    std::string text(std::size_t(size), '\0');
    in.read(text.data(), std::streamsize(size));
    if (std::uint64_t(in.gcount()) != size) throw InputError(path, "", 0, "read error (file shrank while reading?)");
    if (text.find_first_not_of(" \t\r\n") == std::string::npos) throw InputError(path, "", 0, "empty file");
    return text;
}

CameraPath readJsonPath(const std::string& path, const Camera& base, double fps, std::size_t maxFrames) {
    const std::string text = readJsonFile(path);
    json root;
    scene_json::LineMap lines;
    scene_json::parseWithLines(text, path, root, lines);
    const SceneReader r(path, lines);
    if (!root.is_object())
        r.fail("", "a camera path must be a JSON object {\"cameras\": [...]} (or a .gltf/.glb with a camera animation)");
    r.checkKeys(root, "", {"cameras", "fps"});
    if (const json* x = r.find(root, "fps")) {
        fps = r.number(*x, "fps");
        if (!(fps > 0 && fps <= kMaxFps)) r.fail("fps", "must be in (0, 1000] frames per second, not " + num(fps));
    }
    const json& cams = r.require(root, "", "cameras");
    if (!cams.is_array()) r.fail("cameras", std::string("must be an array of cameras, not ") + cams.type_name());
    if (cams.empty()) r.fail("cameras", "must hold at least one camera");
    if (cams.size() > maxFrames)
        r.fail("cameras", std::to_string(cams.size()) + " cameras, more than the " + std::to_string(maxFrames) +
                              " frames a camera path may hold");
    CameraPath out;
    out.frames.reserve(cams.size());
    for (std::size_t i = 0; i < cams.size(); ++i) {
        const std::string p = SceneReader::at("cameras", i);
        CameraPathFrame f;
        f.camera = scene_json::readCamera(r, cams[i], p, base, false, {"time"});
        const json* t = r.find(cams[i], "time");
        f.time = t ? r.number(*t, SceneReader::at(p, "time")) : double(i) / fps;
        if (!std::isfinite(f.time)) r.fail(SceneReader::at(p, "time"), "must be finite");
        if (i > 0 && f.time < out.frames.back().time) {
            const std::string before = "comes before the previous camera's " + num(out.frames.back().time) +
                                       " s: a path's times must not decrease";
            if (t) r.fail(SceneReader::at(p, "time"), num(f.time) + " s " + before);
            r.fail(p, "its default time (index / fps) " + num(f.time) + " s " + before + " (give it a \"time\")");
        }
        out.frames.push_back(std::move(f));
    }
    out.description = std::to_string(out.frames.size()) + (out.frames.size() == 1 ? " camera of " : " cameras of ") +
                       fileName(path);
    return out;
}

// ---------------------------------------------------------------- glTF

enum class Trs { Translation, Rotation, Scale };
enum class Interpolation { Step, Linear, CubicSpline };

// One animation channel on the camera's chain, its keys read and checked.
struct Track {
    std::size_t step;  // index into the chain's steps (an animated node)
    Trs what;
    Interpolation interpolation;
    std::size_t comps;           // 3, or 4 for a rotation (x, y, z, w)
    std::vector<double> times;   // finite, non-decreasing, at least one
    // `comps` per element; CUBICSPLINE has 3 elements per key (in-tangent,
    // value, out-tangent). Rotation values are unit quaternions.
    std::vector<double> values;
    std::string field;           // "animations[0].channels[2]"

    std::size_t valueAt(std::size_t key) const {
        return (interpolation == Interpolation::CubicSpline ? 3 * key + 1 : key) * comps;
    }
    const double* value(std::size_t key) const { return &values[valueAt(key)]; }
    // The sampler at time t (clamped to the keys), glTF 2.0 Appendix C.
    void sample(double t, double* out) const {
        const std::size_t n = times.size();
        if (n == 1 || t <= times.front()) return copy(value(0), out);
        if (t >= times.back()) return copy(value(n - 1), out);
        // times[k] <= t < times[k + 1], so the segment has a positive length.
        const std::size_t k = std::size_t(std::upper_bound(times.begin(), times.end(), t) - times.begin()) - 1;
        const double td = times[k + 1] - times[k], s = (t - times[k]) / td;
        const double *a = value(k), *b = value(k + 1);
        switch (interpolation) {
        case Interpolation::Step: return copy(a, out);
        case Interpolation::Linear:
            if (what == Trs::Rotation) {
                const glm::dquat q = glm::slerp(glm::dquat(a[3], a[0], a[1], a[2]), glm::dquat(b[3], b[0], b[1], b[2]), s);
                out[0] = q.x, out[1] = q.y, out[2] = q.z, out[3] = q.w;
            } else {
                for (std::size_t c = 0; c < comps; ++c) out[c] = a[c] + (b[c] - a[c]) * s;
            }
            return;
        case Interpolation::CubicSpline: {
            // Hermite: p0 = value k, m0 = td * out-tangent k, p1 = value k+1,
            // m1 = td * in-tangent k+1.
            const double *outTangent = a + comps, *inTangent = b - comps;
            const double s2 = s * s, s3 = s2 * s;
            const double h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s, h01 = -2 * s3 + 3 * s2, h11 = s3 - s2;
            for (std::size_t c = 0; c < comps; ++c)
                out[c] = h00 * a[c] + h10 * td * outTangent[c] + h01 * b[c] + h11 * td * inTangent[c];
            return;
        }
        }
    }

private:
    void copy(const double* v, double* out) const { std::copy(v, v + comps, out); }
};

// The camera's world matrix as a product of steps from the scene root down:
// runs of nodes that no channel moves folded into one constant matrix, and
// each animated node as its translation, rotation and scale (the node's own
// values where no channel replaces them).
struct ChainStep {
    glm::dmat4 constant{1.0};
    int node = -1;               // >= 0: an animated node
    glm::dvec3 translation{0.0}, scale{1.0};
    glm::dquat rotation{1, 0, 0, 0};
};

class GltfPathReader {
public:
    GltfPathReader(const std::string& path, const tinygltf::Model& m) : path_(path), m_(m) {}

    [[noreturn]] void fail(const std::string& field, const std::string& what) const {
        throw InputError(path_, field, 0, what);
    }

    // "0 'Fly', 1, 2 'Orbit'": the file's animations for messages (the first 8).
    std::string animationList() const {
        if (m_.animations.empty()) return "the file has no animations";
        std::string s = "the file has ";
        for (std::size_t a = 0; a < m_.animations.size() && a < 8; ++a)
            s += (a ? ", " : "") + label(a);
        if (m_.animations.size() > 8) s += " and " + std::to_string(m_.animations.size() - 8) + " more";
        return s;
    }
    std::string label(std::size_t a) const {
        const std::string& n = m_.animations[a].name;
        return n.empty() ? idx("animations", a) : "'" + n + "' (" + idx("animations", a) + ")";
    }
    std::string nodeLabel(int n) const {
        const std::string& name = m_.nodes[std::size_t(n)].name;
        return name.empty() ? idx("nodes", std::size_t(n)) : "'" + name + "' (" + idx("nodes", std::size_t(n)) + ")";
    }

    static bool trsPath(const std::string& p, Trs& what) {
        if (p == "translation") what = Trs::Translation;
        else if (p == "rotation") what = Trs::Rotation;
        else if (p == "scale") what = Trs::Scale;
        else return false;
        return true;
    }

    // Whether animation a has a channel moving a node of the chain.
    bool moves(std::size_t a, const std::vector<int>& chainPos) const {
        for (const auto& ch : m_.animations[a].channels) {
            Trs what;
            if (ch.target_node >= 0 && std::size_t(ch.target_node) < chainPos.size() &&
                chainPos[std::size_t(ch.target_node)] >= 0 && trsPath(ch.target_path, what))
                return true;
        }
        return false;
    }

    const tinygltf::Accessor& accessor(int i, const std::string& field) const {
        if (i < 0 || std::size_t(i) >= m_.accessors.size())
            fail(field, std::to_string(i) + " is not an index into accessors (" + std::to_string(m_.accessors.size()) + ")");
        return m_.accessors[std::size_t(i)];
    }

    // FLOAT elements of `comps` components, checked, as doubles.
    std::vector<double> readFloats(int accessorIndex, const std::string& field, std::size_t comps, const char* what) {
        const tinygltf::Accessor& a = accessor(accessorIndex, field);
        const std::string ap = idx("accessors", std::size_t(accessorIndex));
        const int type = comps == 1 ? TINYGLTF_TYPE_SCALAR : comps == 3 ? TINYGLTF_TYPE_VEC3 : TINYGLTF_TYPE_VEC4;
        const char* typeName = comps == 1 ? "SCALAR" : comps == 3 ? "VEC3" : "VEC4";
        if (a.type != type) fail(ap + ".type", std::string(what) + " must be " + typeName);
        if (a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT) {
            if (comps == 4 && a.normalized)
                fail(ap + ".componentType", std::to_string(a.componentType) +
                                                ": rotation keys as normalised integers are not read; export float keys");
            fail(ap + ".componentType", std::to_string(a.componentType) + " is not FLOAT (5126): " + what + " are read as floats only");
        }
        if (a.sparse.isSparse) fail(ap + ".sparse", "sparse accessors are not read for animations");
        if (a.bufferView < 0) fail(ap + ".bufferView", std::string("missing: ") + what + " need data");
        if (a.count == 0) fail(ap + ".count", "must be at least 1");
        const GltfByteSpan span = gltfViewSpan(path_, m_, a.bufferView, a.byteOffset, a.count, 4 * comps, ap, what);
        // count fits the view's bytes (checked above), so this cannot overflow.
        const std::uint64_t n = std::uint64_t(a.count) * comps;
        if (n > kMaxKeyValues - keyValues_)
            fail(ap + ".count", "the channels that move the camera hold more than " + std::to_string(kMaxKeyValues) +
                                    " key values, more than this reader takes");
        keyValues_ += n;
        std::vector<double> out(static_cast<std::size_t>(n));
        for (std::size_t e = 0; e < a.count; ++e)
            for (std::size_t c = 0; c < comps; ++c) {
                float f;
                std::memcpy(&f, span.data + e * span.stride + 4 * c, 4);
                if (!std::isfinite(f)) fail(ap, "element " + std::to_string(e) + " is not finite");
                out[e * comps + c] = f;
            }
        return out;
    }

    Track readTrack(std::size_t a, std::size_t k, std::size_t step, Trs what) {
        const tinygltf::Animation& anim = m_.animations[a];
        const tinygltf::AnimationChannel& ch = anim.channels[k];
        Track tr;
        tr.step = step;
        tr.what = what;
        tr.comps = what == Trs::Rotation ? 4 : 3;
        tr.field = idx("animations", a) + "." + idx("channels", k);
        if (ch.sampler < 0 || std::size_t(ch.sampler) >= anim.samplers.size())
            fail(tr.field + ".sampler", std::to_string(ch.sampler) + " is not an index into the animation's samplers (" +
                                            std::to_string(anim.samplers.size()) + ")");
        const tinygltf::AnimationSampler& smp = anim.samplers[std::size_t(ch.sampler)];
        const std::string sp = idx("animations", a) + "." + idx("samplers", std::size_t(ch.sampler));
        if (smp.interpolation == "LINEAR") tr.interpolation = Interpolation::Linear;
        else if (smp.interpolation == "STEP") tr.interpolation = Interpolation::Step;
        else if (smp.interpolation == "CUBICSPLINE") tr.interpolation = Interpolation::CubicSpline;
        else fail(sp + ".interpolation", "'" + smp.interpolation + "' is not LINEAR, STEP or CUBICSPLINE");

        tr.times = readFloats(smp.input, sp + ".input", 1, "key times");
        for (std::size_t i = 1; i < tr.times.size(); ++i)
            if (tr.times[i] < tr.times[i - 1])
                fail(idx("accessors", std::size_t(smp.input)),
                     "key time " + std::to_string(i) + " (" + num(tr.times[i]) + " s) comes before key time " +
                         std::to_string(i - 1) + " (" + num(tr.times[i - 1]) + " s): key times must not decrease");
        const std::uint64_t keys = tr.times.size();
        const std::uint64_t want = tr.interpolation == Interpolation::CubicSpline ? 3 * keys : keys;
        const tinygltf::Accessor& out = accessor(smp.output, sp + ".output");
        if (out.count != want)
            fail(idx("accessors", std::size_t(smp.output)) + ".count",
                 std::to_string(out.count) + " elements for " + std::to_string(keys) + " key times: " +
                     (tr.interpolation == Interpolation::CubicSpline
                          ? "CUBICSPLINE needs 3 per key (in-tangent, value, out-tangent)"
                          : "LINEAR and STEP need one per key"));
        tr.values = readFloats(smp.output, sp + ".output", tr.comps,
                               what == Trs::Rotation ? "rotation keys" : what == Trs::Scale ? "scale keys" : "translation keys");
        if (what == Trs::Rotation)
            for (std::size_t key = 0; key < keys; ++key) {
                double* q = &tr.values[tr.valueAt(key)];
                const double len = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
                if (!(len > 1e-12) || !std::isfinite(len))
                    fail(idx("accessors", std::size_t(smp.output)), "rotation key " + std::to_string(key) + " is a zero quaternion");
                for (int c = 0; c < 4; ++c) q[c] /= len;
            }
        return tr;
    }

private:
    const std::string& path_;
    const tinygltf::Model& m_;
    std::uint64_t keyValues_ = 0;
};

// The animation: the one asked for (by name or index), else the first that
// moves the camera's chain; `moving`: every animation that does.
std::size_t chooseAnimation(const GltfPathReader& r, const tinygltf::Model& model, const std::string& path,
                            const std::string& animation, const std::vector<int>& chainPos,
                            const std::string& cameraLabel, std::vector<std::size_t>& moving) {
    for (std::size_t a = 0; a < model.animations.size(); ++a)
        if (r.moves(a, chainPos)) moving.push_back(a);
    std::size_t anim = 0;
    if (!animation.empty()) {
        const bool numeric = animation.find_first_not_of("0123456789") == std::string::npos && animation.size() < 10;
        std::vector<std::size_t> found;
        for (std::size_t a = 0; a < model.animations.size(); ++a)
            if (numeric ? a == std::size_t(std::stoul(animation)) : model.animations[a].name == animation) found.push_back(a);
        if (found.empty())
            throw SettingsError("animation", "no animation '" + animation + "' in " + path + " (" + r.animationList() + ")");
        if (found.size() > 1)
            throw SettingsError("animation", "'" + animation + "' names more than one animation in " + path +
                                                 ": give the animation's index");
        anim = found.front();
        if (!r.moves(anim, chainPos))
            r.fail(idx("animations", anim), "animation " + r.label(anim) + " does not move the " + cameraLabel +
                                                " or its ancestors" +
                                                (moving.empty() ? std::string(" (no animation does)")
                                                                : " (animations that do: " + r.label(moving.front()) +
                                                                      (moving.size() > 1 ? ", ..." : "") + ")"));
    } else {
        if (moving.empty())
            r.fail("animations", "no animation moves the " + cameraLabel + " or its ancestors (" + r.animationList() + ")");
        anim = moving.front();
    }
    return anim;
}

// The camera's world matrix at time t (frame f): the chain's steps with the
// tracks sampled into them.
glm::dmat4 worldAt(const GltfPathReader& r, std::vector<ChainStep> now, const std::vector<Track>& tracks, double t,
                   std::size_t f, const std::string& animField) {
    for (const Track& tr : tracks) {
        double v[4];
        tr.sample(t, v);
        ChainStep& s = now[tr.step];
        if (tr.what == Trs::Translation) s.translation = {v[0], v[1], v[2]};
        else if (tr.what == Trs::Scale) s.scale = {v[0], v[1], v[2]};
        else s.rotation = glm::dquat(v[3], v[0], v[1], v[2]);
    }
    glm::dmat4 world(1.0);
    for (ChainStep& s : now) {
        if (s.node < 0) {
            world = world * s.constant;
            continue;
        }
        const double len = glm::length(s.rotation);
        if (!(len > 1e-12) || !std::isfinite(len))
            r.fail(animField, "at " + num(t) + " s (frame " + std::to_string(f) + ") the rotation of " +
                                  idx("nodes", std::size_t(s.node)) + " interpolates to a zero or non-finite quaternion");
        world = world * glm::translate(glm::dmat4(1.0), s.translation) * glm::mat4_cast(s.rotation / len) *
                glm::scale(glm::dmat4(1.0), s.scale);
    }
    return world;
}

CameraPath readGltfPath(const std::string& path, const Camera& base, double fps, const std::string& animation,
                        std::size_t maxFrames, const std::string& camera) {
    GltfReadReport rep; // warnings (unknown extensions...) do not concern the path
    const tinygltf::Model model = parseGltfModel(path, rep);
    GltfPathReader r(path, model);
    const std::vector<GltfPlacedNode> placed = walkGltfScene(path, model);
    const int chosen = chooseGltfCamera(path, model, placed, camera);
    if (chosen < 0)
        r.fail("", "no camera node in the scene: a glTF camera path is the animation of a camera node (" +
                       r.animationList() + ")");
    const int camNode = placed[std::size_t(chosen)].node;

    // The camera's chain of nodes, root first. walkGltfScene reached each
    // node of the scene once, so parents are unique and the chain ends.
    std::vector<int> parent(model.nodes.size(), -1);
    for (const GltfPlacedNode& p : placed)
        for (int c : model.nodes[std::size_t(p.node)].children) parent[std::size_t(c)] = p.node;
    std::vector<int> chain;
    for (int n = camNode; n >= 0 && chain.size() <= model.nodes.size(); n = parent[std::size_t(n)]) chain.push_back(n);
    std::reverse(chain.begin(), chain.end());
    std::vector<int> chainPos(model.nodes.size(), -1);
    for (std::size_t i = 0; i < chain.size(); ++i) chainPos[std::size_t(chain[i])] = int(i);
    const std::string cameraLabel = "camera node " + r.nodeLabel(camNode);

    std::vector<std::size_t> moving;
    const std::size_t anim = chooseAnimation(r, model, path, animation, chainPos, cameraLabel, moving);
    const std::string animField = idx("animations", anim);

    // Steps of the world matrix: constant runs and animated nodes.
    std::vector<char> animated(chain.size(), 0);
    const tinygltf::Animation& A = model.animations[anim];
    for (const auto& ch : A.channels) {
        Trs what;
        if (ch.target_node >= 0 && std::size_t(ch.target_node) < chainPos.size() &&
            chainPos[std::size_t(ch.target_node)] >= 0 && GltfPathReader::trsPath(ch.target_path, what))
            animated[std::size_t(chainPos[std::size_t(ch.target_node)])] = 1;
    }
    std::vector<ChainStep> steps;
    std::vector<int> stepOf(chain.size(), -1);
    for (std::size_t i = 0; i < chain.size(); ++i) {
        const std::size_t n = std::size_t(chain[i]);
        const glm::dmat4 local = gltfLocalMatrix(path, model, n); // checks the node's own values
        if (!animated[i]) {
            if (steps.empty() || steps.back().node >= 0) steps.emplace_back();
            steps.back().constant = steps.back().constant * local;
            continue;
        }
        const tinygltf::Node& node = model.nodes[n];
        if (!node.matrix.empty())
            r.fail(idx("nodes", n) + ".matrix", "the node is animated by " + animField +
                                                    " but has a matrix: glTF animates only nodes given by translation, "
                                                    "rotation and scale");
        ChainStep s;
        s.node = int(n);
        if (!node.translation.empty()) s.translation = {node.translation[0], node.translation[1], node.translation[2]};
        if (!node.scale.empty()) s.scale = {node.scale[0], node.scale[1], node.scale[2]};
        if (!node.rotation.empty())
            s.rotation = glm::normalize(glm::dquat(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]));
        stepOf[i] = int(steps.size());
        steps.push_back(s);
    }

    std::vector<Track> tracks;
    std::vector<std::string> seen(steps.size() * 3);
    for (std::size_t k = 0; k < A.channels.size(); ++k) {
        const auto& ch = A.channels[k];
        const std::string cp = animField + "." + idx("channels", k);
        if (ch.target_node >= 0 && std::size_t(ch.target_node) >= model.nodes.size())
            r.fail(cp + ".target.node", std::to_string(ch.target_node) + " is not an index into nodes (" +
                                            std::to_string(model.nodes.size()) + ")");
        Trs what;
        if (ch.target_node < 0 || chainPos[std::size_t(ch.target_node)] < 0 || !GltfPathReader::trsPath(ch.target_path, what))
            continue; // another node, morph weights, or no node (KHR_animation_pointer)
        const std::size_t step = std::size_t(stepOf[std::size_t(chainPos[std::size_t(ch.target_node)])]);
        std::string& first = seen[3 * step + std::size_t(what)];
        if (!first.empty())
            r.fail(cp, "animates " + idx("nodes", std::size_t(ch.target_node)) + "." + ch.target_path + " again (as " +
                           first + " does): one channel per node and property");
        first = idx("channels", k);
        tracks.push_back(r.readTrack(anim, k, step, what));
    }

    // Frames from the first key to the last, both included. Key times are
    // floats: a span a hair past a whole number of frames (4.1666670 s at 24
    // fps) does not add a frame 1e-5 frames after the last whole one.
    double t0 = tracks.front().times.front(), t1 = tracks.front().times.back();
    for (const Track& tr : tracks) t0 = std::min(t0, tr.times.front()), t1 = std::max(t1, tr.times.back());
    const double span = (t1 - t0) * fps;
    if (!std::isfinite(span) || span > double(maxFrames - 1) + 1e-4)
        r.fail(animField, "animation " + r.label(anim) + " runs " + num(t0) + ".." + num(t1) + " s: at " + num(fps) +
                              " fps that is " +
                              (span < 1e18 ? std::to_string(std::uint64_t(std::ceil(span - 1e-4)) + 1) : std::string("too many")) +
                              " frames, more than the " + std::to_string(maxFrames) + " a camera path may hold");
    const std::size_t frameCount = std::size_t(std::max(0.0, std::ceil(span - 1e-4))) + 1;
    if (double(frameCount) * double(steps.size() + tracks.size()) > kMaxSampleWork)
        r.fail(animField, "animation " + r.label(anim) + " moves " + std::to_string(tracks.size()) + " channels over " +
                              std::to_string(steps.size()) + " transform steps at " + std::to_string(frameCount) +
                              " frames: more work than this reader does (lower the frame rate)");

    // The target distance: base's, kept clear of rounding far from the
    // origin (as frameBounds does), so the target never lands on the position.
    const double baseDistance = glm::length(base.target - base.position);
    CameraPath out;
    out.frames.reserve(frameCount);
    for (std::size_t f = 0; f < frameCount; ++f) {
        const double t = f + 1 == frameCount ? t1 : std::min(t0 + double(f) / fps, t1);
        const glm::dmat4 world = worldAt(r, steps, tracks, t, f, animField);
        GltfCameraPose pose;
        if (!gltfCameraPose(world, pose))
            r.fail(animField, "at " + num(t) + " s (frame " + std::to_string(f) + ") the " + cameraLabel +
                                  "'s world transform is singular (a zero scale?)");
        CameraPathFrame frame;
        frame.time = t;
        frame.camera = base;
        frame.camera.position = pose.position;
        frame.camera.up = pose.up;
        const double reach = std::max({std::abs(pose.position.x), std::abs(pose.position.y), std::abs(pose.position.z)});
        frame.camera.target = pose.position + pose.forward * std::max(baseDistance, 1e-9 * reach);
        if (std::string e = frame.camera.validate(); !e.empty())
            r.fail(animField, "at " + num(t) + " s (frame " + std::to_string(f) + ") the " + cameraLabel +
                                  " gives an unusable camera (" + e + ")");
        out.frames.push_back(std::move(frame));
    }

    std::size_t animatedAncestors = 0;
    for (const ChainStep& s : steps) animatedAncestors += s.node >= 0 && s.node != camNode;
    const std::string& name = A.name;
    out.description = (name.empty() ? idx("animations", anim) : "animation '" + name + "'") + " of " + fileName(path) +
                      ": " + cameraLabel +
                      (animatedAncestors ? " and " + std::to_string(animatedAncestors) +
                                               (animatedAncestors == 1 ? " animated ancestor" : " animated ancestors")
                                         : std::string()) +
                      ", " + num(t0) + ".." + num(t1) + " s at " + num(fps) + " fps, " + std::to_string(frameCount) +
                      (frameCount == 1 ? " frame" : " frames");
    if (animation.empty() && moving.size() > 1) {
        out.description += "; the first of " + std::to_string(moving.size()) + " animations that move it (also ";
        for (std::size_t i = 1; i < moving.size() && i < 4; ++i) out.description += (i > 1 ? ", " : "") + r.label(moving[i]);
        out.description += moving.size() > 4 ? ", ...)" : ")";
    }
    return out;
}

} // namespace

CameraPath loadCameraPath(const std::string& path, const Camera& base, double fps, const std::string& animation,
                          std::size_t maxFrames, const std::string& camera) {
    if (!(fps > 0 && fps <= kMaxFps)) throw SettingsError("fps", "must be in (0, 1000] frames per second, not " + num(fps));
    if (maxFrames == 0) throw SettingsError("max-frames", "must be at least 1");
    if (std::string e = base.validate(); !e.empty())
        throw SettingsError("camera", "the camera a path starts from is invalid (" + e + ")");
    if (isGltfPath(path) || hasGlbMagic(path)) return readGltfPath(path, base, fps, animation, maxFrames, camera);
    if (!animation.empty())
        throw SettingsError("animation", "'" + animation + "': " + path + " is a JSON list of cameras, which has no animations");
    return readJsonPath(path, base, fps, maxFrames);
}

} // namespace lc
