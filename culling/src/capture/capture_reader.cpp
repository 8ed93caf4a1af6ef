#include "culling/capture/capture_reader.hpp"

#include "culling/core/errors.hpp"

#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

extern char** environ;

namespace fs = std::filesystem;
using nlohmann::json;

namespace lc {

extern const char* const kReplayScript; // src/capture/replay.py, embedded by CMake

std::string CaptureAction::markerPath() const {
    std::string out;
    for (const std::string& m : markers) out += (out.empty() ? "" : " / ") + m;
    return out;
}

std::string CaptureBinding::where() const {
    std::string names = variable;
    if (!resource.empty() && resource != variable) names += (names.empty() ? "" : ", ") + resource;
    return "set " + std::to_string(set) + " binding " + std::to_string(binding) +
           (element ? "[" + std::to_string(element) + "]" : "") + (names.empty() ? "" : " (" + names + ")");
}

namespace {

// A temporary folder removed with everything in it when this goes.
struct TempDir {
    fs::path path;
    TempDir() {
        const char* base = std::getenv("TMPDIR");
        std::string tmpl = (fs::path(base && *base ? base : "/tmp") / "lightcull-replay-XXXXXX").string();
        std::vector<char> buf(tmpl.begin(), tmpl.end());
        buf.push_back('\0');
        if (!mkdtemp(buf.data())) throw Error("cannot create a temporary folder in " + tmpl);
        path = buf.data();
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path, ec);
    }
};

std::string readFile(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

double replayTimeoutSeconds() {
    if (const char* e = std::getenv("LIGHTCULL_REPLAY_TIMEOUT_S")) {
        char* end = nullptr;
        const double v = std::strtod(e, &end);
        if (end != e && v > 0) return v;
    }
    return 300;
}

std::string pythonPath() {
    if (const char* e = std::getenv("LIGHTCULL_PYTHON"); e && *e) return e;
    // The system interpreter: Debian's python3-renderdoc is built for it (a
    // pyenv or venv python3 first on PATH would not find the module).
    return "/usr/bin/python3";
}

// Runs the replay helper with `args`; returns its JSON reply. Errors the
// helper reports about the file become InputError naming it.
json runReplay(const std::string& capture, const std::vector<std::string>& args, const TempDir& tmp) {
    // A capture starts with "RDOC". RenderDoc's own check of a file that is
    // no capture at all (a text file) now and then crashed the replay
    // (signal 11, RenderDoc 1.24, in the gpu tests), which read as a device
    // failure: such a file is refused here, before any replay.
    if (std::ifstream in(capture, std::ios::binary); in) {
        char magic[4] = {};
        in.read(magic, 4);
        if (in.gcount() < 4 || std::memcmp(magic, "RDOC", 4) != 0)
            throw InputError(capture, "", 0, "not a RenderDoc capture (a capture starts with \"RDOC\")");
    }
    const fs::path script = tmp.path / "replay.py";
    {
        std::ofstream out(script);
        out << kReplayScript;
        if (!out) throw Error("cannot write " + script.string());
    }
    const std::string python = pythonPath();
    if (access(python.c_str(), X_OK) != 0)
        throw DeviceError("cannot run " + python + " to replay RenderDoc captures (Debian 12: apt-get install "
                          "python3 python3-renderdoc; LIGHTCULL_PYTHON names another interpreter)");
    std::vector<std::string> argv{python, script.string()};
    argv.insert(argv.end(), args.begin(), args.end());
    std::vector<char*> cargv;
    for (std::string& a : argv) cargv.push_back(a.data());
    cargv.push_back(nullptr);

    const std::string outPath = (tmp.path / "stdout").string(), errPath = (tmp.path / "stderr").string();
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&fa, 1, outPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    posix_spawn_file_actions_addopen(&fa, 2, errPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    pid_t pid = 0;
    const int rc = posix_spawn(&pid, python.c_str(), &fa, nullptr, cargv.data(), environ);
    posix_spawn_file_actions_destroy(&fa);
    if (rc != 0) throw DeviceError("cannot start " + python + ": " + std::strerror(rc));

    const auto start = std::chrono::steady_clock::now();
    const double limit = replayTimeoutSeconds();
    int status = 0;
    for (;;) {
        const pid_t r = waitpid(pid, &status, WNOHANG);
        if (r == pid) break;
        if (r < 0 && errno != EINTR) throw DeviceError(std::string("waiting for the replay: ") + std::strerror(errno));
        if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > limit) {
            kill(pid, SIGKILL);
            waitpid(pid, &status, 0);
            throw DeviceError(capture + ": RenderDoc's replay ran past " + std::to_string(int(limit)) +
                              " s and was stopped (LIGHTCULL_REPLAY_TIMEOUT_S sets the limit)");
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    const std::string out = readFile(outPath);
    json reply;
    try {
        reply = json::parse(out);
    } catch (const json::exception&) {
        std::string err = readFile(errPath);
        if (const auto nl = err.find_last_not_of("\n "); nl != std::string::npos) err.resize(nl + 1);
        if (const auto last = err.rfind('\n'); last != std::string::npos) err = err.substr(last + 1);
        const std::string how = WIFSIGNALED(status) ? "was killed by signal " + std::to_string(WTERMSIG(status))
                                                    : "exited with status " + std::to_string(WEXITSTATUS(status));
        throw DeviceError(capture + ": RenderDoc's replay " + how + (err.empty() ? "" : ": " + err));
    }
    if (!reply.is_object()) throw DeviceError(capture + ": the replay helper gave no answer");
    if (reply.contains("error")) {
        const std::string message = reply["error"].is_string() ? reply["error"].get<std::string>() : "unknown error";
        if (WIFEXITED(status) && WEXITSTATUS(status) == 3) throw DeviceError(message);
        // The helper names the file itself where the file is at fault.
        if (message.rfind(capture + ": ", 0) == 0) throw InputError(capture, "", 0, message.substr(capture.size() + 2));
        throw InputError(capture, "", 0, message);
    }
    return reply;
}

template <typename T> T field(const json& j, const char* key, T fallback) {
    const auto it = j.find(key);
    if (it == j.end() || it->is_null()) return fallback;
    try {
        return it->get<T>();
    } catch (const json::exception&) {
        return fallback;
    }
}

CaptureBinding bindingFrom(const json& b) {
    CaptureBinding c;
    c.set = field<std::uint32_t>(b, "set", 0);
    c.binding = field<std::uint32_t>(b, "binding", 0);
    c.element = field<std::uint32_t>(b, "element", 0);
    c.kind = field<std::string>(b, "kind", "other");
    c.descriptor = field<std::string>(b, "descriptor", "");
    c.resource = field<std::string>(b, "resource", "");
    c.variable = field<std::string>(b, "variable", "");
    c.offset = field<std::uint64_t>(b, "offset", 0);
    c.size = field<std::uint64_t>(b, "size", 0);
    c.length = field<std::uint64_t>(b, "length", 0);
    c.width = field<std::uint32_t>(b, "width", 0);
    c.height = field<std::uint32_t>(b, "height", 0);
    c.samples = field<std::uint32_t>(b, "samples", 1);
    c.format = field<std::string>(b, "format", "");
    c.componentBytes = field<std::uint32_t>(b, "component_bytes", 0);
    c.components = field<std::uint32_t>(b, "components", 0);
    c.componentType = field<std::string>(b, "component_type", "");
    return c;
}

CaptureInfo infoFrom(const std::string& capture, const json& reply) {
    CaptureInfo info;
    info.file = capture;
    info.renderdoc = field<std::string>(reply, "renderdoc", "");
    if (const auto it = reply.find("actions"); it != reply.end() && it->is_array())
        for (const json& a : *it) {
            CaptureAction c;
            c.event = field<std::uint32_t>(a, "event", 0);
            c.name = field<std::string>(a, "name", "");
            c.kind = field<std::string>(a, "kind", "");
            c.markers = field<std::vector<std::string>>(a, "markers", {});
            const auto dims = field<std::vector<std::uint32_t>>(a, "dims", {});
            for (std::size_t i = 0; i < 3 && i < dims.size(); ++i) c.dims[i] = dims[i];
            info.actions.push_back(std::move(c));
        }
    info.event = field<std::uint32_t>(reply, "event", 0);
    if (const auto it = reply.find("bindings"); it != reply.end() && it->is_array())
        for (const json& b : *it) info.bindings.push_back(bindingFrom(b));
    return info;
}

void checkReadable(const std::string& capture) {
    std::error_code ec;
    if (fs::is_directory(capture, ec)) throw InputError(capture, "", 0, "a folder, not a capture file");
    if (!fs::is_regular_file(capture, ec)) throw InputError(capture, "", 0, "no such file");
    std::ifstream in(capture, std::ios::binary);
    if (!in) throw InputError(capture, "", 0, "cannot read");
}

} // namespace

CaptureInfo readCaptureInfo(const std::string& capture, std::uint32_t event) {
    checkReadable(capture);
    TempDir tmp;
    std::vector<std::string> args{"info", fs::absolute(capture).string()};
    if (event) args.push_back(std::to_string(event));
    CaptureInfo info = infoFrom(capture, runReplay(fs::absolute(capture).string(), args, tmp));
    info.file = capture;
    return info;
}

CaptureInfo readDispatchInfo(const std::string& capture, const std::string& what) {
    checkReadable(capture);
    TempDir tmp;
    CaptureInfo info = infoFrom(capture, runReplay(fs::absolute(capture).string(),
                                                   {"info", fs::absolute(capture).string(), "dispatch:" + what}, tmp));
    info.file = capture;
    // The helper resolves by findDispatch's rule; its errors come from here.
    const std::uint32_t event = findDispatch(info, what);
    return info.event == event ? info : readCaptureInfo(capture, event);
}

std::uint32_t findDispatch(const CaptureInfo& info, const std::string& what) {
    std::vector<const CaptureAction*> dispatches;
    for (const CaptureAction& a : info.actions)
        if (a.kind == "dispatch") dispatches.push_back(&a);
    const auto list = [&](const std::vector<const CaptureAction*>& as) {
        std::string out;
        for (std::size_t i = 0; i < as.size() && i < 8; ++i)
            out += (i ? ", " : "") + std::to_string(as[i]->event) +
                   (as[i]->markers.empty() ? "" : " (" + as[i]->markerPath() + ")");
        if (as.size() > 8) out += ", ...";
        return out.empty() ? std::string("none") : out;
    };
    if (!what.empty() && what.find_first_not_of("0123456789") == std::string::npos && what.size() < 10) {
        const auto event = std::uint32_t(std::stoul(what));
        for (const CaptureAction* a : dispatches)
            if (a->event == event) return event;
        throw InputError(info.file, "", 0,
                         "event " + what + " is not a compute dispatch (dispatches: " + list(dispatches) + ")");
    }
    std::vector<const CaptureAction*> hits;
    for (const CaptureAction* a : dispatches)
        if (a->name.find(what) != std::string::npos || a->markerPath().find(what) != std::string::npos)
            hits.push_back(a);
    if (hits.empty())
        throw InputError(info.file, "", 0,
                         "no compute dispatch named '" + what + "' (dispatches: " + list(dispatches) + ")");
    if (hits.size() > 1)
        throw InputError(info.file, "", 0, "'" + what + "' names " + std::to_string(hits.size()) +
                                               " dispatches: " + list(hits) + "; give the event number");
    return hits.front()->event;
}

namespace {

// One replay that reads `specs` at `at` (an event id, or "dispatch:TEXT");
// `blobs` stays empty when the helper could not resolve TEXT to one dispatch.
json replayRead(const std::string& capture, const std::string& at, const std::map<std::string, std::string>& specs,
                std::map<std::string, CaptureBlob>& blobs) {
    checkReadable(capture);
    TempDir tmp;
    const fs::path data = tmp.path / "data";
    fs::create_directory(data);
    std::vector<std::string> args{"read", fs::absolute(capture).string(), at, data.string()};
    for (const auto& [key, spec] : specs) args.push_back(key + "=" + spec);
    json reply = runReplay(fs::absolute(capture).string(), args, tmp);
    const auto read = reply.find("read");
    if (read == reply.end()) return reply;
    for (const auto& [key, spec] : specs) {
        if (!read->contains(key)) throw DeviceError(capture + ": the replay read no '" + spec + "'");
        CaptureBlob blob;
        blob.binding = bindingFrom((*read)[key]);
        blob.bytes = readFile(data / (key + ".bin"));
        blobs.emplace(key, std::move(blob));
    }
    return reply;
}

} // namespace

std::map<std::string, CaptureBlob> readCaptureBindings(const std::string& capture, std::uint32_t event,
                                                       const std::map<std::string, std::string>& specs) {
    std::map<std::string, CaptureBlob> out;
    replayRead(capture, std::to_string(event), specs, out);
    if (out.size() != specs.size()) throw DeviceError(capture + ": the replay read nothing at event " + std::to_string(event));
    return out;
}

std::map<std::string, CaptureBlob> readDispatchBindings(const std::string& capture, const std::string& dispatch,
                                                        const std::map<std::string, std::string>& specs,
                                                        std::uint32_t& event) {
    std::map<std::string, CaptureBlob> out;
    const json reply = replayRead(capture, "dispatch:" + dispatch, specs, out);
    CaptureInfo info = infoFrom(capture, reply);
    // The same rule as capture-info's: its errors (no such dispatch, several)
    // name the dispatches; the helper resolved by it too.
    event = findDispatch(info, dispatch);
    if (out.size() != specs.size() || info.event != event) {
        out.clear();
        return readCaptureBindings(capture, event, specs);
    }
    return out;
}

} // namespace lc
