#include "culling/core/file_io.hpp"

#include "culling/core/errors.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <signal.h>
#include <sys/stat.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>

namespace lc {

namespace {
// The process's umask, read without setting it (umask(2) would change it
// for every thread for a moment): Linux reports it in /proc/self/status.
mode_t processUmask() {
    std::FILE* f = std::fopen("/proc/self/status", "r");
    mode_t mask = 022;
    if (!f) return mask;
    char line[256];
    while (std::fgets(line, sizeof line, f))
        if (std::strncmp(line, "Umask:", 6) == 0) {
            mask = mode_t(std::strtoul(line + 6, nullptr, 8));
            break;
        }
    std::fclose(f);
    return mask;
}
} // namespace

void writeFileSynced(const std::string& path, const std::string& text) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) throw Error("cannot create " + path + ": " + std::strerror(errno));
    std::size_t done = 0;
    while (done < text.size()) {
        const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
        if (n < 0) {
            if (errno == EINTR) continue;
            const int err = errno;
            ::close(fd);
            throw Error("cannot write " + path + ": " + std::strerror(err));
        }
        done += std::size_t(n);
    }
    // fsync before any rename: otherwise a crash can leave the new name
    // pointing at an empty file.
    if (::fsync(fd) != 0) {
        const int err = errno;
        ::close(fd);
        throw Error("cannot sync " + path + ": " + std::strerror(err));
    }
    if (::close(fd) != 0) throw Error("cannot write " + path + ": " + std::strerror(errno));
}

void writeFileAtomic(const std::string& path, const std::string& text) {
    namespace fs = std::filesystem;
    checkFileTarget(path);
    const fs::path target(path);
    const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
    const std::string tmp = (dir / ("." + target.filename().string() + ".tmp." + std::to_string(::getpid()))).string();
    try {
        writeFileSynced(tmp, text);
    } catch (const Error&) {
        ::unlink(tmp.c_str());
        throw;
    }
    if (::rename(tmp.c_str(), path.c_str()) != 0) {
        const int err = errno;
        ::unlink(tmp.c_str());
        throw Error("cannot rename " + tmp + " to " + path + ": " + std::strerror(err));
    }
    if (const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC); dfd >= 0) {
        ::fsync(dfd); // make the rename itself durable; best effort
        ::close(dfd);
    }
}

void syncFolder(const std::string& path) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) throw Error("cannot open " + path + " to sync it: " + std::strerror(errno));
    const int rc = ::fsync(fd);
    const int err = errno;
    ::close(fd);
    if (rc != 0) throw Error("cannot sync " + path + ": " + std::strerror(err));
}

void checkFileTarget(const std::string& path) {
    namespace fs = std::filesystem;
    const fs::path target(path);
    const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
    std::error_code ec;
    if (path.empty() || !target.has_filename()) throw Error("cannot write '" + path + "': give a file name");
    if (!fs::is_directory(dir, ec))
        throw Error("cannot write " + path + ": folder " + dir.string() + " does not exist");
    if (fs::is_directory(target, ec)) throw Error("cannot write " + path + ": it is a folder");
}

namespace {

// Temporary folders beside `target` that an interrupted writer (its process
// gone) left: ".NAME.tmp-PID-XXXXXX" and ".NAME.old-PID-XXXXXX".
void removeAbandonedTemporaries(const std::filesystem::path& parent, const std::string& name) {
    namespace fs = std::filesystem;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(parent, ec)) {
        const std::string f = e.path().filename().string();
        for (const char* kind : {".tmp-", ".old-"}) {
            const std::string head = "." + name + kind;
            if (f.rfind(head, 0) != 0) continue;
            const std::string rest = f.substr(head.size());
            const auto dash = rest.find('-');
            if (dash == std::string::npos || dash == 0 || rest.find_first_not_of("0123456789") != dash) continue;
            const long pid = std::strtol(rest.substr(0, dash).c_str(), nullptr, 10);
            if (pid > 0 && ::kill(pid_t(pid), 0) != 0 && errno == ESRCH) fs::remove_all(e.path(), ec);
        }
    }
}

