#pragma once
// "1 light", "3 lights" in the studio's messages: lc::countOf as a QString
// (the studio is not translated; a tr() string takes the result as an
// argument).
#include "culling/core/text.hpp"

#include <QString>

namespace lcui {

inline QString countOf(std::uint64_t n, const char* one, const char* many) {
    return QString::fromStdString(lc::countOf(n, one, many));
}

} // namespace lcui
