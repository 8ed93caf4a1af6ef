#pragma once
// Words the tool prints and writes about counts.

#include <cstdint>
#include <string>

namespace lc {

// "1 light", "3 lights": the count with the word that agrees with it.
inline std::string countOf(std::uint64_t n, const char* one, const char* many) {
    return std::to_string(n) + " " + (n == 1 ? one : many);
}

} // namespace lc
