// PLY reader: ascii, binary_little_endian and binary_big_endian; header with
// comments and obj_info; elements in any order; vertex x, y, z of any scalar
// type; the face list "vertex_indices" (or "vertex_index") with any count and
// index integer types; every other element and property (lists included) is
// skipped. See mesh_readers.hpp for the promises every reader keeps.

#include "culling/core/errors.hpp"
#include "scene/mesh_readers.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace lc::meshio {

namespace {

enum class Scalar { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

bool scalarFromName(std::string_view n, Scalar& s) {
    struct Entry {
        const char* name;
        Scalar type;
    };
    static const Entry kTypes[] = {
        {"char", Scalar::Int8},      {"int8", Scalar::Int8},       {"uchar", Scalar::UInt8},
        {"uint8", Scalar::UInt8},    {"short", Scalar::Int16},     {"int16", Scalar::Int16},
        {"ushort", Scalar::UInt16},  {"uint16", Scalar::UInt16},   {"int", Scalar::Int32},
        {"int32", Scalar::Int32},    {"uint", Scalar::UInt32},     {"uint32", Scalar::UInt32},
        {"float", Scalar::Float32},  {"float32", Scalar::Float32}, {"double", Scalar::Float64},
        {"float64", Scalar::Float64}};
    for (const Entry& e : kTypes)
        if (n == e.name) {
            s = e.type;
            return true;
        }
    return false;
}

std::size_t scalarSize(Scalar s) {
    switch (s) {
    case Scalar::Int8:
    case Scalar::UInt8:
        return 1;
    case Scalar::Int16:
    case Scalar::UInt16:
        return 2;
    case Scalar::Int32:
    case Scalar::UInt32:
    case Scalar::Float32:
        return 4;
    case Scalar::Float64:
        return 8;
    }
    return 1;
}

bool isInteger(Scalar s) {
    return s != Scalar::Float32 && s != Scalar::Float64;
}

struct Property {
    std::string name;
    bool isList = false;
    Scalar type = Scalar::Float32;    // the value type (the item type for lists)
    Scalar countType = Scalar::UInt8; // lists only
};

// What an element's values are used for.
enum class Role { Skip, X, Y, Z, FaceIndices };

struct Element {
    std::string name;
    std::uint64_t count = 0;
    int line = 0; // header line, for messages
    std::vector<Property> props;
    std::vector<Role> roles;
};

enum class Format { Ascii, BinaryLE, BinaryBE };

struct Header {
    Format format = Format::Ascii;
    std::vector<Element> elements;
    std::size_t bodyOffset = 0; // first byte after "end_header\n"
    int lines = 0;              // header lines, so ASCII body line k is lines + k
};

std::vector<std::string_view> words(std::string_view line) {
    std::vector<std::string_view> w;
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && (line[i] == ' ' || line[i] == '\t'))
            ++i;
        const std::size_t b = i;
        while (i < line.size() && line[i] != ' ' && line[i] != '\t')
            ++i;
        if (i > b) w.push_back(line.substr(b, i - b));
    }
    return w;
}

