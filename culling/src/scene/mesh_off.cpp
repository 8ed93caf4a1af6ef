// ASCII OFF reader. Line-based, as OpenMesh's reader effectively was: after
// the keyword ([ST][C][N]OFF) and the counts line ("<vertices> <faces>
// [<edges>]", which may follow the keyword on its line), each vertex is a line
// whose first three numbers are x, y, z (normals, colours and texture
// coordinates after them are ignored), and each face a line "<n> <i1> .. <in>"
// followed by optional colour columns (ignored). '#' starts a comment
// anywhere; blank lines are skipped. 4OFF and nOFF are refused with a clear
// error.
//
// Binary OFF ("[ST][C][N]OFF BINARY" on the first content line, then binary
// from the next byte) comes in two incompatible layouts, told apart by the
// byte order of the three int32 counts (vertices, faces, edges):
// - little-endian, as OpenMesh 9 writes and reads it: per vertex float32
//   x y z [N: 3 float32] [C: 3 int32] [ST: 2 float32]; per face int32 n,
//   n int32 indices [C: 3 int32];
// - big-endian, as Geomview's manual specifies: per vertex float32 x y z
//   [N: 3 float32] [C: 4 float32] [ST: 2 float32]; per face int32 n, n int32
//   indices, int32 colour count k, k float32.
// The order whose counts the bytes after the header can hold wins; when both
// can (256 vertices and 65,536 faces read 65,536 and 256 the other way round,
// and a large file holds either), little-endian is tried first and big-endian
// if that fails. See mesh_readers.hpp for the promises
// every reader keeps.

#include "culling/core/errors.hpp"
#include "scene/mesh_readers.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

namespace lc::meshio {

namespace {

// Content lines of the file: comments stripped, blank lines skipped, split
// into whitespace-separated tokens.
class Lines {
  public:
    explicit Lines(std::string_view bytes) : bytes_(bytes) {}

    // The next line with a token; false at the end of the file.
    bool next() {
        tokens.clear();
        while (pos_ < bytes_.size()) {
            std::size_t nl = bytes_.find('\n', pos_);
            if (nl == std::string_view::npos) nl = bytes_.size();
            text = bytes_.substr(pos_, nl - pos_);
            pos_ = nl < bytes_.size() ? nl + 1 : nl;
            ++line;
            const std::size_t hash = text.find('#');
            if (hash != std::string_view::npos) text = text.substr(0, hash);
            while (!text.empty() && isSpace(text.back()))
                text.remove_suffix(1);
            while (!text.empty() && isSpace(text.front()))
                text.remove_prefix(1);
            std::size_t i = 0;
            while (i < text.size()) {
                while (i < text.size() && isSpace(text[i]))
                    ++i;
                const std::size_t b = i;
                while (i < text.size() && !isSpace(text[i]))
                    ++i;
                if (i > b) tokens.push_back(text.substr(b, i - b));
            }
            if (!tokens.empty()) return true;
        }
        return false;
    }
    std::size_t offset() const { return pos_; }
    // Whether the current line ended with a newline (binary data follows it).
    bool endedWithNewline() const { return pos_ > 0 && bytes_[pos_ - 1] == '\n'; }

    std::vector<std::string_view> tokens;
    std::string_view text; // the current line without its comment
    int line = 0;          // 1-based number of the current line

  private:
    static bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }
    std::string_view bytes_;
    std::size_t pos_ = 0;
};

// The two binary OFF layouts (see the top of the file).
enum class BinaryOrder { Little, Big };

std::uint32_t loadU32(std::string_view bytes, std::size_t at, BinaryOrder order) {
    const auto b = [&](std::size_t k) { return std::uint32_t(static_cast<unsigned char>(bytes[at + k])); };
    return order == BinaryOrder::Little ? b(0) | b(1) << 8 | b(2) << 16 | b(3) << 24
                                        : b(3) | b(2) << 8 | b(1) << 16 | b(0) << 24;
}

struct BinaryLayout {
    BinaryOrder order;
    std::size_t vertexBytes;     // x y z plus what the prefixes add
    std::size_t faceColourBytes; // little-endian C only; big-endian faces carry a count
    const char* name;            // for messages
};

BinaryLayout binaryLayout(BinaryOrder order, bool st, bool c, bool n) {
    const bool little = order == BinaryOrder::Little;
    return {order, 12 + (n ? 12u : 0u) + (c ? (little ? 12u : 16u) : 0u) + (st ? 8u : 0u),
            little && c ? 12u : 0u, little ? "little-endian (OpenMesh)" : "big-endian (Geomview)"};
}

// Reads the body after the counts. Counts were checked to fit at minimum size.
class BinaryOff {
  public:
    BinaryOff(std::string_view bytes, std::size_t pos, const BinaryLayout& layout, const ReadContext& ctx)
        : bytes_(bytes), pos_(pos), layout_(layout), ctx_(ctx) {}

