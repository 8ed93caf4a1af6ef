#pragma once
// Wording shared by the Report dock's files: durations, counts and lists as
// the dock shows them.

#include <QString>

#include <cstddef>
#include <string>
#include <vector>

namespace lcui::reporttext {

// "4 h 34 min", "12 min", "40 s", "under a second".
QString duration(double seconds);
// "about 12 min" (a duration under a second is not "about").
QString aboutTime(double seconds);
// 1,234,567.
QString count(std::size_t n);
// "a,b,c".
QString join(const std::vector<std::string>& values);

} // namespace lcui::reporttext