Header parseHeader(std::string_view bytes, const std::string& path) {
    Header h;
    std::size_t pos = 0;
    int n = 0;
    bool sawFormat = false;
    auto fail = [&](const std::string& what) { throw InputError(path, "", n, "PLY header: " + what); };
    while (pos < bytes.size()) {
        std::size_t nl = bytes.find('\n', pos);
        const bool lastLine = nl == std::string_view::npos;
        if (lastLine) nl = bytes.size();
        std::string_view line = bytes.substr(pos, nl - pos);
        pos = lastLine ? nl : nl + 1;
        ++n;
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        if (n == 1) {
            if (line != "ply") fail("the first line must be \"ply\"");
            continue;
        }
        const std::vector<std::string_view> w = words(line);
        if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
        if (w[0] == "end_header") {
            if (w.size() != 1) fail("bad end_header line " + quoted(line));
            if (!sawFormat) fail("no format line before end_header");
            h.bodyOffset = pos;
            h.lines = n;
            return h;
        }
        if (w[0] == "format") {
            if (w.size() != 3 || w[2] != "1.0" ||
                (w[1] != "ascii" && w[1] != "binary_little_endian" && w[1] != "binary_big_endian"))
                fail("bad format line " + quoted(line));
            if (sawFormat) fail("a second format line " + quoted(line));
            sawFormat = true;
            h.format = w[1] == "ascii"                  ? Format::Ascii
                       : w[1] == "binary_little_endian" ? Format::BinaryLE
                                                        : Format::BinaryBE;
        } else if (w[0] == "element") {
            std::int64_t count = -1;
            if (w.size() != 3 || !parseInteger(w[2], count) || count < 0)
                fail("an element line is \"element <name> <count>\", not " + quoted(line));
            Element e;
            e.name = std::string(w[1]);
            e.count = std::uint64_t(count);
            e.line = n;
            // Every item of an element with a property takes at least one
            // byte of the file, so no count may exceed its size. (Checked
            // again against the remaining bytes once the properties are known.)
            if (e.count > bytes.size())
                fail("element '" + e.name + "' announces " + std::to_string(e.count) +
                     " items, more than the " + std::to_string(bytes.size()) + "-byte file can hold");
            h.elements.push_back(std::move(e));
        } else if (w[0] == "property") {
            if (h.elements.empty()) fail("property before any element: " + quoted(line));
            Property p;
            if (w.size() == 5 && w[1] == "list") {
                p.isList = true;
                if (!scalarFromName(w[2], p.countType) || !scalarFromName(w[3], p.type))
                    fail("unknown property type in " + quoted(line));
                if (!isInteger(p.countType))
                    fail("a list's count type must be an integer type: " + quoted(line));
                p.name = std::string(w[4]);
            } else if (w.size() == 3 && w[1] != "list") {
                if (!scalarFromName(w[1], p.type)) fail("unknown property type in " + quoted(line));
                p.name = std::string(w[2]);
            } else {
                fail("bad property line " + quoted(line));
            }
            h.elements.back().props.push_back(std::move(p));
        } else {
            fail("unknown header line " + quoted(line));
        }
    }
    throw InputError(path, "", n, "PLY header has no \"end_header\" line");
}

// Assigns roles and finds the vertex and face elements.
void assignRoles(Header& h, const std::string& path, std::uint64_t& vertexCount) {
    bool sawVertex = false, sawFace = false;
    for (Element& e : h.elements) {
        e.roles.assign(e.props.size(), Role::Skip);
        if (e.name == "vertex") {
            if (sawVertex) throw InputError(path, "", e.line, "PLY header: a second 'vertex' element");
            sawVertex = true;
            vertexCount = e.count;
            const char* axes[3] = {"x", "y", "z"};
            for (int a = 0; a < 3; ++a) {
                std::size_t found = e.props.size();
                for (std::size_t i = 0; i < e.props.size(); ++i)
                    if (e.props[i].name == axes[a]) {
                        found = i;
                        break;
                    }
                if (found == e.props.size())
                    throw InputError(path, "", e.line,
                                     std::string("PLY header: element 'vertex' has no property '") + axes[a] +
                                         "'");
                if (e.props[found].isList)
                    throw InputError(path, "", e.line,
                                     std::string("PLY header: vertex property '") + axes[a] + "' is a list");
                e.roles[found] = Role(int(Role::X) + a);
            }
        } else if (e.name == "face") {
            if (sawFace) throw InputError(path, "", e.line, "PLY header: a second 'face' element");
            sawFace = true;
            std::size_t found = e.props.size();
            for (std::size_t i = 0; i < e.props.size() && found == e.props.size(); ++i)
                if (e.props[i].name == "vertex_indices") found = i;
            for (std::size_t i = 0; i < e.props.size() && found == e.props.size(); ++i)
                if (e.props[i].name == "vertex_index") found = i;
            if (found == e.props.size())
                throw InputError(
                    path, "", e.line,
                    "PLY header: element 'face' has no list property 'vertex_indices' or 'vertex_index'");
            const Property& p = e.props[found];
            if (!p.isList)
                throw InputError(path, "", e.line,
                                 "PLY header: face property '" + p.name + "' is not a list");
            if (!isInteger(p.type))
                throw InputError(path, "", e.line,
                                 "PLY header: face property '" + p.name +
                                     "' must hold integer vertex indices");
            e.roles[found] = Role::FaceIndices;
        }
    }
    if (!sawVertex) throw InputError(path, "", h.lines, "PLY header declares no 'vertex' element");
    if (!sawFace) throw InputError(path, "", h.lines, "PLY header declares no 'face' element");
}