    [[noreturn]] void fail(const std::string& what, std::size_t at) const {
        throw InputError(ctx_.path, "", 0,
                         std::string("binary OFF file (") + layout_.name + "): " + what + " (byte offset " +
                             std::to_string(at) + ")");
    }
    std::size_t left() const { return bytes_.size() - pos_; }
    std::uint32_t u32() {
        const std::uint32_t v = loadU32(bytes_, pos_, layout_.order);
        pos_ += 4;
        return v;
    }
    std::int32_t i32() { return std::int32_t(u32()); }

    void read(std::uint64_t nv, std::uint64_t nf, FlatMesh& out) {
        out.positions.reserve(std::size_t(nv) * 3);
        for (std::uint64_t v = 0; v < nv; ++v) {
            if ((v & 0xFFFF) == 0xFFFF) ctx_.tick(pos_, bytes_.size());
            const std::size_t at = pos_;
            if (left() < layout_.vertexBytes)
                fail("ends inside vertex " + std::to_string(v) + " of " + std::to_string(nv), at);
            for (int k = 0; k < 3; ++k) {
                const float x = std::bit_cast<float>(u32());
                if (!std::isfinite(x))
                    fail("vertex " + std::to_string(v) + " has a non-finite coordinate", at);
                out.positions.push_back(x);
            }
            pos_ = at + layout_.vertexBytes; // normals, colours, texture coordinates are ignored
        }
        out.polyStart.reserve(std::size_t(nf));
        for (std::uint64_t f = 0; f < nf; ++f) {
            if ((f & 0xFFFF) == 0xFFFF) ctx_.tick(pos_, bytes_.size());
            const std::size_t at = pos_;
            const std::string face = "face " + std::to_string(f) + " of " + std::to_string(nf);
            if (left() < 4) fail("ends inside " + face, at);
            const std::int32_t n = i32();
            if (n < 0 || std::uint64_t(n) > left() / 4)
                fail(face + " announces " + std::to_string(n) +
                         " vertices; expected a count the rest of the file can hold",
                     at);
            if (out.polyIndices.size() > std::numeric_limits<std::uint32_t>::max())
                fail("more than 2^32 face corners", at);
            out.polyStart.push_back(std::uint32_t(out.polyIndices.size()));
            for (std::int32_t k = 0; k < n; ++k) {
                const std::int32_t idx = i32();
                if (idx < 0 || std::uint64_t(idx) >= nv)
                    fail("face " + std::to_string(f) + " refers to vertex " + std::to_string(idx) +
                             ", outside 0.." + std::to_string(nv - 1),
                         pos_ - 4);
                out.polyIndices.push_back(idx);
            }
            if (layout_.order == BinaryOrder::Little) {
                if (left() < layout_.faceColourBytes) fail("ends inside the colour of " + face, pos_);
                pos_ += layout_.faceColourBytes;
            } else {
                const std::size_t colourAt = pos_;
                if (left() < 4) fail("ends before the colour count of " + face, colourAt);
                const std::int32_t k = i32();
                if (k < 0 || std::uint64_t(k) > left() / 4)
                    fail(face + " announces " + std::to_string(k) +
                             " colour components; expected a count the rest of the file can hold",
                         colourAt);
                pos_ += 4 * std::size_t(k);
            }
        }
        // Anything after the last face is ignored, as in ASCII OFF.
    }

