#pragma once
// Typed errors of the culling library. Every error a user can cause names what
// was wrong (file, field, line, light); none of them ends the process.

#include <stdexcept>
#include <string>

namespace lc {

// Base of every error the library throws for bad input or a failed device.
class Error : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Bad input in a file: `file` and, where known, the 1-based `line` and the
// JSON `field` path (e.g. "lights[3].intensity").
class InputError : public Error {
public:
    InputError(std::string file, std::string field, int line, const std::string& what);
    const std::string& file() const { return file_; }
    const std::string& field() const { return field_; }
    int line() const { return line_; }

private:
    std::string file_, field_;
    int line_;
};

// A light whose values cannot be culled (non-finite, I_min <= 0, ...).
class LightError : public Error {
public:
    LightError(std::size_t index, std::string name, const std::string& what);
    std::size_t index() const { return index_; }
    const std::string& lightName() const { return name_; }

private:
    std::size_t index_;
    std::string name_;
};

// A camera or settings value out of range; `field` names it.
class SettingsError : public Error {
public:
    SettingsError(std::string field, const std::string& what);
    const std::string& field() const { return field_; }

private:
    std::string field_;
};

// A failed Vulkan call (thrown from the Vulkan backend): the call, the result
// code and where in the source it was made.
class DeviceError : public Error {
public:
    using Error::Error;
};

// The user cancelled a long operation through a CancelToken.
class Cancelled : public Error {
public:
    Cancelled() : Error("cancelled") {}
};

} // namespace lc
