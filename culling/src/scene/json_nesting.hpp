// A bound on JSON nesting, checked before a parser sees the text. tinygltf's
// parser recurses once per nested array or object (tens of thousands of
// levels overflow the stack), and the scene reader's path for every value
// grows with the depth (memory the square of it). No scene or glTF file
// needs more than a few dozen levels; `extras` may hold anything, so the
// bound is generous.
#pragma once

#include <cstddef>
#include <string_view>

namespace lc {

constexpr int kMaxJsonNesting = 256;

// The 1-based line on which `text` opens its (kMaxJsonNesting + 1)th nested
// array or object, or 0 if it never nests that deep. Brackets inside strings
// do not count; the text need not be valid JSON.
inline int jsonNestingTooDeep(std::string_view text) {
    int depth = 0, line = 1;
    bool inString = false, escaped = false;
    for (char c : text) {
        if (c == '\n') ++line;
        if (inString) {
            if (escaped) escaped = false;
            else if (c == '\\') escaped = true;
            else if (c == '"') inString = false;
        } else if (c == '"') {
            inString = true;
        } else if (c == '[' || c == '{') {
            if (++depth > kMaxJsonNesting) return line;
        } else if (c == ']' || c == '}') {
            if (depth > 0) --depth;
        }
    }
    return 0;
}

} // namespace lc
