#pragma once
// Durable file writes shared by the exporters, scene saving and the CLI.

#include <functional>
#include <set>
#include <string>

namespace lc {

// Writes `text` to `path` (created or truncated) and fsyncs it. Throws Error
// naming the path.
void writeFileSynced(const std::string& path, const std::string& text);

// Atomic replace: writes a temporary sibling of `path`, fsyncs it, renames it
// onto `path` and fsyncs the folder, so a crash leaves either the old file or
// the new one, never a truncated one. On failure the temporary file is
// removed and `path` is untouched. Throws Error naming the file.
void writeFileAtomic(const std::string& path, const std::string& text);

// What writeFileAtomic needs of `path` before it writes: a file name in a
// folder that exists, not a folder. Throws Error naming them (callers check
// it before long work).
void checkFileTarget(const std::string& path);

// The FNV-1a 64-bit hash of a file's bytes as 16 hex digits, to record which
// version of a file a result came from (not a cryptographic hash). Throws
// Error naming the file when it cannot be read.
std::string fileHashFnv1a64(const std::string& path);

// fsyncs a folder (its entries' names). Throws Error naming it.
void syncFolder(const std::string& path);

// Atomic folder: `fill` writes the outputs into a new temporary folder beside
// `dir`, which is synced and renamed onto `dir`; a crash or a throw leaves the
// old folder (or none), never a half-written one. An existing `dir` is only
// replaced when it holds nothing but names from `outputs`, so a mistyped
// `--out ~` cannot wipe a home folder. Messages read "cannot <action> into
// DIR: ..." and "... which is not a <outputKind>".
void writeFolderAtomic(const std::string& dir, const std::set<std::string>& outputs, const std::string& action,
                       const std::string& outputKind, const std::function<void(const std::string& tmp)>& fill);
// writeFolderAtomic's checks of `dir` alone (with its messages), for callers
// to run before long work. Temporary folders an interrupted writer left
// beside `dir` are removed by the next writeFolderAtomic there.
void checkFolderTarget(const std::string& dir, const std::set<std::string>& outputs, const std::string& action,
                       const std::string& outputKind);

// An argument as a POSIX shell takes it back: unchanged when it holds only
// letters, digits and -_./:=,+@%; else in single quotes (a quote as '\'').
// For the commands the tool writes down (summary.json, a hunt's scripts).
std::string shellQuote(const std::string& arg);

} // namespace lc