// checkFolderTarget's checks; returns the folder and its parent.
std::pair<std::filesystem::path, std::filesystem::path> checkedFolderTarget(const std::string& dir,
                                                                           const std::set<std::string>& outputs,
                                                                           const std::string& action,
                                                                           const std::string& outputKind) {
    namespace fs = std::filesystem;
    fs::path target = fs::path(dir).lexically_normal();
    if (!target.has_filename()) target = target.parent_path();
    const std::string name = target.filename().string();
    if (dir.empty() || name.empty() || name == "." || name == "..")
        throw Error("cannot " + action + " into '" + dir + "': give a folder name");
    fs::path parent = target.parent_path();
    if (parent.empty()) parent = ".";
    std::error_code ec;
    // Missing parent folders are made when writing (as `mkdir -p`), so the
    // docs' `--out out/frame` works in a fresh clone; the nearest one that
    // exists must be a folder.
    for (fs::path p = parent; !fs::is_directory(p, ec); p = p.parent_path()) {
        if (fs::exists(fs::symlink_status(p, ec)))
            throw Error("cannot " + action + " into " + target.string() + ": " + p.string() + " is not a folder");
        if (!p.has_parent_path() || p.parent_path() == p) break;
    }
    if (fs::exists(fs::symlink_status(target, ec))) {
        if (!fs::is_directory(fs::symlink_status(target, ec)))
            throw Error("cannot " + action + " into " + target.string() + ": it exists and is not a folder");
        for (const auto& e : fs::directory_iterator(target, ec))
            if (!outputs.count(e.path().filename().string()))
                throw Error("refusing to replace " + target.string() + ": it holds " + e.path().filename().string() +
                            ", which is not a " + outputKind);
        if (ec) throw Error("cannot read " + target.string() + ": " + ec.message());
    }
    return {target, parent};
}

} // namespace

void checkFolderTarget(const std::string& dir, const std::set<std::string>& outputs, const std::string& action,
                       const std::string& outputKind) {
    checkedFolderTarget(dir, outputs, action, outputKind);
}

void writeFolderAtomic(const std::string& dir, const std::set<std::string>& outputs, const std::string& action,
                       const std::string& outputKind, const std::function<void(const std::string& tmp)>& fill) {
    namespace fs = std::filesystem;
    const auto [target, parent] = checkedFolderTarget(dir, outputs, action, outputKind);
    const std::string name = target.filename().string();
    std::error_code ec;
    const bool exists = fs::exists(fs::symlink_status(target, ec));
    fs::create_directories(parent, ec);
    if (!fs::is_directory(parent, ec))
        throw Error("cannot " + action + " into " + target.string() + ": cannot make its parent folder " +
                    parent.string() + (ec ? ": " + ec.message() : std::string()));
    removeAbandonedTemporaries(parent, name);

    // The writer's pid in the name: a later writer removes what an
    // interrupted one (Ctrl+C in the middle of a large export) left.
    const std::string pid = std::to_string(::getpid());
    std::string tmpl = (parent / ("." + name + ".tmp-" + pid + "-XXXXXX")).string();
    if (!::mkdtemp(tmpl.data()))
        throw Error("cannot create a temporary folder beside " + target.string() + ": " + std::strerror(errno));
    const fs::path tmp = tmpl;
    // mkdtemp makes 0700; the output folder gets what mkdir would give it.
    ::chmod(tmp.c_str(), 0777 & ~processUmask());
    fs::path aside;
    try {
        fill(tmp.string());
        syncFolder(tmp.string());
        if (exists) {
            std::string asideTmpl = (parent / ("." + name + ".old-" + pid + "-XXXXXX")).string();
            if (!::mkdtemp(asideTmpl.data()))
                throw Error("cannot create a temporary folder beside " + target.string() + ": " + std::strerror(errno));
            aside = asideTmpl;
            if (std::rename(target.c_str(), aside.c_str()) != 0) {
                const int err = errno;
                fs::remove(aside, ec);
                aside.clear();
                throw Error("cannot move " + target.string() + " aside: " + std::strerror(err));
            }
        }
        if (std::rename(tmp.c_str(), target.c_str()) != 0) {
            const int err = errno;
            if (!aside.empty()) std::rename(aside.c_str(), target.c_str()); // restore
            aside.clear();
            throw Error("cannot rename " + tmp.string() + " to " + target.string() + ": " + std::strerror(err));
        }
    } catch (...) {
        fs::remove_all(tmp, ec);
        throw;
    }
    if (!aside.empty()) fs::remove_all(aside, ec);
    syncFolder(parent.string());
}

std::string fileHashFnv1a64(const std::string& path) {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) throw Error("cannot read " + path + ": " + std::strerror(errno));
    std::uint64_t h = 0xcbf29ce484222325ull;
    unsigned char buf[1 << 16];
    for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;)
        for (std::size_t i = 0; i < n; ++i) h = (h ^ buf[i]) * 0x100000001b3ull;
    const bool bad = std::ferror(f);
    std::fclose(f);
    if (bad) throw Error("cannot read " + path);
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
    return hex;
}

std::string shellQuote(const std::string& a) {
    if (!a.empty() && a.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_./:=,+@%") ==
                          std::string::npos)
        return a;
    std::string q = "'";
    for (char c : a) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

} // namespace lc