// The shared face bookkeeping of both body readers.
struct Sink {
    FlatMesh& out;
    std::uint64_t vertexCount;
    const std::string& path;
    void beginFace() {
        if (out.polyIndices.size() > std::numeric_limits<std::uint32_t>::max())
            throw InputError(path, "", 0, "more than 2^32 face corners");
        out.polyStart.push_back(std::uint32_t(out.polyIndices.size()));
    }
};

std::string itemName(const Element& e, std::uint64_t i) {
    return "element '" + e.name + "' " + std::to_string(i) + " of " + std::to_string(e.count);
}

// ---- ASCII body ------------------------------------------------------------

class AsciiBody {
  public:
    AsciiBody(std::string_view bytes, std::size_t offset, int line, const ReadContext& ctx)
        : bytes_(bytes), pos_(offset), line_(line + 1), ctx_(ctx) {}

    // The next whitespace-separated token; empty at the end of the file.
    std::string_view next() {
        while (pos_ < bytes_.size()) {
            const char c = bytes_[pos_];
            if (c == '\n') {
                ++line_;
            } else if (c != ' ' && c != '\t' && c != '\r') {
                break;
            }
            ++pos_;
        }
        const std::size_t b = pos_;
        while (pos_ < bytes_.size()) {
            const char c = bytes_[pos_];
            if (c == ' ' || c == '\t' || c == '\r' || c == '\n') break;
            ++pos_;
        }
        // At the end of the file, messages name the line of the last token.
        if (pos_ > b) tokenLine_ = line_;
        return bytes_.substr(b, pos_ - b);
    }
    // Messages name the line of the token read last.
    [[noreturn]] void fail(const std::string& what) const {
        throw InputError(ctx_.path, "", tokenLine_, what);
    }
    std::string_view need(const Element& e, std::uint64_t i) {
        std::string_view t = next();
        if (t.empty()) fail("PLY file ends inside " + itemName(e, i));
        return t;
    }
    std::int64_t integer(const Element& e, std::uint64_t i, const Property& p) {
        const std::string_view t = need(e, i);
        std::int64_t v = 0;
        if (!parseInteger(t, v))
            fail(itemName(e, i) + ", property '" + p.name + "': " + quoted(t) + " is not a whole number");
        return v;
    }
    std::size_t offset() const { return pos_; }
    std::size_t remaining() const { return bytes_.size() - pos_; }

  private:
    std::string_view bytes_;
    std::size_t pos_;
    int line_;
    int tokenLine_ = line_;
    const ReadContext& ctx_;
};