  private:
    std::string_view bytes_;
    std::size_t pos_;
    BinaryLayout layout_;
    const ReadContext& ctx_;
};

void readOffBinary(std::string_view bytes, std::size_t start, std::string_view prefix, const ReadContext& ctx,
                   FlatMesh& out) {
    const std::string& path = ctx.path;
    const bool st = prefix.find("ST") != std::string_view::npos;
    const bool c = prefix.find('C') != std::string_view::npos;
    const bool n = prefix.find('N') != std::string_view::npos;
    if (bytes.size() - start < 12)
        throw InputError(
            path, "", 0,
            "binary OFF file ends inside its counts (three int32: vertices, faces, edges) (byte offset " +
                std::to_string(start) + ")");
    const std::size_t body = start + 12;
    const std::uint64_t left = bytes.size() - body;
    struct Candidate {
        BinaryLayout layout;
        std::uint64_t nv, nf;
        bool fits;
    };
    auto candidate = [&](BinaryOrder order) {
        const BinaryLayout layout = binaryLayout(order, st, c, n);
        const std::int32_t v = std::int32_t(loadU32(bytes, start, order));
        const std::int32_t f = std::int32_t(loadU32(bytes, start + 4, order));
        // Smallest possible face: its count (and, big-endian, its colour count).
        const std::uint64_t minFace = order == BinaryOrder::Little ? 4 + layout.faceColourBytes : 8;
        const bool fits =
            v >= 0 && f >= 0 && std::uint64_t(v) * layout.vertexBytes + std::uint64_t(f) * minFace <= left;
        return Candidate{layout, std::uint64_t(std::max(v, 0)), std::uint64_t(std::max(f, 0)), fits};
    };
    const Candidate little = candidate(BinaryOrder::Little), big = candidate(BinaryOrder::Big);
    if (!little.fits && !big.fits) {
        const auto counts = [](std::string_view bytes, std::size_t at, BinaryOrder order) {
            return std::to_string(std::int32_t(loadU32(bytes, at, order))) + " vertices and " +
                   std::to_string(std::int32_t(loadU32(bytes, at + 4, order))) + " faces";
        };
        throw InputError(path, "", 0,
                         "binary OFF file announces " + counts(bytes, start, BinaryOrder::Little) +
                             " little-endian (OpenMesh) or " + counts(bytes, start, BinaryOrder::Big) +
                             " big-endian (Geomview), more than the " + std::to_string(left) +
                             " bytes after the counts can hold (byte offset " + std::to_string(start) + ")");
    }
    auto parse = [&](const Candidate& k) {
        if (k.nv == 0 || k.nf == 0)
            throw InputError(path, "", 0,
                             std::string("binary OFF file (") + k.layout.name + ") announces " +
                                 std::to_string(k.nv) + " vertices and " + std::to_string(k.nf) +
                                 " faces: no triangles (byte offset " + std::to_string(start) + ")");
        BinaryOff(bytes, body, k.layout, ctx).read(k.nv, k.nf, out);
    };
    if (little.fits && big.fits && (little.nv != big.nv || little.nf != big.nf)) {
        try {
            parse(little);
            return;
        } catch (const InputError&) {
            out = FlatMesh{};
            try {
                parse(big);
                return;
            } catch (const InputError&) {
                out = FlatMesh{};
            }
        }
        parse(little); // both failed: report the little-endian (OpenMesh) reading's error
        return;
    }
    parse(little.fits ? little : big);
}

} // namespace

