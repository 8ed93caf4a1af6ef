#include "culling/core/errors.hpp"

namespace lc {

namespace {
std::string inputMessage(const std::string& file, const std::string& field, int line,
                         const std::string& what) {
    std::string m = file.empty() ? std::string("<input>") : file;
    if (line > 0) m += ":" + std::to_string(line);
    m += ": ";
    if (!field.empty()) m += field + ": ";
    return m + what;
}
} // namespace

InputError::InputError(std::string file, std::string field, int line, const std::string& what)
    : Error(inputMessage(file, field, line, what)), file_(std::move(file)), field_(std::move(field)),
      line_(line) {}

LightError::LightError(std::size_t index, std::string name, const std::string& what)
    : Error("light " + std::to_string(index) + (name.empty() ? "" : " '" + name + "'") + ": " + what),
      index_(index), name_(std::move(name)) {}

SettingsError::SettingsError(std::string field, const std::string& what)
    : Error(field + ": " + what), field_(std::move(field)) {}

} // namespace lc