void readAsciiBody(std::string_view bytes, const Header& h, const ReadContext& ctx, Sink& sink) {
    AsciiBody body(bytes, h.bodyOffset, h.lines, ctx);
    for (const Element& e : h.elements) {
        if (e.props.empty()) continue; // items with no values take no text
        // Each item takes at least one token of at least two bytes (a digit
        // and a separator), bar the file's last.
        if (e.count > body.remaining() / 2 + 1)
            throw InputError(ctx.path, "", e.line,
                             "PLY header: element '" + e.name + "' announces " + std::to_string(e.count) +
                                 " items, more than the rest of the file can hold");
        const bool isVertex = e.name == "vertex";
        if (isVertex) sink.out.positions.reserve(std::size_t(e.count) * 3);
        if (e.name == "face") sink.out.polyStart.reserve(std::size_t(e.count));
        for (std::uint64_t i = 0; i < e.count; ++i) {
            if ((i & 0xFFFF) == 0xFFFF) ctx.tick(body.offset(), bytes.size());
            float xyz[3] = {0, 0, 0};
            for (std::size_t k = 0; k < e.props.size(); ++k) {
                const Property& p = e.props[k];
                const Role role = e.roles[k];
                if (!p.isList) {
                    const std::string_view t = body.need(e, i);
                    if (role == Role::Skip) continue;
                    // A float column is rounded once, straight to float.
                    float v = 0;
                    double d = 0;
                    const bool ok = p.type == Scalar::Float64 ? parseNumber(t, d) : parseFloat(t, v);
                    if (!ok)
                        body.fail(itemName(e, i) + ", property '" + p.name + "': " + quoted(t) +
                                  " is not a number");
                    if (p.type == Scalar::Float64)
                        v = std::isfinite(d) && std::abs(d) <= std::numeric_limits<float>::max() ? float(d)
                                                                                                 : HUGE_VALF;
                    if (!std::isfinite(v))
                        body.fail("vertex " + std::to_string(i) + " has a non-finite coordinate " +
                                  quoted(t));
                    xyz[int(role) - int(Role::X)] = v;
                    continue;
                }
                const std::int64_t n = body.integer(e, i, p);
                // Every list item takes at least one byte.
                if (n < 0 || std::uint64_t(n) > body.remaining())
                    body.fail(itemName(e, i) + ": list '" + p.name + "' announces " + std::to_string(n) +
                              " items; expected a count the rest of the file can hold");
                if (role == Role::FaceIndices) sink.beginFace();
                for (std::int64_t j = 0; j < n; ++j) {
                    if (role != Role::FaceIndices) {
                        body.need(e, i);
                        continue;
                    }
                    const std::int64_t v = body.integer(e, i, p);
                    if (v < 0 || std::uint64_t(v) >= sink.vertexCount)
                        body.fail("face " + std::to_string(i) + " refers to vertex " + std::to_string(v) +
                                  ", outside 0.." + std::to_string(std::int64_t(sink.vertexCount) - 1));
                    sink.out.polyIndices.push_back(v);
                }
            }
            if (isVertex) sink.out.positions.insert(sink.out.positions.end(), xyz, xyz + 3);
        }
    }
}

// ---- binary body -----------------------------------------------------------

class BinaryBody {
  public:
    BinaryBody(std::string_view bytes, std::size_t offset, bool swap, const ReadContext& ctx)
        : bytes_(bytes), pos_(offset), swap_(swap), ctx_(ctx) {}

    [[noreturn]] void fail(const std::string& what) const {
        throw InputError(ctx_.path, "", 0, what + " (byte offset " + std::to_string(pos_) + ")");
    }
    void need(std::size_t n, const Element& e, std::uint64_t i) const {
        if (bytes_.size() - pos_ < n) fail("PLY file ends inside " + itemName(e, i));
    }
    void skip(std::size_t n, const Element& e, std::uint64_t i) {
        need(n, e, i);
        pos_ += n;
    }
    double real(Scalar t, const Element& e, std::uint64_t i) {
        unsigned char b[8];
        load(b, t, e, i);
        switch (t) {
        case Scalar::Float32: {
            float f;
            std::memcpy(&f, b, 4);
            return f;
        }
        case Scalar::Float64: {
            double d;
            std::memcpy(&d, b, 8);
            return d;
        }
        default:
            return double(asInteger(b, t));
        }
    }
    // Integer types only (the header checked that).
    std::int64_t integer(Scalar t, const Element& e, std::uint64_t i) {
        unsigned char b[8];
        load(b, t, e, i);
        return asInteger(b, t);
    }
    std::size_t offset() const { return pos_; }
    std::size_t remaining() const { return bytes_.size() - pos_; }

  private:
    // Copies one value in host byte order.
    void load(unsigned char* b, Scalar t, const Element& e, std::uint64_t i) {
        const std::size_t n = scalarSize(t);
        need(n, e, i);
        std::memcpy(b, bytes_.data() + pos_, n);
        if (swap_) std::reverse(b, b + n);
        pos_ += n;
    }
    static std::int64_t asInteger(const unsigned char* b, Scalar t) {
        switch (t) {
        case Scalar::Int8:
            return std::int8_t(b[0]);
        case Scalar::UInt8:
            return b[0];
        case Scalar::Int16: {
            std::int16_t v;
            std::memcpy(&v, b, 2);
            return v;
        }
        case Scalar::UInt16: {
            std::uint16_t v;
            std::memcpy(&v, b, 2);
            return v;
        }
        case Scalar::Int32: {
            std::int32_t v;
            std::memcpy(&v, b, 4);
            return v;
        }
        case Scalar::UInt32: {
            std::uint32_t v;
            std::memcpy(&v, b, 4);
            return v;
        }
        default:
            return 0;
        }
    }

