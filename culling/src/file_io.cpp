#include "culling/file_io.hpp"

#include "culling/errors.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

namespace lc {

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

} // namespace lc
