#pragma once
// Durable file writes shared by the exporters, scene saving and the CLI.

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

} // namespace lc