    std::string_view bytes_;
    std::size_t pos_;
    bool swap_;
    const ReadContext& ctx_;
};

bool hostIsLittleEndian() {
    const std::uint16_t one = 1;
    unsigned char b;
    std::memcpy(&b, &one, 1);
    return b == 1;
}

void readBinaryBody(std::string_view bytes, const Header& h, const ReadContext& ctx, Sink& sink) {
    const bool swap = (h.format == Format::BinaryLE) != hostIsLittleEndian();
    BinaryBody body(bytes, h.bodyOffset, swap, ctx);
    for (const Element& e : h.elements) {
        if (e.props.empty()) continue;
        std::size_t minItem = 0; // bytes of one item at least (lists count their count only)
        for (const Property& p : e.props)
            minItem += scalarSize(p.isList ? p.countType : p.type);
        if (e.count > body.remaining() / minItem)
            throw InputError(ctx.path, "", e.line,
                             "PLY header: element '" + e.name + "' announces " + std::to_string(e.count) +
                                 " items of at least " + std::to_string(minItem) + " bytes, more than the " +
                                 std::to_string(body.remaining()) + " bytes after the header hold");
        const bool isVertex = e.name == "vertex";
        if (isVertex) sink.out.positions.reserve(std::size_t(e.count) * 3);
        if (e.name == "face") sink.out.polyStart.reserve(std::size_t(e.count));
        for (std::uint64_t i = 0; i < e.count; ++i) {
            if ((i & 0xFFFF) == 0xFFFF) ctx.tick(body.offset(), bytes.size());
            float xyz[3] = {0, 0, 0};
            for (std::size_t k = 0; k < e.props.size(); ++k) {
                const Property& p = e.props[k];
                const Role role = e.roles[k];
                if (!p.isList) {
                    if (role == Role::Skip) {
                        body.skip(scalarSize(p.type), e, i);
                        continue;
                    }
                    const double v = body.real(p.type, e, i);
                    if (!std::isfinite(v) || std::abs(v) > std::numeric_limits<float>::max())
                        body.fail("vertex " + std::to_string(i) + " has a non-finite coordinate");
                    xyz[int(role) - int(Role::X)] = float(v);
                    continue;
                }
                const std::int64_t n = body.integer(p.countType, e, i);
                const std::size_t itemSize = scalarSize(p.type);
                if (n < 0 || std::uint64_t(n) > body.remaining() / itemSize)
                    body.fail(itemName(e, i) + ": list '" + p.name + "' announces " + std::to_string(n) +
                              " items; expected a count the rest of the file can hold");
                if (role != Role::FaceIndices) {
                    body.skip(std::size_t(n) * itemSize, e, i);
                    continue;
                }
                sink.beginFace();
                for (std::int64_t j = 0; j < n; ++j) {
                    const std::int64_t v = body.integer(p.type, e, i);
                    if (v < 0 || std::uint64_t(v) >= sink.vertexCount)
                        body.fail("face " + std::to_string(i) + " refers to vertex " + std::to_string(v) +
                                  ", outside 0.." + std::to_string(std::int64_t(sink.vertexCount) - 1));
                    sink.out.polyIndices.push_back(v);
                }
            }
            if (isVertex) sink.out.positions.insert(sink.out.positions.end(), xyz, xyz + 3);
        }
    }
}

} // namespace

void readPly(std::string_view bytes, const ReadContext& ctx, FlatMesh& out) {
    Header h = parseHeader(bytes, ctx.path);
    std::uint64_t vertexCount = 0;
    assignRoles(h, ctx.path, vertexCount);
    Sink sink{out, vertexCount, ctx.path};
    if (h.format == Format::Ascii) {
        readAsciiBody(bytes, h, ctx, sink);
    } else {
        readBinaryBody(bytes, h, ctx, sink);
    }
}

} // namespace lc::meshio
