#pragma once
// Runs the built `lightcull` CLI (LC_CLI_PATH) as a child process and
// captures its exit code, stdout and stderr. Shared by test_cli and
// test_end_to_end.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace lc_test {

struct CliResult {
    int code = -1;
    std::string out, err;
};

inline std::string slurp(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

// Arguments go through fork/exec (no shell), so nothing needs quoting.
inline CliResult runCli(const std::vector<std::string>& args, const std::filesystem::path& scratch) {
    const std::filesystem::path outFile = scratch / ".cli_stdout", errFile = scratch / ".cli_stderr";
    const pid_t pid = ::fork();
    if (pid == 0) {
        std::vector<char*> argv;
        std::string exe = LC_CLI_PATH;
        argv.push_back(exe.data());
        std::vector<std::string> copy = args;
        for (auto& a : copy) argv.push_back(a.data());
        argv.push_back(nullptr);
        if (!std::freopen(outFile.c_str(), "w", stdout) || !std::freopen(errFile.c_str(), "w", stderr))
            ::_exit(126);
        ::execv(exe.c_str(), argv.data());
        ::_exit(127);
    }
    CliResult r;
    int status = 0;
    ::waitpid(pid, &status, 0);
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    r.out = slurp(outFile);
    r.err = slurp(errFile);
    std::filesystem::remove(outFile);
    std::filesystem::remove(errFile);
    return r;
}

// Runs a hunt's repro.sh (LIGHTCULL set to the CLI under test) the way a
// user would: its exit code (-1 when it did not exit) and, in *log, what
// it printed.
inline int runReproScript(const std::filesystem::path& dir, std::string* log = nullptr) {
    const std::filesystem::path logFile = dir.parent_path() / (dir.filename().string() + ".repro.log");
    const std::string cmd = "LIGHTCULL='" + std::string(LC_CLI_PATH) + "' sh '" + (dir / "repro.sh").string() +
                            "' >'" + logFile.string() + "' 2>&1";
    const int status = std::system(cmd.c_str());
    if (log) *log = slurp(logFile);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

inline std::size_t lineCount(const std::string& s) {
    std::size_t n = 0;
    for (char c : s) n += c == '\n';
    return n + (!s.empty() && s.back() != '\n');
}

// A fresh, empty folder under the system temp dir, removed at the end.
struct ScratchDir {
    std::filesystem::path path;
    ScratchDir() {
        std::string t = (std::filesystem::temp_directory_path() / "lc_cli_XXXXXX").string();
        path = ::mkdtemp(t.data());
    }
    ~ScratchDir() { std::filesystem::remove_all(path); }
};

} // namespace lc_test