void readOff(std::string_view bytes, const ReadContext& ctx, FlatMesh& out) {
    const std::string& path = ctx.path;
    Lines in(bytes);
    if (!in.next())
        throw InputError(path, "", in.line, "OFF file: no OFF keyword (only blank or comment lines)");

    // The keyword: [ST][C][N][4][n]OFF.
    const std::string_view keyword = in.tokens[0];
    const std::size_t stem = keyword.size() >= 3 ? keyword.size() - 3 : 0;
    const std::string_view prefix = keyword.substr(0, stem);
    if (keyword.size() < 3 || keyword.substr(stem) != "OFF" ||
        prefix.find_first_not_of("STCN4n") != std::string_view::npos)
        throw InputError(path, "", in.line,
                         "OFF file: the first line must name the OFF format, not " + quoted(in.text));
    if (prefix.find_first_of("4n") != std::string_view::npos)
        throw InputError(path, "", in.line,
                         "OFF file: " + std::string(keyword) + " (4-D or n-D vertices) is not supported");
    std::vector<std::string_view> counts(in.tokens.begin() + 1, in.tokens.end());
    if (!counts.empty() && counts[0] == "BINARY") {
        if (counts.size() != 1)
            throw InputError(path, "", in.line,
                             "OFF file: binary data must start on the line after \"" + std::string(keyword) +
                                 " BINARY\", not after " + quoted(counts[1]));
        if (!in.endedWithNewline())
            throw InputError(path, "", in.line, "binary OFF file ends after its header line");
        readOffBinary(bytes, in.offset(), prefix, ctx, out);
        return;
    }
    if (counts.empty()) {
        if (!in.next()) throw InputError(path, "", in.line, "OFF file: no counts line");
        counts = in.tokens;
    }
    const int countsLine = in.line;
    std::int64_t c[3] = {0, 0, 0};
    bool countsOk = counts.size() == 2 || counts.size() == 3;
    for (std::size_t k = 0; countsOk && k < counts.size(); ++k)
        countsOk = parseInteger(counts[k], c[k]) && c[k] >= 0;
    if (!countsOk)
        throw InputError(path, "", countsLine,
                         "OFF file: the counts line is \"<vertices> <faces> <edges>\", not " +
                             quoted(in.text));
    const std::uint64_t nv = std::uint64_t(c[0]), nf = std::uint64_t(c[1]);
    if (nv == 0 || nf == 0)
        throw InputError(path, "", countsLine,
                         "OFF file announces " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
                             " faces: no triangles");
    // Every vertex and face is a line of at least two bytes.
    const std::uint64_t size = bytes.size();
    if (nv > size / 2 + 1 || nf > size / 2 + 1)
        throw InputError(path, "", countsLine,
                         "OFF file announces " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
                             " faces, more than the " + std::to_string(size) + "-byte file can hold");

    out.positions.reserve(std::size_t(nv) * 3);
    for (std::uint64_t v = 0; v < nv; ++v) {
        if ((v & 0xFFFF) == 0xFFFF) ctx.tick(in.offset(), bytes.size());
        if (!in.next())
            throw InputError(path, "", in.line,
                             "OFF file ends before vertex " + std::to_string(v) + " of " +
                                 std::to_string(nv));
        if (in.tokens.size() < 3)
            throw InputError(path, "", in.line,
                             "OFF file: vertex " + std::to_string(v) + " needs three coordinates, not " +
                                 quoted(in.text));
        for (int k = 0; k < 3; ++k) {
            float x = 0;
            if (!parseFloat(in.tokens[k], x))
                throw InputError(path, "", in.line,
                                 "OFF file: vertex " + std::to_string(v) + ": " + quoted(in.tokens[k]) +
                                     " is not a number");
            if (!std::isfinite(x))
                throw InputError(path, "", in.line,
                                 "vertex " + std::to_string(v) + " has a non-finite coordinate " +
                                     quoted(in.tokens[k]));
            out.positions.push_back(x);
        }
    }

    out.polyStart.reserve(std::size_t(nf));
    for (std::uint64_t f = 0; f < nf; ++f) {
        if ((f & 0xFFFF) == 0xFFFF) ctx.tick(in.offset(), bytes.size());
        if (!in.next())
            throw InputError(path, "", in.line,
                             "OFF file ends before face " + std::to_string(f) + " of " + std::to_string(nf));
        std::int64_t n = -1;
        if (!parseInteger(in.tokens[0], n) || n < 0)
            throw InputError(path, "", in.line,
                             "OFF file: face " + std::to_string(f) + " gives " + quoted(in.tokens[0]) +
                                 " as its vertex count; expected a whole number");
        // The line must hold the indices; what follows them is colour.
        if (std::uint64_t(n) > in.tokens.size() - 1)
            throw InputError(path, "", in.line,
                             "OFF file: face " + std::to_string(f) + " announces " + std::to_string(n) +
                                 " vertices but its line holds " + std::to_string(in.tokens.size() - 1) +
                                 " numbers after the count");
        if (out.polyIndices.size() > std::numeric_limits<std::uint32_t>::max())
            throw InputError(path, "", in.line, "OFF file: more than 2^32 face corners");
        out.polyStart.push_back(std::uint32_t(out.polyIndices.size()));
        for (std::int64_t k = 1; k <= n; ++k) {
            std::int64_t idx = 0;
            if (!parseInteger(in.tokens[std::size_t(k)], idx))
                throw InputError(path, "", in.line,
                                 "OFF file: face " + std::to_string(f) + ": " +
                                     quoted(in.tokens[std::size_t(k)]) + " is not a vertex index");
            if (idx < 0 || std::uint64_t(idx) >= nv)
                throw InputError(path, "", in.line,
                                 "face " + std::to_string(f) + " refers to vertex " + std::to_string(idx) +
                                     ", outside 0.." + std::to_string(nv - 1));
            out.polyIndices.push_back(idx);
        }
    }
    // Anything after the last face (OpenMesh ignored it too) is ignored.
}

} // namespace lc::meshio
