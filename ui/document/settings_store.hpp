#pragma once
// The culling parameters the studio remembers between sessions (QSettings
// group "params", one value per parameter by its CLI name). The camera-owned
// parameters (width, height, near, far, fov) belong to the scene: they are
// written, and read into a scratch camera that is thrown away.

#include "culling/core/params.hpp"

class QSettings;

namespace lcui {

// `base` with every remembered parameter that parses applied (a value this
// build no longer accepts is skipped, not an error).
lc::CullSettings readCullSettings(QSettings& st, lc::CullSettings base);
void writeCullSettings(QSettings& st, const lc::CullSettings& s);

} // namespace lcui
